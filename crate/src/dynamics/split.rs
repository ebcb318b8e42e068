//! A long print's deviation-only run in two halves, side by side where there are threads.
//!
//! The model is linear in the state: a run started at rest at some step differs from the true
//! run by the free response of the true state there, which dies away at the rate of the
//! machine's slowest-decaying eigenvalue ([`super::axis::slowest_decay`]). So the second
//! half starts at rest [`DECAY_SPANS`] time constants before the split and is counted only
//! from the split on; the first half stops there, and stops reading the file. The two agree
//! with one whole run to rounding (a free response of `e^-40` ≈ 4e-18 of the state).
//!
//! The split is the run's, not the threads': where there is one thread the halves run in
//! turn, so a file is judged alike on every build. A machine with a mode that never decays
//! (the ball-screw preset's undamped one), or a print whose split comes before two warm-ups,
//! is run whole.

use super::parameters::{Drive, MachineDynamics};
use super::simulate::{LayerSums, Outcome, Settings};
use super::stream::{self, Simulating, Steps};
use super::{timeline, untimed, VibrationOptions};
use crate::error::Error;
use crate::path::Walked;

/// Time constants of the slowest decay the second half starts early by.
pub const DECAY_SPANS: f64 = 40.0;

/// Positions along each axis's travel the decay is taken at (the model's stiffness varies
/// with the nut's position): both ends and seven between.
const DECAY_POSITIONS: usize = 9;

/// Which half of a split run, split at `at_s` seconds of the timeline.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Half {
    First { at_s: f64 },
    Second { at_s: f64 },
}

/// What a half's run gives: its outcome and its sums by counted layer, if it ran.
pub(super) type HalfRun = Option<(Outcome, Option<Vec<LayerSums>>)>;

impl Half {
    /// The steps this half takes on `machine` at period `ts`: `None` for a second half where
    /// the run is not split (the first half is then the whole run). Each half learns the
    /// machine from its own walk and takes the warm-up itself: 0.9 ms of eigenvalues on the
    /// belt preset, against two seconds or more of stepping, not worth sharing across threads.
    pub(super) fn steps(self, machine: &MachineDynamics, ts: f64) -> Option<Steps> {
        let at_s = match self {
            Half::First { at_s } | Half::Second { at_s } => at_s,
        };
        let split = warmup_s(machine).filter(|w| at_s >= 2.0 * w && at_s / ts < 1e15);
        match (self, split) {
            (Half::First { .. }, None) => Some(Steps::default()),
            (Half::Second { .. }, None) => None,
            (Half::First { .. }, Some(_)) => Some(Steps {
                until: Some((at_s / ts).floor() as u64),
                ..Steps::default()
            }),
            (Half::Second { .. }, Some(w)) => Some(Steps {
                from: ((at_s - w) / ts).floor() as u64,
                until: None,
                counted_after: (at_s / ts).floor() as u64,
            }),
        }
    }
}

/// The second half's warm-up: [`DECAY_SPANS`] time constants of the slowest decay of either
/// axis anywhere on its travel, in whole seconds (so that rounding in the eigenvalues cannot
/// move it between builds); `None` where some motion never decays.
pub fn warmup_s(machine: &MachineDynamics) -> Option<f64> {
    let slowest = [machine.x, machine.y]
        .iter()
        .flat_map(|d| positions(d).map(move |p| super::axis::slowest_decay(d, p)))
        .try_fold(f64::INFINITY, |r, d| d.map(|d| r.min(d)))?;
    let w = (DECAY_SPANS / slowest).ceil();
    (slowest > 0.0 && w.is_finite()).then_some(w)
}

/// The positions [`warmup_s`] takes the decay at along `drive`'s travel, m.
fn positions(drive: &Drive) -> impl Iterator<Item = f64> + '_ {
    let travel = drive.travel_m();
    (0..DECAY_POSITIONS).map(move |i| travel * i as f64 / (DECAY_POSITIONS - 1) as f64)
}

/// The share of the print's expected time the first half runs to. Each half reads and plans
/// the file up to where it stops, the second all of it (the first half stops reading at its
/// end): a split a little past the middle gives both about as much to do.
pub const FIRST_SHARE: f64 = 0.55;

/// What one half's walk gives: its run, whether the run was split, whether every move was
/// timed, and what the walk learnt.
type Walk = ((HalfRun, bool), bool, Walked);

/// `input` read, planned and simulated for its deviation alone at `settings`, split at
/// [`FIRST_SHARE`] of `expected_s` (the print's planned time, about) where the machine allows:
/// the run's outcome, its per-layer sums final, and what the walk learnt of the file.
pub(super) fn deviation_run(
    input: &[u8],
    options: &VibrationOptions,
    settings: Settings,
    expected_s: f64,
) -> Result<(Outcome, Walked), Error> {
    // A whole second: the same split on every build.
    let at_s = (expected_s * FIRST_SHARE).floor();
    let run = |half: Half| -> Result<Walk, Error> {
        let dynamics_for = |name: &str| options.machine_dynamics(name);
        let mut quiet = |_| true;
        let sim = Simulating::new(dynamics_for, (settings, None), input, &mut quiet).half(half);
        let (sim, timed, file) = timeline::of_file(input, &options.analyze, sim)?;
        Ok((sim.finish_half()?, timed, file))
    };
    let (second, first) = if crate::parallel::threads() > 1 {
        let (second, first) =
            crate::parallel::join(|| run(Half::Second { at_s }), || run(Half::First { at_s }));
        (Some(second), first)
    } else {
        // One thread: the second half only where the first says the run is split.
        let first = run(Half::First { at_s });
        let split = matches!(first, Ok(((_, true), _, _)));
        (split.then(|| run(Half::Second { at_s })), first)
    };
    let ((first, split), first_timed, first_file) = first?;
    let (mut out, mut counted) = first.ok_or_else(untimed)?;
    // The first half read the file only up to its end: the second's walk says what the file is.
    let (timed, file) = if split {
        let ((second, _), timed, file) = second.ok_or_else(untimed)??;
        let (later, later_counted) = second.ok_or_else(untimed)?;
        out.then(later);
        if let (Some(c), Some(l)) = (counted.as_mut(), later_counted) {
            super::simulate::merge_layers(c, &l);
        }
        (timed, file)
    } else {
        (first_timed, first_file)
    };
    if !timed {
        return Err(untimed());
    }
    let by_markers = matches!(file.layer_source, crate::read::LayerSource::Markers(_));
    stream::finish_layers(&mut out, counted, file.layers.len(), by_markers);
    Ok((out, file))
}
