//! The search for the rewrite, its ladders of variants in one table. Every rung is tried in
//! the order listed; the first that passes (or the best, where noted) is kept.
//!
//! | level | rungs | enumerated by | tried in |
//! |---|---|---|---|
//! | file | VTG eq. 29 speed scale 1 with keyholes and steps joined, then without keyholes, then the steps as walked at `Tuning::quieter_scales` with and without keyholes; the quietest under the dynamics model is kept | [`quieter_variants`] | `vtg::with_simulated_deviation` |
//! | file | the time allowance, cut by the excess for `Tuning::time_rounds` rounds, then none | — | [`within_allowed_time`] |
//! | path | the free rewrite (corners rounded at no loss of speed), then `Tuning::dearer_speed_shares` where time may be spent | `rewrite::Offering` | [`rewrite::offers`] |
//! | path | VTG eq. 29 speeds at `Tuning::cap_scales`, each without then with a ceiling at the original's speed: the first that costs nothing, else the cheapest and the fastest | [`writings`] | `rewrite::cheapest_and_fastest` |
//! | path | the corners written as they are (Klipper polygons), asked first of the whole path | [`WRITTEN_KINDS`] | `smooth::smooth_path` |
//! | path | the racing line, then the inside line where that left more sharp turns | — | [`smooth_cut`] |
//! | line | each sharp corner's fillet (`blend::Fillets`), then the corners fitted with the path: hairpins, then keyholes; the replacements taken in the order of their corners | [`FITTED_KINDS`] | `smooth::smooth_on` |
//! | piece | blends at `Tuning::blend_share` of the tolerance, shrunk by `Tuning::retry_scale` for `Tuning::attempts` tries (each kind asked for its replacement again: `CornerKind::again`); keyholes dropped where none fits | [`blend_shares`] | `smooth::smooth_piece` |
//!
//! Each path goes through the stages with its corners chosen (`smooth`, asking the kinds of
//! `corners` through `CornerKind`), is written its free way and its dearer ways (`rewrite`),
//! and the file-level choice decides what to buy with the time allowed (`budget`).

use super::corners::{arc_hairpin, hairpin, keyhole, klipper, CornerKind};
use super::tuning::TUNING;
use super::VtgOptions;
use crate::analyze::Report;
use crate::error::Error;
use crate::vtg::feed::Way;
use crate::vtg::report::OutputKept;
use smooth::{Settings, SmoothPath, Smoothed};

pub(crate) mod budget;
mod compact;
pub(crate) mod rewrite;
pub(crate) mod smooth;
pub(crate) mod smoothings;
pub(crate) mod straights;

/// What a whole-file rewrite is tried with; [`crate::vtg::vtg`] tries others where the dynamics
/// model finds the first one ringing more than the original.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Variant {
    /// The first scale of the VTG eq. 29 speeds ([`Settings::feed_cap_scale`]).
    pub(crate) feed_cap_scale: f64,
    /// Turn corners too tight to fillet round keyhole loops ([`Settings::keyholes`]).
    pub(crate) keyholes: bool,
    /// Join the walked steps up to the segment budget ([`Settings::min_segment_s`]).
    pub(crate) thin: bool,
    /// Rewrite nothing: the original, reported as a rewrite would be ([`Variant::original`]).
    pub(crate) keep_original: bool,
    /// At each scale of the VTG eq. 29 speeds, joined segments capped for their stretch's
    /// mean curvature too, before the next scale ([`Settings::stretch`]).
    pub(crate) stretch: bool,
}

impl Variant {
    /// The variant that rewrites nothing, for when no rewrite keeps the no-dearer rule.
    pub(crate) fn original() -> Self {
        Variant {
            keep_original: true,
            ..Variant::default()
        }
    }

