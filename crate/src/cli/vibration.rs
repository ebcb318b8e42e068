//! `quietpath vibration`: Simulate the machine's axis dynamics on a file: natural frequencies,
//! trajectory deviation, per-layer vibration and the acceleration spectrum.

use std::io::Write;
use std::path::PathBuf;

use quietpath::dynamics::{self, VibrationOptions, VibrationReport, Window};

use super::{output, read, AnalyzeArgs};

/// Arguments of `quietpath vibration`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// G-code file to read.
    pub file: PathBuf,
    /// Interpolation period T_s, ms.
    #[arg(long, value_name = "MS", default_value_t = 1.0)]
    pub ts_ms: f64,
    /// Accelerometer sampling rate for the spectrum, Hz.
    #[arg(long, value_name = "HZ", default_value_t = 200.0)]
    pub fs: f64,
    /// Welch segment (window) length, samples.
    #[arg(long, value_name = "N", default_value_t = 512)]
    pub window: usize,
    /// Window function.
    #[arg(long, value_enum, default_value_t = WindowArg::Hamming)]
    pub window_kind: WindowArg,
    /// Dynamics parameter set: ldam-ball-screw, desktop-belt (default: from the machine preset).
    #[arg(long, value_name = "SET")]
    pub dynamics: Option<String>,
    /// Dynamics parameters as a JSON file (the serde form of `MachineDynamics`).
    #[arg(long, value_name = "FILE")]
    pub dynamics_file: Option<PathBuf>,
    /// Spectral peaks to report.
    #[arg(long, default_value_t = 5)]
    pub peaks: usize,
    /// A second file (e.g. the optimised toolpath) to compare with: both are simulated and the
    /// relative change of the deviation is reported (JSON: `{before, after, change}`).
    #[arg(long, value_name = "FILE")]
    pub compare: Option<PathBuf>,
    /// Print the report as JSON (the same object the JS API returns).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    opts: AnalyzeArgs,
}

/// Window functions.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum WindowArg {
    /// Hamming (the VTG paper's).
    Hamming,
    /// Hann (scipy's default).
    Hann,
    /// None.
    Rectangular,
}

/// Runs `quietpath vibration`.
pub fn run(args: Args) -> Result<(), String> {
    let input = read(&args.file)?;
    let dynamics_parameters = match &args.dynamics_file {
        Some(path) => {
            let text =
                std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            Some(serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?)
        }
        None => None,
    };
    let options = VibrationOptions {
        analyze: args.opts.options()?,
        ts_ms: args.ts_ms,
        fs_hz: args.fs,
        window: args.window,
        window_kind: match args.window_kind {
            WindowArg::Hamming => Window::Hamming,
            WindowArg::Hann => Window::Hann,
            WindowArg::Rectangular => Window::Rectangular,
        },
        dynamics: args.dynamics.clone(),
        dynamics_parameters,
        peaks: args.peaks,
        ..VibrationOptions::default()
    };
    let mut bar = output::ProgressBar::for_input(input.len());
    let report = dynamics::vibration_with_progress(&input, &options, &mut |f| bar.update(f))
        .map_err(|e| format!("{}: {e}", args.file.display()))?;
    bar.finish();
    let mut stdout = std::io::stdout().lock();
    if let Some(other) = &args.compare {
        let after = dynamics::vibration(&read(other)?, &options)
            .map_err(|e| format!("{}: {e}", other.display()))?;
        let change = dynamics::compare(&report, &after);
        if args.json {
            output::write_json(
                &mut stdout,
                &serde_json::json!({ "before": report, "after": after, "change": change }),
            )?;
        } else {
            print(&mut stdout, &args.file, &report).map_err(|e| e.to_string())?;
            writeln!(stdout).map_err(|e| e.to_string())?;
            print(&mut stdout, other, &after).map_err(|e| e.to_string())?;
            let pct = |x: f64| format!("{:+.2}%", 100.0 * x);
            writeln!(
                stdout,
                "\nchange: max {}, mean {}, min {}",
                pct(change.max_deviation),
                pct(change.mean_deviation),
                pct(change.min_deviation)
            )
            .map_err(|e| e.to_string())?;
        }
        return stdout.flush().map_err(|e| e.to_string());
    }
    if args.json {
        output::write_json(&mut stdout, &report)?;
    } else {
        print(&mut stdout, &args.file, &report).map_err(|e| e.to_string())?;
    }
    stdout.flush().map_err(|e| e.to_string())
}

fn print(out: &mut impl Write, file: &std::path::Path, r: &VibrationReport) -> std::io::Result<()> {
    writeln!(out, "{}", file.display())?;
    writeln!(
        out,
        "  machine                {} (dynamics: {})",
        r.machine, r.dynamics
    )?;
    writeln!(
        out,
        "  simulated              {:.0} s of motion, {} steps of {} ms",
        r.simulated_s, r.steps, r.ts_ms
    )?;
    let d = &r.deviation_mm;
    writeln!(
        out,
        "  deviation (eq. 15)     max {:.4} mm, mean {:.4} mm, min {:.4} mm",
        d.max, d.mean, d.min
    )?;
    writeln!(
        out,
        "  largest at             X {:.2} Y {:.2} mm, t = {:.1} s",
        d.max_at[0], d.max_at[1], d.max_at[2]
    )?;
    writeln!(out)?;
    writeln!(out, "  axis  position mm   modes Hz (damping ratio)")?;
    for a in &r.axes {
        let modes: Vec<String> = a
            .modes
            .iter()
            .map(|m| format!("{:.1} ({:.3})", m.frequency_hz, m.damping_ratio))
            .collect();
        writeln!(
            out,
            "  {:<4}  {:>11.1}   {}",
            a.axis,
            a.position_mm,
            modes.join(", ")
        )?;
    }
    writeln!(out)?;
    let p = &r.psd;
    writeln!(
        out,
        "  table acceleration PSD (Welch, {:?} {}, {:.0} Hz, {} segments), top peaks:",
        p.window_kind, p.window, p.fs_hz, p.segments
    )?;
    for peak in &p.peaks {
        writeln!(
            out,
            "    {:>8.2} Hz   {:.4e} (m/s²)²/Hz",
            peak.hz, peak.power
        )?;
    }
    writeln!(out)?;
    writeln!(
        out,
        "  layer        z mm   amplitude mm    mean mm   accel rms m/s²"
    )?;
    let n = r.layers.len();
    let shown: Vec<usize> = if n <= 20 {
        (0..n).collect()
    } else {
        (0..10).chain(n - 5..n).collect()
    };
    for (k, &i) in shown.iter().enumerate() {
        if k > 0 && shown[k - 1] + 1 != i {
            writeln!(out, "  ...")?;
        }
        let l = &r.layers[i];
        let z = l.z.map_or("-".to_string(), |z| format!("{z:.2}"));
        writeln!(
            out,
            "  {:>5}  {:>10}   {:>12.4}   {:>8.4}   {:>14.3}",
            l.layer, z, l.amplitude, l.mean, l.acceleration_rms
        )?;
    }
    Ok(())
}
