//! `quietpath smooth`: Smooth the tool orientation of a multi-axis toolpath within a tolerance cone.

use std::io::Write;
use std::path::PathBuf;

use clap::ValueEnum;

use quietpath::orient::{
    smooth_with_progress, Coordinates, FilterKind, InputFormat, KinematicModel, Kinematics,
    SmoothOptions, SmoothReport, Window,
};

use super::output;

/// Arguments of `quietpath smooth`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input: multi-axis G-code, or point-vector data (`.csv` x,y,z,i,j,k or `.json`).
    pub file: PathBuf,
    /// Where to write the smoothed file (same format as the input; atomically).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Kinematic model of the rotary axes.
    #[arg(long, value_enum, default_value_t = KinematicsArg::TableBc)]
    pub kinematics: KinematicsArg,
    /// table-bc: a point on the B axis (direction +Y), machine coordinates, "x,y,z" mm.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point)]
    pub b_axis_point: Option<[f64; 3]>,
    /// table-bc: a point on the C axis (direction +Z) at B = 0, "x,y,z" mm.
    #[arg(long, value_name = "X,Y,Z", value_parser = parse_point)]
    pub c_axis_point: Option<[f64; 3]>,
    /// What X, Y, Z are: machine axes, or the tool tip in the workpiece frame (RTCP/TCPM; only
    /// the rotary words are rewritten).
    #[arg(long, value_enum, default_value_t = CoordinatesArg::Machine)]
    pub coordinates: CoordinatesArg,
    /// head-ab: nozzle tip to pivot point distance, mm (0 with RTCP/TCPM).
    #[arg(long, value_name = "MM", default_value_t = 0.0)]
    pub pivot_length: f64,
    /// Smoothing filter.
    #[arg(long, value_enum, default_value_t = FilterArg::ZeroPhaseMovingAverage)]
    pub filter: FilterArg,
    /// Window in points (default 15).
    #[arg(long, value_name = "N", conflicts_with = "window_mm")]
    pub window: Option<usize>,
    /// Window in millimetres of path.
    #[arg(long, value_name = "MM")]
    pub window_mm: Option<f64>,
    /// Opening of the tolerance cone around each original tool vector, degrees.
    #[arg(long, value_name = "DEG", default_value_t = 60.0)]
    pub cone_deg: f64,
    /// Keep-out angle around the kinematic singularity (table C axis / head B = ±90°), degrees
    /// (default 6 for G-code, 0 for point-vector data).
    #[arg(long, value_name = "DEG")]
    pub singular_deg: Option<f64>,
    /// Longest step inside one continuous path, mm; longer moves are jumps the filter does not
    /// average across.
    #[arg(long, value_name = "MM", default_value_t = 5.0)]
    pub max_gap: f64,
    /// Decimals of the rewritten axis words.
    #[arg(long, default_value_t = 3)]
    pub decimals: u8,
    /// Point-vector data: feed used for the rotary timing metrics, mm/s.
    #[arg(long, value_name = "MM_S", default_value_t = 6.0)]
    pub feed: f64,
    /// Leave a G-code file's time comments and M73 lines as they were written.
    #[arg(long)]
    pub no_estimates: bool,
    /// Allow the output to replace the input file.
    #[arg(long)]
    pub force: bool,
    /// Print the report as JSON (the same object the JS API returns).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    opts: super::AnalyzeArgs,
}

/// `--kinematics` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum KinematicsArg {
    /// Table tilting about Y (B) carrying a turntable about Z (C).
    TableBc,
    /// Head tilting about X (A) and Y (B).
    HeadAb,
}

/// `--coordinates` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum CoordinatesArg {
    /// X, Y, Z are machine axes; the tip follows through the kinematic model.
    Machine,
    /// X, Y, Z are the tool tip in the workpiece frame (RTCP / TCPM).
    Workpiece,
}

/// `--filter` values.
#[derive(Debug, Clone, Copy, ValueEnum)]
pub enum FilterArg {
    /// Forward-backward moving average (no lag).
    ZeroPhaseMovingAverage,
    /// Centred median (no lag).
    ZeroPhaseMedian,
    /// Causal moving average (lags).
    MovingAverage,
    /// Causal median (lags).
    Median,
}

fn parse_point(s: &str) -> Result<[f64; 3], String> {
    let v: Vec<f64> = s
        .split(',')
        .map(|x| x.trim().parse::<f64>().map_err(|e| e.to_string()))
        .collect::<Result<_, _>>()?;
    match v.as_slice() {
        [x, y, z] => Ok([*x, *y, *z]),
        _ => Err("expected x,y,z".into()),
    }
}

