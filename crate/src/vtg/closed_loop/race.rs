//! The race of the closed loop's variants on a sample of a large file's layers: each written
//! and simulated there only, and the quietest there written whole.

use super::{every_variant, on_sample, quietness, vibration_options, Again, Quietness};
use super::{SampledPair, Simulated, Tried};
use crate::error::Error;
use crate::vtg::{search, VtgOptions};

/// Files at least this large race the variants on a sample of their layers ([`raced`]):
/// below it, writing and simulating each variant whole takes a second or two natively.
const RACE_MIN_BYTES: usize = 512 << 10;

/// The race samples every `RACE_STRIDE`-th layer, from the middle of the first stride (not
/// the first layer, which firmware and slicers print slower than the rest).
const RACE_STRIDE: usize = 8;

/// The layers [`super::quietest`] races the variants on, where it races them: a file
/// [`race_sample`] samples, the feed VTG eq. 29's (else no variant is tried) and
/// `--exhaustive` not asked for.
pub(super) fn race_layers(bytes: usize, layers: usize, options: &VtgOptions) -> Option<Vec<bool>> {
    race_sample(bytes, layers).filter(|_| options.limit_feed && !options.exhaustive)
}

/// The layers a file of `bytes` bytes and `layers` layers races its variants on ([`raced`]),
/// `None` where it is small enough to try each whole or would have fewer than eight layers
/// in the sample.
pub(super) fn race_sample(bytes: usize, layers: usize) -> Option<Vec<bool>> {
    (bytes >= RACE_MIN_BYTES && layers >= 8 * RACE_STRIDE).then(|| {
        (0..layers)
            .map(|l| l % RACE_STRIDE == RACE_STRIDE / 2)
            .collect()
    })
}

/// The variants raced on the layers `sample` marks: each written on those layers only and
/// simulated on them only (the machine at rest as each layer starts,
/// [`crate::dynamics::printing_deviation_in_layers`]), against the original and `first` simulated
/// the same way. The variants that keep the no-dearer rule there are written whole in turn,
/// quietest there first (at most [`RACE_WHOLE_MAX`]), until one keeps it on the whole file;
/// where none keeps it on the
/// sample, the one that rings least there is written whole if it rings less there than
/// `first`. Variants the sample cannot judge (they left its layers as they were) are written
/// whole after them. On the 34 MB corpus file a
/// variant costs 0.4 s raced (its offers 0.08–0.2 s, writing 0.04 s, reading and simulating
/// the sample 0.21 s; a trial is not analysed, [`Again::measured`]) against 2.7 s written and
/// simulated whole. The verdict is still the whole file's: the race only chooses which
/// variant to write.
pub(super) fn raced(
    (first, pair): (Tried, SampledPair),
    orig: &Simulated,
    sample: &[bool],
    options: &VtgOptions,
    again: &mut dyn Again,
) -> Result<Tried, Error> {
    let vibration = vibration_options(options);
    let sampled = |bytes: &[u8]| on_sample(bytes, &vibration, sample);
    let Some((b, first_sampled)) = pair else {
        return Ok(first);
    };
    let others: Vec<bool> = sample.iter().map(|&s| !s).collect();
    let mut ranked = Vec::new();
    // Variants the sample cannot judge: none of their paths in the sampled layers differs
    // from the original's (a file with few rewrites), so they ring there exactly as it does.
    let mut untold = Vec::new();
    for (k, variant) in search::quieter_variants().enumerate() {
        let span = (0.7 + 0.025 * k as f64, 0.025);
        let (measured, corners) =
            again.measured(variant, &others, &first.report.before, (span, &sampled))?;
        let Some(a) = measured else {
            break;
        };
        if a == b {
            untold.push(variant);
        } else {
            ranked.push(Trial {
                quietness: quietness(&b, &a),
                corners,
                variant,
            });
        }
    }
    let chosen = to_write_whole(ranked, quietness(&b, &first_sampled));
    let whole = (chosen.into_iter().chain(untold), 0.88, 0.01);
    every_variant(first, whole, orig, again)
}

/// The most variants that kept the rule on the race's sample a race writes whole. A sample is
/// not the file: the quietest there may still ring more whole, and the next be the one that
/// keeps it (the K1 SE accessory: the second of five), so more than one is tried. But where
/// the first two fail whole, the rest fail likewise: the variants differ in their speeds and
/// keyholes, while what fails whole is a peak at one spot the sample did not see (the K1C
/// benchy: seven passed on the sample, all seven raised the peak whole, at 1.3 s each).
const RACE_WHOLE_MAX: usize = 2;

/// A variant's trial in a race: how it rang on the sample against the original
/// ([`quietness`]), and the sharp corners its rewrite of the sample removed.
#[derive(Debug, Clone, Copy)]
struct Trial {
    quietness: Quietness,
    corners: u64,
    variant: search::Variant,
}

