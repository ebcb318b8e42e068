//! `quietpath vtg`: Rewrite a file as a vibration-suppressed toolpath (NURBS fit, Taylor interpolation, curvature and feed limits).

use std::io::Write;
use std::path::PathBuf;

use quietpath::vtg::{vtg_with_progress, Comparison, VtgOptions, VtgReport};

use super::{output, read, AnalyzeArgs, ArcsArg};

/// Arguments of `quietpath vtg`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input file.
    pub file: PathBuf,
    /// Output file.
    #[arg(short, long, value_name = "OUT")]
    pub output: PathBuf,
    /// Largest distance the new path may stray from the original, mm.
    #[arg(long, value_name = "MM", default_value_t = 0.1)]
    pub tolerance: f64,
    /// Critical angle: turns above it are sharp corners, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 30.0)]
    pub critical_angle: f64,
    /// Keep the programmed feed rates even where the curvature is above K_cr.
    #[arg(long)]
    pub keep_feed: bool,
    /// Skip the dynamics simulation of both files (Table 2's deviation rows, and the second
    /// rewrite with faster fillet speeds it asks for when the first one rings more).
    #[arg(long)]
    pub no_dynamics: bool,
    /// Write runs of new points that lie on a circle as arcs (G2/G3): fewer lines. auto:
    /// where the firmware runs them (the file has arcs already; Marlin, RepRapFirmware,
    /// Smoothieware and Repetier flavours; Klipper only with [gcode_arcs] in
    /// --klipper-config). `--arcs` alone is `on`.
    #[arg(long, value_enum, value_name = "WHEN", num_args = 0..=1, default_value = "auto", default_missing_value = "on")]
    pub arcs: ArcsArg,
    /// Print time the rewrite may add to round corners that cost time, percent of the
    /// original's. Only Klipper machines with a high square-corner velocity spend it: they take
    /// sharp corners faster than rounded ones. 0: the print gets no slower and uses no more
    /// energy; 100 rounds every corner the tolerance allows.
    #[arg(long, value_name = "PCT", default_value_t = quietpath::vtg::DEFAULT_ALLOW_SLOWER_PCT)]
    pub allow_slower: f64,
    /// Total energy the rewrite may add, percent of the original's. 0 (the default): the time
    /// --allow-slower allows is spent only while the file uses no more energy than before.
    #[arg(long, value_name = "PCT", default_value_t = 0.0)]
    pub allow_more_energy: f64,
    /// Lines the rewritten file may have over the original's, percent. Each rounded corner
    /// takes several lines where the original had one; a printer fed over USB or from SD reads
    /// only so many a second. 0 (the default): never more lines than the original, the paths
    /// that do not fit kept as they were.
    #[arg(long, value_name = "PCT", default_value_t = 0.0)]
    pub allow_more_lines: f64,
    /// Round corners only on the inside (fillets tangent to the legs) instead of on the racing
    /// line, which eases out by up to the tolerance before a corner for a wider circle.
    #[arg(long)]
    pub inside_corners: bool,
    /// The firmware's minimum segment time, ms (default: the file's M205 B, else Marlin's
    /// 20 ms): new segments are made at least this long at their feed where the tolerance
    /// allows.
    #[arg(long, value_name = "MS")]
    pub min_segment_time: Option<f64>,
    /// Write and simulate every quieter variant the dynamics model asks for whole, instead of
    /// racing them on every eighth layer first (files of 512 kB and 64 layers or more). Slower;
    /// the choice is checked on the whole file either way.
    #[arg(long)]
    pub exhaustive: bool,
    /// Leave the file's time comments and M73 lines as the slicer wrote them.
    #[arg(long)]
    pub no_estimates: bool,
    /// Overwrite the input file if OUT names it.
    #[arg(long)]
    pub force: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    opts: AnalyzeArgs,
}

/// Runs `quietpath vtg`.
pub fn run(args: Args) -> Result<(), String> {
    let input = read(&args.file)?;
    let options = VtgOptions {
        analyze: args.opts.options()?,
        tolerance_mm: args.tolerance,
        critical_angle_deg: args.critical_angle,
        limit_feed: !args.keep_feed,
        dynamics: !args.no_dynamics,
        arcs: args.arcs.into(),
        allow_slower_pct: args.allow_slower,
        allow_more_energy_pct: args.allow_more_energy,
        allow_more_lines_pct: args.allow_more_lines,
        inside_corners: args.inside_corners,
        estimates: !args.no_estimates,
        min_segment_time_ms: args.min_segment_time,
        exhaustive: args.exhaustive,
        ..VtgOptions::default()
    };
    let mut bar = output::ProgressBar::for_input(input.len());
    let report = vtg_with_progress(&input, &options, &mut |f| bar.update(f))
        .map_err(|e| format!("{}: {e}", args.file.display()))?;
    bar.finish();
    output::finish_rewrite(
        &args.file,
        &args.output,
        args.force,
        &report.output,
        &report,
        args.json,
        |mut w| print(&mut w, &report),
    )
}