    /// The variant that may round more corners where this one keeps the no-dearer rule: for
    /// steps joined without keyholes, the keyholes with the steps as walked. Which rounds more
    /// depends on the lines the file allows: walked steps cost lines that joined ones leave to
    /// other paths (by default the joined round more: the bored block 3029 corners left
    /// against 4143), while with lines to spare the keyholes round the wedges' tips (the
    /// thesis square at `--allow-more-lines 1000`: 0 left against 135).
    pub(crate) fn rival(self) -> Option<Variant> {
        (self.thin && !self.keyholes && !self.keep_original).then_some(Variant {
            keyholes: true,
            thin: false,
            stretch: false,
            ..self
        })
    }

    /// The variants tried, in turn, for more rounded corners where this one keeps the
    /// no-dearer rule: [`Variant::rival`], then the stretch twins (`stretch`) of this one, of
    /// the first rewrite and of the first without keyholes (a variant whose steps are not
    /// joined has no twin of its own: its feeds would be its own). Joined segments capped for their
    /// stretch run their long straights faster, so a path more often costs no time at the
    /// speeds as they are: on the thesis teardrop and oval and the Simplify3D file the twins
    /// keep the rule with more corners rounded, while on the L bracket the first rewrite's
    /// twin rounds fewer (its slower fillets need ramps, and so lines; docs/measurements/vtg.md).
    pub(crate) fn rivals(self) -> Vec<Variant> {
        let twin = |v: Variant| Variant { stretch: true, ..v };
        let mut out: Vec<Variant> = self.rival().into_iter().collect();
        if self.keep_original {
            return out;
        }
        let joined = quieter_variants().next().unwrap_or_default();
        for v in [twin(self), twin(Variant::default()), twin(joined)] {
            if v.thin && v != self && !out.contains(&v) {
                out.push(v);
            }
        }
        out
    }
}

impl Default for Variant {
    fn default() -> Self {
        Variant {
            feed_cap_scale: 1.0,
            keyholes: true,
            thin: true,
            keep_original: false,
            stretch: false,
        }
    }
}

/// The whole-file variants tried after the first (scale 1 with keyholes, steps joined), in
/// turn: the first without keyholes (the loops round wedges that can ring more than the stop
/// did), then the steps as walked (longer segments turn more at each junction, and on some
/// files the machine rings more for it: the fixture cube +15.7 % in simulated mean deviation
/// with them joined), then faster VTG eq. 29 speeds and no keyholes, as walked. Joined steps
/// come first because they leave lines for more paths' rewrites: where the first rewrite rang
/// more, the variants as walked kept 1.5–2 times its sharp corners (the bored block's 4143
/// against 2042), and without keyholes but joined is what passes on five fixtures and files
/// (the bored block −45.8 → −60.4 %, the L bracket −10.4 → −37.9 %, the Kiri:Moto Voron
/// −72.4 → −82.2 %; docs/measurements/vtg.md).
pub(crate) fn quieter_variants() -> impl Iterator<Item = Variant> {
    let joined = Variant {
        keyholes: false,
        ..Variant::default()
    };
    std::iter::once(joined).chain([true, false].into_iter().flat_map(|keyholes| {
        TUNING.quieter_scales.map(|feed_cap_scale| Variant {
            feed_cap_scale,
            keyholes,
            thin: false,
            keep_original: false,
            stretch: false,
        })
    }))
}

/// The ways a smoothed path is written, in turn: the VTG eq. 29 speeds at each of
/// `Tuning::cap_scales` times the settings' first scale (`None`: no caps; only that without
/// `limit_feed`), each first without a ceiling, then no faster than the original; with
/// [`Settings::stretch`], each then again with joined segments capped for their stretch.
pub(crate) fn writings(settings: &Settings) -> Vec<Way> {
    let base = settings.feed_cap_scale;
    let capped = TUNING.cap_scales.map(|k| k.map(|k| k * base));
    let scales: &[Option<f64>] = if settings.limit_feed {
        &capped
    } else {
        &[None]
    };
    let stretches: &[bool] = if settings.stretch {
        &[false, true]
    } else {
        &[false]
    };
    let mut ways = Vec::with_capacity(scales.len() * 2 * stretches.len());
    for &scale in scales {
        for &stretch in stretches {
            for ceiling in [false, true] {
                ways.push(Way {
                    scale,
                    ceiling,
                    stretch,
                });
            }
        }
    }
    ways
}

