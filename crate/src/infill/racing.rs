//! Ruling candidates out on a sample of layers before costing them whole.
//!
//! A search's candidates differ by far more than its margin of choice: on a 16-bore block at
//! 70 % infill a Hilbert curve doubles the print time and the octagram adds 6 % of energy,
//! while the best rectilinear angles lie within 1.6 % of each other. Yet a Hilbert candidate
//! is the costliest to cost (a vertex every cell: 25 times the original file's moves), and was
//! half of the whole search. So after the first pattern, each pattern's angles are first
//! generated and replayed on every 4th layer only ([`FINE`]): those layers alone are
//! replayed, with the machine's limits and its heater and fan events, once with the original
//! infill and once per candidate (the layers between them cost the same either way, so they
//! are not planned at all). The change, scaled up by the layers' share of the original infill
//! length, estimates the whole. A candidate whose estimate scores clearly worse than the best
//! exact candidate of the earlier patterns ([`ruled_out`]) is listed with the estimate
//! (`estimated: true`) and not costed whole; tall parts are first sampled on every 16th layer
//! ([`COARSE`]), which rules out only the far worse; a pattern's first angle that survives,
//! and every angle after it, are costed whole, and only exact candidates can be chosen. `InfillOptions::exhaustive` (the CLI's `--csv` DOE
//! table and `--exhaustive`) costs every candidate whole.

use super::cost::{replay_ops, Costs, Replacement, Rotation};
use super::geom::Path;
use super::program::{Op, Program};
use super::search::Prepared;
use super::Pattern;

/// How a sample is drawn and how far its estimates must fall behind to rule a candidate out.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Stage {
    /// Every how many layers with sparse infill one is sampled.
    pub every: usize,
    /// Least share of the original infill length the sample must hold.
    pub min_share: f64,
    /// The least margin ([`ruled_out`]), a share of the best score.
    pub margin: f64,
}

/// The first look: every 16th layer, ruling out only candidates more than 10 % worse. A
/// Hilbert curve (a vertex every cell) costs as much to sample on every 4th layer as two
/// rectilinear candidates cost whole, and on the parts measured it is 8 % to 140 % worse than
/// the best; a sample a quarter the size tells that apart (on a 16-bore block its estimates
/// of the change were within 0.1 % of the whole-file change for the Hilbert curve, 3.3 % for
/// the octagram), and what it cannot rule out goes on to [`FINE`].
pub(crate) const COARSE: Stage = Stage {
    every: 16,
    min_share: 0.04,
    margin: 0.10,
};

/// The second look: every 4th layer, ruling out candidates more than half a per cent worse
/// and more than [`CHANGE_SHARE`] of their estimated change.
pub(crate) const FINE: Stage = Stage {
    every: 4,
    min_share: 0.15,
    margin: 0.005,
};

/// Fewest sampled layers: fewer, and one odd layer (a first or a top one) would sway the
/// estimate.
const MIN_PROBE_LAYERS: usize = 3;

/// How far behind the best an estimate must be, as a share of the change it estimates: a
/// sample's estimate of a change is good to 0.4 of that change (`crate/tests/infill.rs` holds
/// it there; measured up to 0.36, a cube's Archimedean chords on the coarse sample). If the
/// error is at most `e` of the true change, an estimate more than `e / (1 − e)` of its own
/// change behind the best (0.67 for 0.4) is truly behind it.
pub(crate) const CHANGE_SHARE: f64 = 0.7;

/// How far behind the best an estimate must be, in gaps between its halves' estimates. Two
/// halves with errors of spread σ differ by about 1.1 σ on average, and their mean is off by
/// σ/√2: twice the gap covers about three of those.
pub(crate) const SPREAD_SHARE: f64 = 2.0;

/// One half of a sample: every other sampled layer.
struct Half {
    /// Whether each work item is in this half.
    sampled: Vec<bool>,
    /// This half's share of the original infill length.
    share: f64,
    /// The program's operations on this half's layers, with every limit, heater and fan
    /// event of the file (so the sample runs under the file's limits and heaters).
    ops: Vec<Op>,
    /// The original replayed over these layers at each rotation of the search: what a
    /// candidate's half is measured against.
    originals: Vec<Costs>,
}

/// The sampled layers of a search, in two halves, and how their change scales to the whole.
pub(crate) struct Probe {
    halves: [Half; 2],
    /// This sample's margin ([`Stage::margin`]).
    pub margin: f64,
}

/// A candidate's estimated whole-file costs, from the whole sample and from each half alone
/// (how far the halves disagree tells how far the sample may be off).
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct Estimate {
    pub costs: Costs,
    pub halves: [Costs; 2],
}

