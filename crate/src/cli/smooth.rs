//! `quietpath smooth`: Smooth the tool orientation of a multi-axis toolpath within a tolerance cone.

use std::path::PathBuf;

/// Arguments of `quietpath smooth`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input file.
    pub file: PathBuf,
}

/// Runs `quietpath smooth`.
pub fn run(args: Args) -> Result<(), String> {
    Err(format!(
        "{}: `smooth` is not available yet",
        args.file.display()
    ))
}
