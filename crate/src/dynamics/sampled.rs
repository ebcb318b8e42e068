//! The dynamics model over a sample of a file's layers, for optimisers that compare variants
//! of a large file before writing one whole.

use super::simulate::{self, Outcome, Stats};
use super::trajectory::{self, Segment};
use super::{simulation_settings, untimed, Deviation, VibrationOptions};
use crate::error::Error;

/// The deviation over the printing moves of the layers `layers` marks (by layer index), each
/// run of a layer's moves simulated from rest. The ringing a layer inherits from the one
/// before is small beside what its own corners excite, and from rest the runs are independent:
/// they are simulated side by side where there are threads, and a sample of an eighth of the
/// layers costs about an eighth of [`super::vibration`] (which runs the whole print in one).
/// Where the machine settles between the layers anyway (a long dwell), a layer rings exactly
/// as in the whole run.
pub fn printing_deviation_in_layers(
    input: &[u8],
    options: &VibrationOptions,
    layers: &[bool],
) -> Result<Deviation, Error> {
    options.validate()?;
    let sampled = |layer: u32| layers.get(layer as usize).copied().unwrap_or(false);
    let (segs, file) = trajectory::segments_of_file(input, &options.analyze, sampled)?;
    let segs = segs.ok_or_else(untimed)?;
    let machine = options.machine_dynamics(&file.profile.name)?;
    let runs: Vec<&[Segment]> = segs.chunk_by(|a, b| a.layer == b.layer).collect();
    let (settings, _) = simulation_settings(options);
    let outcomes = crate::parallel::map_each(&runs, |run| {
        simulate::run(run, 0, &machine, settings, None, &mut |_| true)
    });
    let mut printing = Stats::default();
    let mut max_at = [0.0; 3];
    for outcome in outcomes {
        let Outcome {
            printing: p,
            printing_max_at,
            ..
        } = outcome?;
        if p.count > 0 && (printing.count == 0 || p.max > printing.max) {
            max_at = printing_max_at;
        }
        printing.merge(&p);
    }
    Ok(Deviation::of(&printing, max_at))
}