impl Probe {
    /// The sample `stage` draws of `prep`'s layers, with the original replayed over it at each
    /// of `rotations`, or `None` when the part has too few layers for one.
    pub fn of(
        prep: &Prepared<'_>,
        stage: Stage,
        rotations: &[(f64, Option<Rotation>)],
    ) -> Option<Self> {
        let n = prep.work.len();
        // One layer a stride, half a stride in (away from the first layers), and one layer
        // further in every other stride: the halves are the even and the odd layers, so a
        // pattern that alternates by layer (the slicer's own rectilinear) is sampled in both
        // directions, and a difference between them shows as a gap between the halves.
        let half_of = |k: usize| {
            let stride = k / stage.every;
            (k % stage.every == stage.every / 2 + stride % 2).then_some(stride % 2)
        };
        let picked = |k: usize| half_of(k).is_some();
        let total: f64 = prep.work.iter().map(|w| w.target_mm).sum();
        let count = (0..n).filter(|&k| picked(k)).count();
        let halves = [0, 1].map(|h| {
            let sampled: Vec<bool> = (0..n).map(|k| half_of(k) == Some(h)).collect();
            let chosen = || prep.work.iter().zip(&sampled).filter(|(_, &s)| s);
            let layers: Vec<usize> = chosen().map(|(w, _)| w.layer).collect();
            let part: f64 = chosen().map(|(w, _)| w.target_mm).sum();
            let ops = sample_ops(&prep.prog, &layers);
            let none: &[Option<Replacement>] = &[];
            Half {
                share: part / total,
                originals: crate::parallel::map_each(rotations, |(_, r)| {
                    replay_ops(&prep.prog, &ops, none, r.as_ref(), &prep.base, None)
                }),
                sampled,
                ops,
            }
        });
        let share = halves[0].share + halves[1].share;
        let each = halves.iter().all(|h| h.share.is_finite() && h.share > 0.0);
        (count >= MIN_PROBE_LAYERS && each && share >= stage.min_share).then_some(Self {
            halves,
            margin: stage.margin,
        })
    }

    /// The whole-file costs `pattern` at part-frame angle `beta` is estimated to have, from
    /// its sampled layers replayed at rotation `ri` of the search (`rotation`) against the
    /// original's: `base` over the whole file, and over the sample.
    pub fn estimate(
        &self,
        prep: &Prepared<'_>,
        (pattern, beta): (Pattern, f64),
        (ri, rotation): (usize, Option<&Rotation>),
        base: &Costs,
    ) -> Estimate {
        let changes = self.halves.each_ref().map(|half| {
            let plans: Vec<Vec<Path>> = prep
                .work
                .iter()
                .zip(&half.sampled)
                .map(|(w, &s)| match s {
                    true => prep.plan_layer(w, pattern, beta),
                    false => Vec::new(),
                })
                .collect();
            let refs: Vec<&Vec<Path>> = plans.iter().collect();
            let lazy = prep.lazy(&refs, rotation);
            let sample = replay_ops(&prep.prog, &half.ops, &lazy, rotation, &prep.base, None);
            let original = half.originals.get(ri).copied().unwrap_or_default();
            change(&sample, &original)
        });
        let [a, b] = &self.halves;
        Estimate {
            costs: scaled(&pooled(&changes[0], &changes[1]), a.share + b.share, base),
            halves: [
                scaled(&changes[0], a.share, base),
                scaled(&changes[1], b.share, base),
            ],
        }
    }
}

/// `sample`'s change from `original` (the new infill's own metrics as they are).
fn change(sample: &Costs, original: &Costs) -> Costs {
    Costs {
        time_s: sample.time_s - original.time_s,
        thesis_j: sample.thesis_j - original.thesis_j,
        total_j: sample.total_j - original.total_j,
        length_mm: sample.length_mm - original.length_mm,
        filament_mm: sample.filament_mm - original.filament_mm,
        infill: sample.infill,
    }
}

/// Two changes summed (the infill's mean turn and chord error weighted by its corners).
fn pooled(a: &Costs, b: &Costs) -> Costs {
    let (x, y) = (&a.infill, &b.infill);
    let corners = x.n_corners + y.n_corners;
    let mean = |u: f64, v: f64| match corners {
        0 => 0.0,
        n => (u * x.n_corners as f64 + v * y.n_corners as f64) / n as f64,
    };
    let mut infill = *x;
    infill.l_total_mm += y.l_total_mm;
    infill.l_infill_mm += y.l_infill_mm;
    infill.n_total += y.n_total;
    infill.n_infill += y.n_infill;
    infill.n_turning += y.n_turning;
    infill.n_corners = corners;
    infill.mean_turn_deg = mean(x.mean_turn_deg, y.mean_turn_deg);
    infill.mean_chord_error_mm = mean(x.mean_chord_error_mm, y.mean_chord_error_mm);
    Costs {
        time_s: a.time_s + b.time_s,
        thesis_j: a.thesis_j + b.thesis_j,
        total_j: a.total_j + b.total_j,
        length_mm: a.length_mm + b.length_mm,
        filament_mm: a.filament_mm + b.filament_mm,
        infill,
    }
}

