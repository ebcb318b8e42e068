//! `quietpath infill`: Regenerate sparse infill, searching pattern, angle and orientation for the least energy.

use std::io::Write;
use std::path::PathBuf;
use std::time::Instant;

use quietpath::infill::{
    infill_with_progress, Choice, InfillOptions, InfillReport, Objective, Pattern, Weights,
};

use super::output::{write_atomically, write_json, ProgressBar};

/// Arguments of `quietpath infill`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input file(s). Several files need `--csv` (the DOE mode: every file × pattern × angle ×
    /// rotation, one CSV row each).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Where to write the regenerated G-code (one input file only).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Infill angles, degrees: `start:end:step` (end excluded) or a list `0,45,90`.
    #[arg(long, default_value = "0:180:15")]
    pub angles: String,
    /// Part rotations about Z, degrees: a list or `start:end:step`.
    #[arg(long, default_value = "0")]
    pub rotations: String,
    /// Patterns, comma-separated (rectilinear, grid, triangles, tri_hexagon, concentric,
    /// hilbert, archimedean_chords, octagram_spiral, cross_line; `thesis` = the DOE's five,
    /// `all`).
    #[arg(long, default_value = "thesis")]
    pub patterns: String,
    /// What to minimise: energy, time, length or weighted.
    #[arg(long, default_value = "energy")]
    pub objective: String,
    /// Weights of `--objective weighted`: `energy,time,length` (each relative to the original).
    #[arg(long, default_value = "1,1,0")]
    pub weights: String,
    /// Choose pattern and angle layer by layer (the thesis's hybrid).
    #[arg(long)]
    pub per_layer: bool,
    /// Rectilinear-equivalent line spacing, mm (default: measured from the file).
    #[arg(long)]
    pub spacing: Option<f64>,
    /// Write every candidate of every file to this CSV (the DOE table; every candidate costed
    /// on the whole file, as with --exhaustive).
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Cost every candidate on the whole file (by default a candidate whose estimate from a
    /// sample of layers is clearly worse than the best so far is listed with that estimate).
    #[arg(long)]
    pub exhaustive: bool,
    /// Allow the output to replace the input file.
    #[arg(long)]
    pub force: bool,
    /// Write the best candidate even when it does not beat the original on the objective
    /// (by default the original is written unchanged and the report says why).
    #[arg(long)]
    pub force_candidate: bool,
    /// Leave the file's time comments and M73 lines as the slicer wrote them.
    #[arg(long)]
    pub no_estimates: bool,
    /// Print the report as JSON (an array with several files).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub opts: super::AnalyzeArgs,
}

/// `a:b:s` (b excluded) or `a,b,c`.
fn parse_list(s: &str, what: &str) -> Result<Vec<f64>, String> {
    let bad = || format!("--{what}: expected start:end:step or a comma-separated list, got '{s}'");
    let num = |t: &str| t.trim().parse::<f64>().ok().filter(|v| v.is_finite());
    if s.contains(':') {
        let parts: Vec<&str> = s.split(':').collect();
        let [a, b, step] = parts.as_slice() else {
            return Err(bad());
        };
        let (a, b, step) = (
            num(a).ok_or_else(bad)?,
            num(b).ok_or_else(bad)?,
            num(step).ok_or_else(bad)?,
        );
        if step <= 0.0 || (b - a) / step > 10_000.0 {
            return Err(bad());
        }
        let mut v = Vec::new();
        let mut k = 0.0;
        while a + k * step < b - 1e-9 {
            v.push(a + k * step);
            k += 1.0;
        }
        if v.is_empty() {
            v.push(a);
        }
        Ok(v)
    } else {
        s.split(',').map(|t| num(t).ok_or_else(bad)).collect()
    }
}

fn options(args: &Args) -> Result<InfillOptions, String> {
    let patterns = match args.patterns.trim() {
        "thesis" => Pattern::THESIS.to_vec(),
        "all" => Pattern::ALL.to_vec(),
        list => list
            .split(',')
            .map(|p| Pattern::parse(p).ok_or_else(|| format!("--patterns: unknown pattern '{p}'")))
            .collect::<Result<_, _>>()?,
    };
    let objective = match args.objective.trim() {
        "energy" => Objective::Energy,
        "time" => Objective::Time,
        "length" => Objective::Length,
        "weighted" => Objective::Weighted,
        o => {
            return Err(format!(
                "--objective: expected energy, time, length or weighted, got '{o}'"
            ))
        }
    };
    let w = parse_list(&args.weights, "weights")?;
    let [energy, time, length] = w.as_slice() else {
        return Err("--weights: expected three numbers energy,time,length".into());
    };
    Ok(InfillOptions {
        analyze: args.opts.options()?,
        angles_deg: parse_list(&args.angles, "angles")?,
        rotations_deg: parse_list(&args.rotations, "rotations")?,
        patterns,
        objective,
        weights: Weights {
            energy: *energy,
            time: *time,
            length: *length,
        },
        per_layer: args.per_layer,
        spacing_mm: args.spacing,
        force_candidate: args.force_candidate,
        estimates: !args.no_estimates,
        exhaustive: args.exhaustive || args.csv.is_some(),
    })
}

