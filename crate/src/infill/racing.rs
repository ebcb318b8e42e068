//! Ruling candidates out on a sample of layers before costing them whole.
//!
//! A search's candidates differ by far more than its margin of choice: on a 16-bore block at
//! 70 % infill a Hilbert curve doubles the print time and the octagram adds 6 % of energy,
//! while the best rectilinear angles lie within 1.6 % of each other. Yet a Hilbert candidate
//! is the costliest to cost (a vertex every cell: 25 times the original file's moves), and was
//! half of the whole search. So after the first pattern, each pattern's angles are first
//! generated and replayed on every [`PROBE_EVERY`]-th layer only (the other layers keep their
//! original infill); the change against the original, scaled up by the layers' share of the
//! original infill length, estimates the whole. A candidate whose estimate scores more than
//! [`MARGIN`] worse than the best exact candidate of the earlier patterns is listed with the
//! estimate (`estimated: true`) and not costed whole; a pattern's first angle that survives,
//! and every angle after it, are costed whole, and only exact candidates can be chosen. `InfillOptions::exhaustive` (the CLI's `--csv` DOE
//! table and `--exhaustive`) costs every candidate whole.

use super::cost::{replay, Costs, Rotation};
use super::geom::Path;
use super::search::Prepared;
use super::Pattern;

/// Every how many layers with sparse infill one is sampled.
pub(crate) const PROBE_EVERY: usize = 4;
/// Fewest sampled layers: fewer, and one odd layer (a first or a top one) would sway the
/// estimate.
const MIN_PROBE_LAYERS: usize = 3;
/// Least share of the original infill length the sample must hold.
const MIN_PROBE_SHARE: f64 = 0.15;
/// How much worse than the best exact score an estimate must be to rule its candidate out:
/// a sample's estimate of a change is good to a fraction of that change (measured: within a
/// quarter), and the candidates it rules out on the parts measured are 4 % to 140 % worse.
pub(crate) const MARGIN: f64 = 0.02;

/// The sampled layers of a search, and how their change scales to the whole.
pub(crate) struct Probe {
    /// Whether each work item is sampled.
    sampled: Vec<bool>,
    /// Original infill length of all layers over that of the sampled ones.
    scale: f64,
}

impl Probe {
    /// The sample of `prep`'s layers, or `None` when the part has too few for one.
    pub fn of(prep: &Prepared<'_>) -> Option<Self> {
        let n = prep.work.len();
        // The sample starts half a stride in, away from the first layers.
        let sampled: Vec<bool> = (0..n).map(|k| k % PROBE_EVERY == PROBE_EVERY / 2).collect();
        let count = sampled.iter().filter(|&&s| s).count();
        let total: f64 = prep.work.iter().map(|w| w.target_mm).sum();
        let part: f64 = prep
            .work
            .iter()
            .zip(&sampled)
            .filter(|(_, &s)| s)
            .map(|(w, _)| w.target_mm)
            .sum();
        let share = part / total;
        (count >= MIN_PROBE_LAYERS && share.is_finite() && share >= MIN_PROBE_SHARE).then(|| Self {
            sampled,
            scale: 1.0 / share,
        })
    }

    /// The whole-file costs `pattern` at part-frame angle `beta` is estimated to have, from
    /// its sampled layers replayed (turned by `rotation`) against the original's `base`.
    pub fn estimate(
        &self,
        prep: &Prepared<'_>,
        pattern: Pattern,
        beta: f64,
        rotation: Option<&Rotation>,
        base: &Costs,
    ) -> Costs {
        let plans: Vec<Vec<Path>> = prep
            .work
            .iter()
            .zip(&self.sampled)
            .map(|(w, &s)| {
                if s {
                    prep.plan_layer(w, pattern, beta)
                } else {
                    Vec::new()
                }
            })
            .collect();
        let refs: Vec<&Vec<Path>> = plans.iter().collect();
        let sample = replay(
            &prep.prog,
            &prep.lazy(&refs, rotation),
            rotation,
            &prep.base,
        );
        self.scaled(&sample, base)
    }

    /// `base` plus `sample`'s change from it times the scale (the new infill's own metrics
    /// scaled alike: its lengths and counts grow with the layers, its mean turn does not).
    fn scaled(&self, sample: &Costs, base: &Costs) -> Costs {
        let up = |s: f64, b: f64| b + (s - b) * self.scale;
        let count = |n: u64| (n as f64 * self.scale).round() as u64;
        let mut infill = sample.infill;
        infill.l_total_mm *= self.scale;
        infill.l_infill_mm *= self.scale;
        infill.n_total = count(infill.n_total);
        infill.n_infill = count(infill.n_infill);
        infill.n_turning = count(infill.n_turning);
        infill.n_corners = count(infill.n_corners);
        Costs {
            time_s: up(sample.time_s, base.time_s),
            thesis_j: up(sample.thesis_j, base.thesis_j),
            total_j: up(sample.total_j, base.total_j),
            length_mm: up(sample.length_mm, base.length_mm),
            filament_mm: up(sample.filament_mm, base.filament_mm),
            infill,
        }
    }
}

/// Whether an estimated `score` rules its candidate out against the best exact score so far.
pub(crate) fn ruled_out(score: f64, best_exact: Option<f64>) -> bool {
    best_exact.is_some_and(|b| score > b + MARGIN * b.abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sample_scales_its_change_not_the_whole() {
        let probe = Probe {
            sampled: vec![false, true, false, false],
            scale: 4.0,
        };
        let base = Costs {
            time_s: 100.0,
            total_j: 1000.0,
            ..Costs::default()
        };
        let sample = Costs {
            time_s: 101.0,
            total_j: 990.0,
            ..Costs::default()
        };
        let e = probe.scaled(&sample, &base);
        assert_eq!((e.time_s, e.total_j), (104.0, 960.0));
    }

    #[test]
    fn only_a_clear_loss_is_ruled_out() {
        assert!(!ruled_out(101.9, Some(100.0)));
        assert!(ruled_out(102.1, Some(100.0)));
        assert!(!ruled_out(1e9, None), "nothing exact yet: cost it whole");
    }
}
