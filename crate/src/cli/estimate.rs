//! `quietpath estimate`: the file's time comments and `M73` progress lines rewritten from our
//! planner (klipper_estimator's `post-process`, with quietpath's planner).

use std::io::Write;
use std::path::PathBuf;

use quietpath::estimate::{rewrite_estimates, EstimateReport};

use super::{output, read, AnalyzeArgs};

/// Arguments of `quietpath estimate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input file.
    pub file: PathBuf,
    /// Where to write the file with true estimates.
    #[arg(short, long, value_name = "OUT", conflicts_with = "in_place")]
    pub output: Option<PathBuf>,
    /// Rewrite the file itself (atomically: an error leaves it as it was).
    #[arg(long)]
    pub in_place: bool,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    opts: AnalyzeArgs,
}

/// Runs `quietpath estimate`.
pub fn run(args: Args) -> Result<(), String> {
    let target = match (&args.output, args.in_place) {
        (Some(o), _) => o.clone(),
        (None, true) => args.file.clone(),
        (None, false) => return Err("give -o OUT or --in-place".into()),
    };
    let input = read(&args.file)?;
    let options = args.opts.options()?;
    let e = rewrite_estimates(&input, &options, &["estimates rewritten".to_string()])
        .map_err(|e| format!("{}: {e}", args.file.display()))?;
    output::finish_rewrite(
        &args.file,
        &target,
        args.in_place,
        &e.output,
        &e.report,
        args.json,
        |w| print(w, &e.report),
    )
}

fn print(out: &mut dyn Write, r: &EstimateReport) -> std::io::Result<()> {
    writeln!(
        out,
        "print time {:.1} s; {} M73 lines and {} time comments rewritten",
        r.time_s, r.progress_lines, r.time_comments
    )
}