fn print(
    out: &mut impl Write,
    file: &std::path::Path,
    r: &InfillReport,
    secs: f64,
) -> std::io::Result<()> {
    let (b, a) = (&r.before, &r.after);
    writeln!(out, "{}", file.display())?;
    let m = &r.measured;
    writeln!(
        out,
        "  measured: spacing {:.3} mm, clearance {:.3} mm, {:.5} mm filament/mm, {} layers ({} blocks) regenerated",
        m.spacing_mm, m.clearance_mm, m.e_per_mm, m.layers_regenerated, m.blocks
    )?;
    if r.best.pattern == Choice::Original {
        writeln!(out, "  best: the original (written unchanged)")?;
    } else {
        writeln!(
            out,
            "  best: {} at {}°, part turned {}°{}",
            r.best.pattern.name(),
            r.best.angle_deg,
            r.best.rotation_deg,
            if r.best.layers.is_some() {
                " (per-layer hybrid)"
            } else {
                ""
            }
        )?;
    }
    if let Some(m) = &r.best.message {
        writeln!(out, "  note: {m}")?;
    }
    writeln!(
        out,
        "  {:<12} {:>12} {:>12} {:>10} {:>12}",
        "", "thesis J", "total J", "time s", "filament mm"
    )?;
    for (name, rep) in [("before", b), ("after", a)] {
        writeln!(
            out,
            "  {name:<12} {:>12.1} {:>12.1} {:>10.1} {:>12.1}",
            rep.energy.thesis_j, rep.energy.total_j, rep.time_s, rep.filament_mm
        )?;
    }
    writeln!(
        out,
        "  saving {:.1} J ({:.2} %)",
        r.best.saving_j, r.best.saving_pct
    )?;
    print_candidates(out, r, secs)?;
    if !r.rotations_skipped.is_empty() {
        writeln!(
            out,
            "  rotations skipped (off the bed): {:?}",
            r.rotations_skipped
        )?;
    }
    Ok(())
}

/// The candidates' count and the cheapest eight.
fn print_candidates(out: &mut impl Write, r: &InfillReport, secs: f64) -> std::io::Result<()> {
    let mut sorted: Vec<_> = r.candidates.iter().collect();
    sorted.sort_by(|x, y| x.total_j.total_cmp(&y.total_j));
    writeln!(
        out,
        "  {} candidates ({} with the geometry of an earlier one, not costed again; {} ruled out on a sample of layers, estimated) in {secs:.2} s; cheapest:",
        r.candidates.len(),
        r.candidates_skipped,
        r.candidates_estimated
    )?;
    for c in sorted.iter().take(8) {
        writeln!(
            out,
            "    {:<20} {:>6.1}° {:>6.1}°  thesis {:>9.1} J  total {:>10.1} J  {:>8.1} s{}",
            c.pattern.name(),
            c.angle_deg,
            c.rotation_deg,
            c.thesis_j,
            c.total_j,
            c.time_s,
            if c.estimated { "  (estimated)" } else { "" }
        )?;
    }
    Ok(())
}

/// Runs `quietpath infill`.
pub fn run(args: Args) -> Result<(), String> {
    let options = options(&args)?;
    if args.files.len() > 1 && args.csv.is_none() {
        return Err("several files need --csv (the DOE mode)".into());
    }
    if args.files.len() > 1 && args.output.is_some() {
        return Err("-o takes one input file".into());
    }
    if args.output.is_none() && args.csv.is_none() {
        return Err("give -o OUT (or --csv for the DOE table)".into());
    }
    let mut csv = String::from(
        "file,pattern,angle_deg,rotation_deg,thesis_j,total_j,time_s,length_mm,filament_mm\n",
    );
    let mut reports = Vec::new();
    let stdout = std::io::stdout();
    let mut out = stdout.lock();
    for file in &args.files {
        let input = super::read(file)?;
        let mut bar =
            ProgressBar::new(!args.json && std::io::IsTerminal::is_terminal(&std::io::stderr()));
        let t0 = Instant::now();
        let report = infill_with_progress(&input, &options, &mut |f| bar.update(f))
            .map_err(|e| format!("{}: {e}", file.display()))?;
        let secs = t0.elapsed().as_secs_f64();
        bar.finish();
        let name = file
            .file_name()
            .map(|n| n.to_string_lossy().to_string())
            .unwrap_or_default();
        for c in &report.candidates {
            csv.push_str(&format!(
                "{name},{},{},{},{:.3},{:.3},{:.3},{:.3},{:.3}\n",
                c.pattern.name(),
                c.angle_deg,
                c.rotation_deg,
                c.thesis_j,
                c.total_j,
                c.time_s,
                c.length_mm,
                c.filament_mm
            ));
        }
        if let Some(o) = &args.output {
            write_atomically(file, o, args.force, |w| w.write_all(&report.output))?;
        }
        if !args.json {
            print(&mut out, file, &report, secs).map_err(|e| e.to_string())?;
        }
        reports.push(report);
    }
    if let Some(path) = &args.csv {
        std::fs::write(path, csv).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    if args.json {
        if reports.len() == 1 {
            write_json(&mut out, &reports[0])?;
        } else {
            write_json(&mut out, &reports)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_and_ranges() {
        assert_eq!(
            parse_list("0:180:45", "a").unwrap(),
            vec![0.0, 45.0, 90.0, 135.0]
        );
        assert_eq!(parse_list("0,30", "a").unwrap(), vec![0.0, 30.0]);
        assert!(parse_list("0:1:0", "a").is_err());
        assert!(parse_list("x", "a").is_err());
    }
}
