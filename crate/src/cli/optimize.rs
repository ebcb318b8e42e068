//! `quietpath optimize`: the recommended pipeline, as a command and as a slicer's
//! post-processing script.
//!
//! PrusaSlicer, SuperSlicer, OrcaSlicer and Bambu Studio run a post-processing script with the
//! G-code's temporary path as its last argument (the final name in `SLIC3R_PP_OUTPUT_NAME`);
//! `quietpath optimize --in-place` rewrites that file atomically, and on any error leaves it as
//! it was and exits non-zero with the message on stderr, which the slicer shows.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

use quietpath::optimize::{optimize_with_progress, OptimizeOptions, OptimizeReport};

use super::{output, read, AnalyzeArgs, ArcsArg};

/// Arguments of `quietpath optimize`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input file(s).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Where to write the optimised file (one input file).
    #[arg(short, long, value_name = "OUT", conflicts_with_all = ["in_place", "out_dir"])]
    pub output: Option<PathBuf>,
    /// Rewrite each file itself (a slicer's post-processing script).
    #[arg(long, conflicts_with = "out_dir")]
    pub in_place: bool,
    /// Write each optimised file into this folder under its own name.
    #[arg(long, value_name = "DIR")]
    pub out_dir: Option<PathBuf>,
    /// Options as a TOML file: the JSON API's option names (`arcs = "auto"`,
    /// `[vtg_options] tolerance_mm = 0.05`, `[infill]`, `[analyze]`); flags win over it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// Search the infill pattern, angle and orientation first (the infill command's defaults).
    #[arg(long)]
    pub infill: bool,
    /// Skip VTG.
    #[arg(long)]
    pub no_vtg: bool,
    /// VTG's largest distance from the original path, mm.
    #[arg(long, value_name = "MM")]
    pub tolerance: Option<f64>,
    /// Print time VTG may add to round corners that cost time, percent (default 0).
    #[arg(long, value_name = "PCT")]
    pub allow_slower: Option<f64>,
    /// Arcs in the output: auto (where the firmware runs them), on or off.
    #[arg(long, value_enum)]
    pub arcs: Option<ArcsArg>,
    /// Skip VTG's dynamics simulation (faster on big files).
    #[arg(long)]
    pub no_dynamics: bool,
    /// Leave the time comments and M73 lines as they are.
    #[arg(long)]
    pub no_estimates: bool,
    /// Print the report as JSON (one object per line with several files).
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    opts: AnalyzeArgs,
}

/// The options: the config file's, then the flags.
fn options(args: &Args) -> Result<OptimizeOptions, String> {
    let mut o = match &args.config {
        Some(path) => {
            let text =
                std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
            toml::from_str::<OptimizeOptions>(&text)
                .map_err(|e| format!("{}: {e}", path.display()))?
        }
        None => OptimizeOptions::default(),
    };
    if args.config.is_none() {
        o.analyze = args.opts.options()?;
    } else if args.opts.any() {
        o.analyze = args.opts.over(std::mem::take(&mut o.analyze))?;
    }
    if args.infill {
        o.infill.get_or_insert_with(Default::default);
    }
    o.vtg &= !args.no_vtg;
    o.estimates &= !args.no_estimates;
    if let Some(t) = args.tolerance {
        o.vtg_options.tolerance_mm = t;
    }
    if let Some(p) = args.allow_slower {
        o.allow_slower_pct = p;
    }
    if args.no_dynamics {
        o.vtg_options.dynamics = false;
    }
    if let Some(a) = args.arcs {
        o.arcs = a.into();
    }
    Ok(o)
}

/// Where `file`'s result goes.
fn target(args: &Args, file: &Path) -> Result<PathBuf, String> {
    match (&args.output, args.in_place, &args.out_dir) {
        (Some(o), _, _) if args.files.len() == 1 => Ok(o.clone()),
        (Some(_), _, _) => Err("-o takes one input file; use --out-dir or --in-place".into()),
        (None, true, _) => Ok(file.to_path_buf()),
        (None, false, Some(dir)) => Ok(dir.join(file.file_name().ok_or("not a file name")?)),
        (None, false, None) => Err("give -o OUT, --out-dir DIR or --in-place".into()),
    }
}

