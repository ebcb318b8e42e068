//! Progress reporting shared by every long job (analysis, VTG, infill search, orientation
//! smoothing, vibration).

/// Progress callback: receives the fraction done (0..=1); returning `false` cancels the job.
pub type Progress<'p> = &'p mut dyn FnMut(f64) -> bool;