/// Mean deviations on a race's sample within this share of the quietest's are not told apart
/// by it. On the 34 MB corpus file six variants' means on every eighth layer lie within 1.1 %
/// of each other, and a sample of every 15th or 32nd layer ranks them in another order: the
/// variant written whole came out at −82 % or −93.5 % of the sharp corners by that ordering
/// alone.
const RACE_MEAN_TIE: f64 = 0.01;

/// The variants a race writes whole, in turn, from their trials on the sample: up to
/// [`RACE_WHOLE_MAX`] of those that keep the rule there, quietest there first; where none
/// does, the quietest if it rings less there than the first rewrite (`first`). Of the trials
/// that raised the same figures, those whose mean is within [`RACE_MEAN_TIE`] of the lowest
/// are ordered by the corners they removed, most first: a difference the sample cannot tell
/// from noise does not decide, and rounded corners are what VTG is for.
fn to_write_whole(mut ranked: Vec<Trial>, first: Quietness) -> Vec<search::Variant> {
    let figures = |t: &Trial| (t.quietness.0, t.quietness.1);
    ranked.sort_by(|x, y| {
        (figures(x).cmp(&figures(y))).then(x.quietness.2.total_cmp(&y.quietness.2))
    });
    for group in ranked.chunk_by_mut(|x, y| figures(x) == figures(y)) {
        let lowest = group[0].quietness.2;
        let tied = (group.iter())
            .take_while(|t| t.quietness.2 <= lowest * (1.0 + RACE_MEAN_TIE))
            .count();
        // Stable: equal corners keep their order by the mean.
        group[..tied].sort_by_key(|t| std::cmp::Reverse(t.corners));
    }
    let passing: Vec<_> = (ranked.iter())
        .filter(|t| t.quietness.0 == 0)
        .map(|t| t.variant)
        .take(RACE_WHOLE_MAX)
        .collect();
    if !passing.is_empty() {
        return passing;
    }
    let best = ranked.first().filter(|t| t.quietness < first);
    best.map(|t| t.variant).into_iter().collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// the sample and removed `corners` there.
    fn trial(quietness: Quietness, corners: u64, feed_cap_scale: f64) -> Trial {
        let variant = search::Variant {
            feed_cap_scale,
            ..search::Variant::default()
        };
        Trial {
            quietness,
            corners,
            variant,
        }
    }

    fn scales(chosen: &[search::Variant]) -> Vec<f64> {
        chosen.iter().map(|v| v.feed_cap_scale).collect()
    }

    #[test]
    fn the_race_writes_whole_the_two_variants_quietest_on_the_sample_that_pass_there() {
        // Three pass on the sample (no figure rose): the two quietest, the quieter first; one
        // that raised the peak is not written while any passes.
        let ranked = vec![
            trial((1, true, 0.010), 9, 1.5),
            trial((0, false, 0.014), 9, 2.0),
            trial((0, false, 0.016), 9, 4.0),
            trial((0, false, 0.012), 9, 3.0),
        ];
        assert_eq!(
            scales(&to_write_whole(ranked, (1, false, 0.02))),
            [3.0, 2.0]
        );
        // None passes: the quietest alone, where it rings less than the first rewrite did.
        let ranked = vec![
            trial((1, false, 0.012), 9, 1.5),
            trial((2, true, 0.011), 9, 2.0),
        ];
        let chosen = to_write_whole(ranked.clone(), (1, false, 0.013));
        assert_eq!(scales(&chosen), [1.5]);
        assert!(to_write_whole(ranked, (1, false, 0.012)).is_empty());
    }

    #[test]
    fn means_the_sample_cannot_tell_apart_are_ordered_by_the_corners_removed() {
        // The 34 MB file's race: every variant raised the peak on the sample, their means
        // within 1.1 % of each other. Those within 1 % of the lowest go by corners removed;
        // the two beyond it, though they removed more, do not.
        let ranked = vec![
            trial((1, true, 0.025770), 900, 1.0),
            trial((1, true, 0.025715), 500, 1.1),
            trial((1, true, 0.025739), 700, 1.2),
            trial((1, true, 0.025993), 950, 1.3),
            trial((1, true, 0.025999), 990, 1.4),
            trial((2, true, 0.020000), 999, 1.5),
        ];
        let first = (2, true, 0.027);
        assert_eq!(scales(&to_write_whole(ranked.clone(), first)), [1.0]);
        let mut apart = ranked;
        apart[0].quietness.2 = 0.0262;
        assert_eq!(scales(&to_write_whole(apart, first)), [1.2]);
        // Among passing variants likewise, two at most.
        let passing = vec![
            trial((0, false, 0.0100), 10, 1.0),
            trial((0, false, 0.0101), 30, 2.0),
            trial((0, false, 0.0200), 90, 3.0),
            trial((0, false, 0.0100), 20, 4.0),
        ];
        assert_eq!(scales(&to_write_whole(passing, first)), [2.0, 4.0]);
    }
}