/// Optimises one file and writes it; the report, or the error with the file's name.
fn one(args: &Args, o: &OptimizeOptions, file: &Path) -> Result<OptimizeReport, String> {
    let to = target(args, file)?;
    let input = read(file)?;
    let show = args.files.len() == 1 && !args.json;
    let mut bar =
        output::ProgressBar::new(show && std::io::IsTerminal::is_terminal(&std::io::stderr()));
    let report = optimize_with_progress(&input, o, &mut |f| bar.update(f))
        .map_err(|e| format!("{}: {e}", file.display()))?;
    bar.finish();
    output::write_atomically(file, &to, args.in_place, |w| w.write_all(&report.output))?;
    Ok(report)
}

/// Runs `quietpath optimize`.
pub fn run(args: Args) -> Result<(), String> {
    let o = options(&args)?;
    if let Some(dir) = &args.out_dir {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let results = run_all(&args, &o);
    let mut stdout = std::io::stdout().lock();
    let mut failed = 0;
    for (file, result) in args.files.iter().zip(&results) {
        match result {
            Ok(r) if args.json => {
                let line = serde_json::to_string(r).map_err(|e| e.to_string())?;
                writeln!(stdout, "{line}").map_err(|e| e.to_string())?;
            }
            Ok(r) => print(&mut stdout, file, r).map_err(|e| e.to_string())?,
            Err(e) => {
                failed += 1;
                eprintln!("error: {e}");
            }
        }
    }
    stdout.flush().map_err(|e| e.to_string())?;
    match failed {
        0 => Ok(()),
        n => Err(format!("{n} of {} files failed", args.files.len())),
    }
}

/// Every file, several at a time (each on its own thread; the results in the files' order).
fn run_all(args: &Args, o: &OptimizeOptions) -> Vec<Result<OptimizeReport, String>> {
    let n = args.files.len();
    let workers = std::thread::available_parallelism()
        .map_or(1, |p| p.get())
        .min(n);
    let next = AtomicUsize::new(0);
    let results: Mutex<Vec<Option<Result<OptimizeReport, String>>>> = Mutex::new(vec![None; n]);
    std::thread::scope(|scope| {
        for _ in 0..workers {
            scope.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(file) = args.files.get(i) else { break };
                let r = one(args, o, file);
                if let Ok(mut all) = results.lock() {
                    all[i] = Some(r);
                }
            });
        }
    });
    results
        .into_inner()
        .unwrap_or_default()
        .into_iter()
        .map(|r| r.unwrap_or_else(|| Err("the worker stopped".into())))
        .collect()
}

fn print(out: &mut dyn Write, file: &Path, r: &OptimizeReport) -> std::io::Result<()> {
    let name = std::env::var("SLIC3R_PP_OUTPUT_NAME")
        .map(PathBuf::from)
        .unwrap_or_else(|_| file.to_path_buf());
    writeln!(out, "{}", name.display())?;
    for s in &r.stages {
        writeln!(
            out,
            "  {:<10} {}{}",
            s.stage,
            if s.applied { "" } else { "(not applied) " },
            s.message
        )?;
    }
    let (b, a) = (&r.before, &r.after);
    let pct = |a: f64, b: f64| {
        if b > 0.0 {
            format!("{:+.2} %", 100.0 * (a / b - 1.0))
        } else {
            "—".into()
        }
    };
    writeln!(
        out,
        "  {:<12} {:>14} {:>14} {:>10}",
        "", "before", "after", "change"
    )?;
    let rows = [
        ("time s", b.time_s, a.time_s),
        ("energy J", b.energy.total_j, a.energy.total_j),
        ("material g", b.material_g, a.material_g),
        ("CO2 g", b.energy.co2_g, a.energy.co2_g),
        ("lines", b.file.lines as f64, a.file.lines as f64),
        ("bytes", b.file.bytes as f64, a.file.bytes as f64),
    ];
    for (name, x, y) in rows {
        writeln!(out, "  {name:<12} {x:>14.1} {y:>14.1} {:>10}", pct(y, x))?;
    }
    Ok(())
}