/// The shares of the tolerance a piece's blends are tried with, in turn: `Tuning::blend_share`,
/// then each retry `Tuning::retry_scale` of the one before, `Tuning::attempts` in all.
pub(crate) fn blend_shares() -> impl Iterator<Item = f64> {
    std::iter::successors(Some(TUNING.blend_share), |share| {
        Some(share * TUNING.retry_scale)
    })
    .take(TUNING.attempts)
}

/// The corner kinds whose replacements are written as they are, asked first, of the whole
/// path: Klipper's polygons about each sharp corner its own fillet does not round at no loss
/// of speed, then hairpins written as one arc each.
pub(crate) const WRITTEN_KINDS: [&dyn CornerKind; 2] =
    [&klipper::Polygons, &arc_hairpin::ArcHairpins];

/// The corner kinds whose replacements are blended and fitted with the path, asked in turn
/// on each line tried, after each corner's fillet: two corners across a short leg before
/// single corners.
pub(crate) const FITTED_KINDS: [&dyn CornerKind; 2] = [&hairpin::Hairpins, &keyhole::Keyholes];

/// [`smooth::smooth_path`] without the corners written as they are, the path also cut at the
/// points `forced` (whose pieces are kept as they are unless they have a sharp corner): on the
/// settings' line, then, where the racing line rounded a corner the inside fillet could not
/// and sharp turns were left, on the inside line too; the one left with fewer sharp turns is
/// kept.
pub(crate) fn smooth_cut(
    path: &SmoothPath<'_>,
    s: &Settings,
    forced: &[usize],
) -> Option<Smoothed> {
    let (result, rescued) = smooth::smooth_on(path, s, forced);
    if !rescued {
        return result;
    }
    let cos_critical = crate::math::cos(s.critical_rad);
    let left = |r: &Option<Smoothed>| {
        r.as_ref().map_or(usize::MAX, |r| {
            rewrite::sharp_turns(path.pts.iter().take(1).chain(&r.points), cos_critical)
        })
    };
    let left_wide = left(&result);
    if left_wide == 0 {
        return result;
    }
    let inside_line = Settings {
        line: super::blend::Line::Inside,
        ..*s
    };
    let (inside, _) = smooth::smooth_on(path, &inside_line, forced);
    if left(&inside) < left_wide {
        inside
    } else {
        result
    }
}

/// The rewrite written from `offers` with the time `allow_slower_pct` allows, measured on the
/// whole file, and the analysis it was measured with (`None`: no time allowed, or no path that
/// could spend it, not analysed).
/// The choice counts the time each path adds as planned with its neighbours only; across the
/// file the firmware's look-ahead adds a little more, so where the whole file comes out slower
/// than allowed the allowance is cut by the excess and the choice made again (at most
/// `Tuning::time_rounds` times, then without any allowance). The time bought also costs
/// energy (the motors, heaters and electronics run as long as the print does): where the whole
/// file comes out dearer than `allow_more_energy_pct` allows, the allowance is cut to the time
/// spent less the excess energy's worth of time at the print's mean power. Before each
/// analysis the choice's own forecast is cut the same way ([`within_forecast`]), so that a
/// choice the paths' costing already shows to be too dear is not written and analysed.
pub(crate) fn within_allowed_time<T>(
    input: &[u8],
    offers: &rewrite::Offers,
    (options, before): (&VtgOptions, &Report),
    beside: Option<Beside<'_, T>>,
) -> Result<(rewrite::Rewritten, Option<Measured<T>>), Error> {
    let limits = Allowance::of(offers, (options, before));
    let mut allowed_s = limits.time_s;
    let lines = offers.allowed_lines();
    for _ in 0..TUNING.time_rounds {
        let Some(kept) = within_forecast(offers, (allowed_s, lines), &limits, before) else {
            break;
        };
        allowed_s = kept;
        let rewritten = offers.write(input, (allowed_s, lines), limits.mean_power_w);
        let (analysed, alongside) = crate::parallel::join(
            || analysed(&rewritten.output, input, options),
            || beside.map(|f| f(&rewritten.output)),
        );
        let (after, kept) = analysed?;
        let added = [
            after.time_s - before.time_s,
            after.energy.total_j - before.energy.total_j,
        ];
        match limits.cut(allowed_s, added) {
            None => return Ok((rewritten, Some((after, kept, alongside)))),
            Some(cut) => allowed_s = cut,
        }
    }
    Ok((offers.write(input, (0.0, lines), limits.mean_power_w), None))
}

