//! `quietpath vtg`: Rewrite a file as a vibration-suppressed toolpath (NURBS fit, Taylor interpolation, curvature and feed limits).

use std::path::PathBuf;

/// Arguments of `quietpath vtg`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Input file.
    pub file: PathBuf,
}

/// Runs `quietpath vtg`.
pub fn run(args: Args) -> Result<(), String> {
    Err(format!(
        "{}: `vtg` is not available yet",
        args.file.display()
    ))
}
