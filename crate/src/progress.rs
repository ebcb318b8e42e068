//! Progress reporting shared by every long job (analysis, VTG, infill search, orientation
//! smoothing, vibration).

/// Progress callback: receives the fraction done (0..=1); returning `false` cancels the job.
pub type Progress<'p> = &'p mut dyn FnMut(f64) -> bool;

/// A progress callback that is told the furthest fraction reached so far, for a job whose
/// stages report over spans that may overlap (a bar that went back would mislead).
pub struct Furthest<'p> {
    progress: Progress<'p>,
    reached: f64,
}

impl<'p> Furthest<'p> {
    /// `progress`, nothing reached yet.
    pub fn new(progress: Progress<'p>) -> Self {
        Self {
            progress,
            reached: 0.0,
        }
    }

    /// Reports `fraction`, or the furthest reached before it where that is further; `false`
    /// where the callback cancels.
    pub fn report(&mut self, fraction: f64) -> bool {
        self.reached = self.reached.max(fraction);
        (self.progress)(self.reached)
    }
}

impl std::fmt::Debug for Furthest<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Furthest")
            .field("reached", &self.reached)
            .finish_non_exhaustive()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_furthest_fraction_is_reported_and_a_cancel_goes_through() {
        let mut seen = Vec::new();
        let mut callback = |f: f64| {
            seen.push(f);
            f < 0.8
        };
        let mut furthest = Furthest::new(&mut callback);
        let asked: Vec<bool> = [0.2, 0.5, 0.3, 0.9].map(|f| furthest.report(f)).to_vec();
        assert_eq!(asked, [true, true, true, false]);
        assert_eq!(seen, [0.2, 0.5, 0.5, 0.9]);
    }
}