/// [`within_allowed_time`]'s first choice, written without the whole file's analysis that
/// would confirm it: the allowance as the choice's own forecast keeps it within the limits
/// ([`within_forecast`]). What a race's trial writes (its output is simulated on a sample of
/// layers only, to choose which variant to write whole): the same bytes wherever the analysis
/// confirms the first choice, as it does on every trial of the 34 MB corpus file, where the
/// analysis was 40 % of a trial's work. The variant written whole is checked in full.
pub(crate) fn within_forecast_time(
    input: &[u8],
    offers: &rewrite::Offers,
    (options, before): (&VtgOptions, &Report),
) -> rewrite::Rewritten {
    let limits = Allowance::of(offers, (options, before));
    let lines = offers.allowed_lines();
    let allowed_s = within_forecast(offers, (limits.time_s, lines), &limits, before)
        .filter(|_| TUNING.time_rounds > 0)
        .unwrap_or(0.0);
    offers.write(input, (allowed_s, lines), limits.mean_power_w)
}

/// What the whole file may add: time s, total energy J, and the print's mean power W (what a
/// second of the allowance costs in energy, roughly).
struct Allowance {
    time_s: f64,
    energy_j: f64,
    mean_power_w: f64,
}

impl Allowance {
    /// What `options` allow a rewrite from `offers` to add to the original (`before`). Nothing
    /// to buy (every Marlin file of the corpus): no time, the choice is the free rewrites'.
    fn of(offers: &rewrite::Offers, (options, before): (&VtgOptions, &Report)) -> Self {
        let time_s = if offers.has_dearer() {
            options.allow_slower_pct / 100.0 * before.time_s
        } else {
            0.0
        };
        Allowance {
            time_s,
            energy_j: before.energy.total_j * options.allow_more_energy_pct / 100.0,
            mean_power_w: before.energy.total_j / before.time_s,
        }
    }

    /// The allowance cut from `allowed_s` where a choice made with it adds `added` (time s,
    /// total energy J) to the file, over what may be added; `None` where it is within both.
    fn cut(&self, mut allowed_s: f64, [added, added_j]: [f64; 2]) -> Option<f64> {
        let over_j = added_j - self.energy_j;
        if added <= self.time_s && over_j <= 0.0 {
            return None;
        }
        if added > self.time_s {
            allowed_s -= TUNING.time_margin * (added - self.time_s);
        }
        if over_j > 0.0 {
            allowed_s = allowed_s.min(added) - TUNING.time_margin * over_j / self.mean_power_w;
        }
        Some(allowed_s)
    }
}