/// `base` plus a sample's `change` scaled up from the sample's `share` of the infill (the new
/// infill's own metrics scaled alike: its lengths and counts grow with the layers, its mean
/// turn does not).
fn scaled(change: &Costs, share: f64, base: &Costs) -> Costs {
    let scale = 1.0 / share;
    let count = |n: u64| (n as f64 * scale).round() as u64;
    let mut infill = change.infill;
    infill.l_total_mm *= scale;
    infill.l_infill_mm *= scale;
    infill.n_total = count(infill.n_total);
    infill.n_infill = count(infill.n_infill);
    infill.n_turning = count(infill.n_turning);
    infill.n_corners = count(infill.n_corners);
    Costs {
        time_s: base.time_s + change.time_s * scale,
        thesis_j: base.thesis_j + change.thesis_j * scale,
        total_j: base.total_j + change.total_j * scale,
        length_mm: base.length_mm + change.length_mm * scale,
        filament_mm: base.filament_mm + change.filament_mm * scale,
        infill,
    }
}

/// The operations of `prog` on `layers` (sorted), with every limit, heater and fan event of
/// the file. An operation between moves belongs to the layer of the move before it. Heater
/// targets outside the sample still set the heaters the sample's time is charged at; the
/// waits and dwells of other layers are left out with their moves.
fn sample_ops(prog: &Program, layers: &[usize]) -> Vec<Op> {
    let mut out = Vec::new();
    let mut here = false;
    for op in &prog.ops {
        let keep = match op {
            Op::Move(i) => {
                here = prog
                    .moves
                    .get(*i)
                    .is_some_and(|m| layers.binary_search(&(m.layer as usize)).is_ok());
                here
            }
            Op::Limits(_) | Op::Temperature { .. } | Op::Fan { .. } => true,
            Op::Dwell(_) | Op::Flush => here,
        };
        if keep {
            out.push(op.clone());
        }
    }
    out
}

/// An estimate's scores: of the whole sample, of the original, and of each half alone.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Scores {
    pub estimate: f64,
    pub original: f64,
    pub halves: [f64; 2],
}

/// Whether an estimate rules its candidate out against the best exact score so far: by more
/// than `margin` of the best, by more than [`CHANGE_SHARE`] of the estimated change (a large
/// change's estimate may be further out), and by more than [`SPREAD_SHARE`] times the gap
/// between the halves' estimates (a sample whose layers disagree may be further out).
pub(crate) fn ruled_out(s: &Scores, best_exact: Option<f64>, margin: f64) -> bool {
    best_exact.is_some_and(|b| {
        let gap = (margin * b.abs())
            .max(CHANGE_SHARE * (s.estimate - s.original).abs())
            .max(SPREAD_SHARE * (s.halves[0] - s.halves[1]).abs());
        s.estimate > b + gap
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sample_scales_its_change_not_the_whole() {
        let base = Costs {
            time_s: 100.0,
            total_j: 1000.0,
            ..Costs::default()
        };
        let original = Costs {
            time_s: 30.0,
            total_j: 300.0,
            ..Costs::default()
        };
        let sample = Costs {
            time_s: 31.0,
            total_j: 290.0,
            ..Costs::default()
        };
        let e = scaled(&change(&sample, &original), 0.25, &base);
        assert_eq!((e.time_s, e.total_j), (104.0, 960.0));
        let both = pooled(&change(&sample, &original), &change(&original, &original));
        assert_eq!(scaled(&both, 0.25, &base).total_j, 960.0);
    }

    #[test]
    fn only_a_clear_loss_is_ruled_out() {
        let at = |estimate: f64, halves: [f64; 2]| Scores {
            estimate,
            original: 100.0,
            halves,
        };
        let agreed = |estimate: f64| at(estimate, [estimate; 2]);
        // A change of 1 % from the original (100): behind the best by more than 0.7 %.
        assert!(!ruled_out(&agreed(101.0), Some(100.3), FINE.margin));
        assert!(ruled_out(&agreed(101.0), Some(100.2), FINE.margin));
        // A small change is ruled out by the half per cent.
        assert!(ruled_out(&agreed(100.1), Some(99.5), FINE.margin));
        assert!(!ruled_out(&agreed(100.1), Some(99.65), FINE.margin));
        // A large change needs a larger gap: a 20 % change, 14 %.
        assert!(!ruled_out(&agreed(120.0), Some(106.0), FINE.margin));
        assert!(ruled_out(&agreed(120.0), Some(105.0), FINE.margin));
        // Halves that disagree by 1 (100.6 and 101.6) need a gap of 2.
        assert!(!ruled_out(
            &at(101.1, [100.6, 101.6]),
            Some(99.2),
            FINE.margin
        ));
        assert!(ruled_out(
            &at(101.1, [100.6, 101.6]),
            Some(99.0),
            FINE.margin
        ));
        assert!(!ruled_out(
            &at(100.1, [100.6, 101.6]),
            Some(98.2),
            FINE.margin
        ));
        assert!(!ruled_out(&agreed(109.9), Some(100.0), COARSE.margin));
        assert!(
            !ruled_out(&agreed(1e9), None, FINE.margin),
            "nothing exact yet: cost it whole"
        );
    }
}