fn print(out: &mut impl Write, r: &VtgReport) -> std::io::Result<()> {
    writeln!(
        out,
        "tolerance {} mm, measured max deviation {:.4} mm, critical angle {}°, K_cr {:.4} /mm",
        r.tolerance_mm, r.max_deviation_mm, r.critical_angle_deg, r.k_cr_per_mm
    )?;
    if let Some(m) = &r.message {
        writeln!(out, "{m}")?;
    }
    let p = &r.paths;
    writeln!(
        out,
        "paths with sharp corners {}, rewritten {}; moves {} -> {}; feed lowered on {} segments",
        p.candidates, p.rewritten, p.replaced_moves, p.written_moves, p.lowered_feed_segments
    )?;
    if p.kept_for_lines > 0 || p.compacted > 0 {
        writeln!(
            out,
            "line budget: {} paths kept sharp for lines, {} written with arcs to save lines \
             (--allow-more-lines)",
            p.kept_for_lines, p.compacted
        )?;
    }
    if r.feed_lines_folded > 0 {
        writeln!(
            out,
            "{} feed-only lines folded into the moves after them (the same motion, fewer lines)",
            r.feed_lines_folded
        )?;
    }
    writeln!(
        out,
        "{:<28} {:>14} {:>14} {:>9}",
        "metric", "before", "after", "change"
    )?;
    let row = |out: &mut dyn Write, name: &str, c: &Comparison| {
        writeln!(
            out,
            "{:<28} {:>14.4} {:>14.4} {:>8.2}%",
            name, c.before, c.after, c.change_pct
        )
    };
    let t = &r.table1;
    row(out, "L_total (mm)", &t.l_total_mm)?;
    row(out, "n_total", &t.n_total)?;
    row(out, "L_infill (mm)", &t.l_infill_mm)?;
    row(out, "n_infill", &t.n_infill)?;
    row(out, "n_turning", &t.n_turning)?;
    row(out, "mean turn (deg)", &t.mean_turn_deg)?;
    row(out, "mean chord error (mm)", &t.mean_chord_error_mm)?;
    let t = &r.table2;
    row(out, "energy E (J)", &t.energy_j)?;
    row(out, "servo energy (J)", &t.servo_energy_j)?;
    row(out, "material (g)", &t.material_g)?;
    row(out, "CO2 (g)", &t.co2_g)?;
    row(out, "time (s)", &t.time_s)?;
    if let Some(f) = &r.firmware {
        print_firmware(out, f)?;
    }
    Ok(())
}

/// The firmware's side: lines, bytes, short segments and the peak segment rate against the
/// budget, and the warning when the rewrite exceeds it.
fn print_firmware(
    out: &mut impl Write,
    f: &quietpath::vtg::firmware::FirmwareReport,
) -> std::io::Result<()> {
    let (b, a) = (&f.before, &f.after);
    let rows: [(&str, f64, f64); 6] = [
        ("lines", b.lines as f64, a.lines as f64),
        ("bytes", b.bytes as f64, a.bytes as f64),
        (
            "segments < 0.1 mm",
            b.segments_under_0_1mm as f64,
            a.segments_under_0_1mm as f64,
        ),
        (
            "segments < min time",
            b.segments_under_min_time as f64,
            a.segments_under_min_time as f64,
        ),
        (
            "peak segments/s",
            b.peak_segments_per_s,
            a.peak_segments_per_s,
        ),
        (
            "segment budget /s",
            b.budget_segments_per_s,
            a.budget_segments_per_s,
        ),
    ];
    for (name, x, y) in rows {
        let c = Comparison::new(x, y);
        writeln!(
            out,
            "{:<28} {:>14.0} {:>14.0} {:>8.2}%",
            name, c.before, c.after, c.change_pct
        )?;
    }
    writeln!(
        out,
        "min segment time {} ms ({}), block buffer {}",
        f.budget.min_segment_time_s * 1000.0,
        f.budget.min_segment_time_source,
        f.budget.block_buffer
    )?;
    if let Some(w) = &f.warning {
        writeln!(out, "warning: {w}")?;
    }
    Ok(())
}