/// Runs `quietpath smooth`.
pub fn run(args: Args) -> Result<(), String> {
    let input = super::read(&args.file)?;
    let ext = args
        .file
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase());
    let format = match ext.as_deref() {
        Some("csv") => InputFormat::Csv,
        Some("json") => InputFormat::Json,
        _ => InputFormat::Gcode,
    };
    let defaults = Kinematics::default();
    let options = SmoothOptions {
        kinematics: Kinematics {
            model: match args.kinematics {
                KinematicsArg::TableBc => KinematicModel::TableBc,
                KinematicsArg::HeadAb => KinematicModel::HeadAb,
            },
            b_axis_point_mm: args.b_axis_point.unwrap_or(defaults.b_axis_point_mm),
            c_axis_point_mm: args.c_axis_point.unwrap_or(defaults.c_axis_point_mm),
            pivot_length_mm: args.pivot_length,
        },
        coordinates: match args.coordinates {
            CoordinatesArg::Machine => Coordinates::Machine,
            CoordinatesArg::Workpiece => Coordinates::Workpiece,
        },
        filter: match args.filter {
            FilterArg::ZeroPhaseMovingAverage => FilterKind::ZeroPhaseMovingAverage,
            FilterArg::ZeroPhaseMedian => FilterKind::ZeroPhaseMedian,
            FilterArg::MovingAverage => FilterKind::MovingAverage,
            FilterArg::Median => FilterKind::Median,
        },
        window: match (args.window, args.window_mm) {
            (_, Some(mm)) => Window::Millimetres(mm),
            (Some(n), None) => Window::Points(n),
            (None, None) => Window::default(),
        },
        cone_deg: args.cone_deg,
        singular_deg: args.singular_deg,
        max_gap_mm: args.max_gap,
        decimals: args.decimals,
        format,
        feed_mm_s: args.feed,
        analyze: args.opts.options()?,
        estimates: !args.no_estimates,
    };
    let mut bar = output::ProgressBar::for_input(input.len());
    let report = smooth_with_progress(&input, &options, &mut |f| bar.update(f))
        .map_err(|e| format!("{}: {e}", args.file.display()))?;
    bar.finish();
    for w in &report.warnings {
        eprintln!("warning: {}:{}: {}", args.file.display(), w.line, w.message);
    }
    output::finish_rewrite(
        &args.file,
        &args.output,
        args.force,
        &report.output,
        &report,
        args.json,
        |mut w| print(&mut w, &args, &report),
    )
}

fn print(out: &mut impl Write, args: &Args, r: &SmoothReport) -> std::io::Result<()> {
    writeln!(out, "{} -> {}", args.file.display(), args.output.display())?;
    writeln!(
        out,
        "  points {} in {} runs, {} motion lines, {} changed, {} put back on the cone edge",
        r.points, r.runs, r.motion_lines, r.changed, r.corrected
    )?;
    writeln!(
        out,
        "  angle to original: max {:.3} deg (cone {} deg, limit {:.3}), mean {:.3} deg",
        r.max_angle_to_original_deg,
        r.cone_deg,
        r.cone_deg / 2.0,
        r.mean_angle_to_original_deg
    )?;
    writeln!(out, "  {:<34} {:>14} {:>14}", "", "before", "after")?;
    let row = |out: &mut dyn Write, name: &str, a: f64, b: f64| {
        writeln!(out, "  {name:<34} {a:>14.4} {b:>14.4}")
    };
    row(
        out,
        "roughness (rms |d2 T|)",
        r.before.roughness,
        r.after.roughness,
    )?;
    row(
        out,
        "angle change per point, mean deg",
        r.before.mean_angle_change_deg,
        r.after.mean_angle_change_deg,
    )?;
    row(
        out,
        "angle change per point, max deg",
        r.before.max_angle_change_deg,
        r.after.max_angle_change_deg,
    )?;
    row(
        out,
        "angle change per mm, mean deg/mm",
        r.before.mean_angle_change_per_mm_deg,
        r.after.mean_angle_change_per_mm_deg,
    )?;
    for (b, a) in r.before.rotary.iter().zip(&r.after.rotary) {
        let rows = [
            (
                "velocity peak, deg/s",
                b.max_velocity_deg_s,
                a.max_velocity_deg_s,
            ),
            (
                "velocity rms, deg/s",
                b.rms_velocity_deg_s,
                a.rms_velocity_deg_s,
            ),
            (
                "acceleration peak, deg/s2",
                b.max_acceleration_deg_s2,
                a.max_acceleration_deg_s2,
            ),
            (
                "acceleration rms, deg/s2",
                b.rms_acceleration_deg_s2,
                a.rms_acceleration_deg_s2,
            ),
            ("jerk peak, deg/s3", b.max_jerk_deg_s3, a.max_jerk_deg_s3),
            ("jerk rms, deg/s3", b.rms_jerk_deg_s3, a.rms_jerk_deg_s3),
            ("travel, deg", b.travel_deg, a.travel_deg),
        ];
        for (name, before, after) in rows {
            row(out, &format!("{} {name}", b.axis), before, after)?;
        }
    }
    writeln!(
        out,
        "  roughness reduction {:.1}%",
        100.0 * r.roughness_reduction
    )
}