/// `allowed_s`, cut ([`Allowance::cut`]) until the choice's own forecast ([`rewrite::Offers::forecast`])
/// is within `limits`: the time its paths add as each was planned, and the energy their
/// motors add plus that time at the heaters', fans' and electronics' power in the original
/// (`before`'s `aux_j` over its time). The forecast tracks the whole file's analysis: on the
/// 34 MB corpus file, whose first choice bought 102 s and went over by 3.3 kJ, the forecast
/// was 110 s and 3.8 kJ, and within 0.2 kJ on the other files that buy time (not over on any).
/// `None` where no time is left to spend (none allowed, or cut to none).
fn within_forecast(
    offers: &rewrite::Offers,
    (mut allowed_s, lines): (f64, i64),
    limits: &Allowance,
    before: &Report,
) -> Option<f64> {
    let aux_power_w = before.energy.aux_j / before.time_s;
    for _ in 0..TUNING.time_rounds {
        if allowed_s <= 0.0 || !allowed_s.is_finite() || !aux_power_w.is_finite() {
            break;
        }
        let [time_s, motors_j] = offers.forecast((allowed_s, lines), limits.mean_power_w);
        match limits.cut(allowed_s, [time_s, motors_j + time_s * aux_power_w]) {
            None => break,
            Some(cut) => allowed_s = cut,
        }
    }
    Some(allowed_s).filter(|&s| s > 0.0 && s.is_finite())
}

/// A rewrite's analysis and what it kept of its pass, as the time allowance measured it, and
/// what was measured beside it ([`within_allowed_time`]'s `beside`: the output's metrics, where
/// they are wanted, read while the analysis runs, in case this round's output is the one kept).
pub(crate) type Measured<T> = (Report, OutputKept, Option<T>);

/// `output`, the rewrite of `input`, analysed, with its segments counted against `input`'s
/// minimum segment time and, without the dynamics model, its clock, from the same planning
/// pass: what measuring it against the firmware and refreshing its time estimates read, where
/// it is the file handed back. With the model the closed loop holds several rewrites' reports
/// at once, and their clocks (17 MB each on the 34 MB corpus file) took its peak from 0.74 to
/// 0.81 GB, over the 800 MB it is held to; its file handed back is planned for its clock.
pub(crate) fn analysed(
    output: &[u8],
    input: &[u8],
    options: &VtgOptions,
) -> Result<(Report, OutputKept), Error> {
    let min_s = crate::vtg::firmware::min_segment_time_s(input, options.min_segment_time_ms);
    let keep = crate::analyze::Keep {
        starts: !options.dynamics,
        min_segment_s: Some(min_s),
        layer_metrics_deg: Some(options.critical_angle_deg),
        timed_moves: false,
    };
    let (after, kept) = crate::analyze::analyze_keeping(output, &options.analyze, keep)?;
    let output_kept = OutputKept {
        clock: kept
            .starts
            .map(|starts| crate::estimate::Clock::from_analysis(&after, starts)),
        segments: kept.segments.unwrap_or_default(),
        // Asked for above, so always there.
        metrics: kept.layer_metrics.unwrap_or_default(),
    };
    Ok((after, output_kept))
}

/// What [`within_allowed_time`] measures of each output beside its analysis.
pub(crate) type Beside<'f, T> = &'f dyn Fn(&[u8]) -> T;

