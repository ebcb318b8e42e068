//! `quietpath infill`: Regenerate sparse infill, searching pattern, angle and orientation for the least energy.

use std::path::PathBuf;

/// Arguments of `quietpath infill`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input file.
    pub file: PathBuf,
}

/// Runs `quietpath infill`.
pub fn run(args: Args) -> Result<(), String> {
    Err(format!(
        "{}: `infill` is not available yet",
        args.file.display()
    ))
}
