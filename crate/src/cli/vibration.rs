//! `quietpath vibration`: Simulate the machine's axis dynamics on a file: natural frequencies, trajectory deviation, per-layer vibration and the acceleration spectrum.

use std::path::PathBuf;

/// Arguments of `quietpath vibration`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input file.
    pub file: PathBuf,
}

/// Runs `quietpath vibration`.
pub fn run(args: Args) -> Result<(), String> {
    Err(format!(
        "{}: `vibration` is not available yet",
        args.file.display()
    ))
}