/// Lines the rewrite may add to `input`: `allow_more_lines_pct` of its lines, less the header
/// the refreshed time estimates will add where it has estimates (`crate::vtg::ESTIMATE_HEADER_LINES`), so the file as
/// written keeps to it.
pub(crate) fn allowed_lines(input: &[u8], options: &VtgOptions) -> i64 {
    let lines = crate::gcode::file_lines(input);
    let header = if options.estimates && crate::estimate::has_estimates(input) {
        super::ESTIMATE_HEADER_LINES
    } else {
        0
    };
    (lines as f64 * options.allow_more_lines_pct / 100.0).floor() as i64 - header
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The first variant tried after the first rewrite is that rewrite without keyholes, its
    /// steps still joined; the rest walk their steps, at every scale with and without keyholes,
    /// and none is the first rewrite again.
    #[test]
    fn the_first_variant_is_the_first_rewrite_without_keyholes() {
        let variants: Vec<Variant> = quieter_variants().collect();
        let first = Variant::default();
        assert!(first.thin && first.keyholes);
        assert_eq!(
            variants[0],
            Variant {
                keyholes: false,
                ..first
            }
        );
        assert!(!variants.contains(&first));
        assert!(variants[1..].iter().all(|v| !v.thin && !v.keep_original));
        assert_eq!(variants.len(), 1 + 2 * TUNING.quieter_scales.len());
    }

    /// Only steps joined without keyholes have a rival: the keyholes with the steps as walked,
    /// at the same scale, which is one of the variants tried.
    #[test]
    fn joined_steps_without_keyholes_have_the_walked_keyholes_as_rival() {
        let variants: Vec<Variant> = quieter_variants().collect();
        let rival = variants[0].rival().expect("a rival");
        assert_eq!(rival, variants[1]);
        assert!(rival.keyholes && !rival.thin && rival.feed_cap_scale == 1.0);
        assert!(variants[1..].iter().all(|v| v.rival().is_none()));
        assert_eq!(Variant::default().rival(), None);
        assert_eq!(Variant::original().rival(), None);
    }

    /// A variant's rivals: its own rival first, then the stretch twins of itself, of the first
    /// rewrite and of the first without keyholes, none twice and none the variant itself.
    #[test]
    fn the_rivals_are_the_rival_then_the_stretch_twins() {
        let twin = |v: Variant| Variant { stretch: true, ..v };
        let joined = quieter_variants().next().expect("a variant");
        let walked = joined.rival().expect("a rival");
        assert_eq!(
            joined.rivals(),
            [walked, twin(joined), twin(Variant::default())]
        );
        // Steps as walked have no twin of their own: their feeds would be the same.
        assert_eq!(walked.rivals(), [twin(Variant::default()), twin(joined)]);
        // A twin's rival is the plain rival (walked steps have no twin), its own twin itself.
        assert_eq!(twin(joined).rivals(), [walked, twin(Variant::default())]);
        assert_eq!(Variant::original().rivals(), []);
        assert!(quieter_variants().all(|v| !v.stretch) && !Variant::default().stretch);
    }

    /// With `stretch`, each scale is offered as it is, then with joined segments capped for
    /// their stretch, each first without a ceiling; without it, only as it is.
    #[test]
    fn stretch_offers_each_scale_again_for_the_stretch() {
        let mut s = smooth::tests::settings();
        let plain = writings(&s);
        assert!(plain.iter().all(|w| !w.stretch));
        assert_eq!(plain.len(), 2 * TUNING.cap_scales.len());
        s.stretch = true;
        let ways = writings(&s);
        assert_eq!(ways.len(), 2 * plain.len());
        for (k, four) in ways.chunks(4).enumerate() {
            let scale = TUNING.cap_scales[k];
            let got: Vec<(bool, bool)> = four.iter().map(|w| (w.stretch, w.ceiling)).collect();
            assert_eq!(
                got,
                [(false, false), (false, true), (true, false), (true, true)]
            );
            assert!(four
                .iter()
                .all(|w| w.scale == scale.map(|x| x * s.feed_cap_scale)));
        }
    }

    /// Within both limits nothing is cut; over the time, the allowance loses the excess and the
    /// margin's share of it; over the energy, it falls to the time spent less the excess
    /// energy's worth of time at the mean power, with the same margin.
    #[test]
    fn the_allowance_is_cut_by_what_goes_over() {
        let limits = Allowance {
            time_s: 10.0,
            energy_j: 0.0,
            mean_power_w: 50.0,
        };
        let m = TUNING.time_margin;
        assert_eq!(limits.cut(10.0, [10.0, 0.0]), None);
        assert_eq!(limits.cut(10.0, [-3.0, -100.0]), None);
        assert_eq!(limits.cut(10.0, [12.0, -1.0]), Some(10.0 - m * 2.0));
        assert_eq!(limits.cut(10.0, [6.0, 100.0]), Some(6.0 - m * 100.0 / 50.0));
        let both = limits.cut(10.0, [12.0, 100.0]).unwrap();
        assert!((both - ((10.0 - m * 2.0_f64).min(12.0) - m * 2.0)).abs() < 1e-12);
    }
}
