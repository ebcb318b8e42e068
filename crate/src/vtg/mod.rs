//! Vibration-suppressed toolpath generation (VTG paper section 3, VTG eq. 21–31, Algorithm 1).
//!
//! [`vtg`] reads a file, finds its extrusion paths (runs of consecutive printing moves of one
//! feature) and rewrites each that turns by more than the critical angle δθ (VTG eq. 26).
//! Three parts do the work, each a folder:
//!
//! - **`stages`, the paper's**, per path: a cubic B-spline (VTG eq. 21–22, `bspline`) fitted by
//!   least squares to the path with its corners blended (`fit`), walked by Algorithm 1
//!   (`resample`: the second-order Taylor step of VTG eq. 27 with Newton correction, speed
//!   fluctuation VTG eq. 28) in steps that each turn by less than δθ, the filament spread over
//!   the new points, and the feed lowered where the curvature exceeds `K_cr` so `a_n`, `j_n`
//!   and the chord error stay within VTG eq. 29–30 (`kinematics`, `feed`), never below the
//!   original's own speed there.
//! - **`corners`, replacements for sharp corners**: the fillet or racing line (`blend`), two
//!   corners across a short leg as one arc (`hairpin`), a loop round a corner too tight to
//!   fillet (`keyhole`), a polygon placed for Klipper's look-ahead (`klipper`), and runs on a
//!   circle written as `G2`/`G3` (`arcs`).
//! - **`search`**: each path through the stages with its corners chosen and retried
//!   (`smooth`), offered written its free way and, where time may be spent, dearer ways
//!   (`rewrite`); the file-level choice within the allowed time (`budget`); and, where the
//!   dynamics model finds the result ringing more than the original, the whole file again
//!   with quieter variants. Its ladders of variants are one table, in `search`'s doc; the
//!   values they trade with are one struct, `tuning::Tuning`.
//!
//! Travels, retractions and every other line are kept byte for byte. The result is checked
//! against the original independently ([`deviation`]) and compared with [`metrics`] (Table 1,
//! VTG eq. 24–26 and 31) and the analysis (Table 2).

mod arc_support;
mod block;
mod closed_loop;
mod corners;
pub mod deviation;
pub mod feeds;
pub mod firmware;
pub mod metrics;
mod report;
mod search;
pub mod source;
mod stages;
mod tuning;

use crate::plan::segments::SegmentCounts;
use corners::{arcs, blend, hairpin};
use search::{budget, rewrite, smooth, smoothings};
use stages::{bspline, feed, fit, kinematics, resample, thin};

use serde::{Deserialize, Serialize};

use crate::analyze::toolpath::ToolpathMetrics;
use crate::analyze::{AnalyzeOptions, Report};
use crate::error::{Error, ErrorKind};
use crate::path::PrintPath;
use crate::progress::Progress;
pub use arc_support::ArcsMode;
pub use report::{
    Comparison, DeviationComparison, LayerMetrics, PathCounts, Table1, Table2, VtgReport,
};
pub use stages::kinematics::KinematicLimits;

/// Options of [`vtg`]. Every field is optional in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct VtgOptions {
    /// How the file is read and the machine it runs on (as `analyze`).
    pub analyze: AnalyzeOptions,
    /// Largest distance the new path may stray from the original, mm (default 0.1: under a
    /// quarter of a 0.45 mm line width, and the paper's own deviations are 0.14 mm; at 0.05 mm
    /// a 90° corner cannot be rounded in turns under 30° and is kept).
    pub tolerance_mm: f64,
    /// Critical angle δθ: turns above it are sharp corners, degrees (default 30).
    pub critical_angle_deg: f64,
    /// Interpolation period `T_s` of VTG eq. 30, s (default 0.001: a 1 kHz firmware step planner).
    pub interpolation_period_s: f64,
    /// Normal jerk limit `J_n` of VTG eq. 29–30, mm/s³. By default the machine's own: `A_n · f₁`,
    /// with `f₁` the lowest natural frequency of its X and Y drives in the dynamics model
    /// ([`crate::dynamics`], the parameter set that goes with the machine preset). An
    /// acceleration that builds up over at least one period of the first mode leaves little
    /// ringing behind (the reasoning of jerk-limited motion and input shaping); a rounded
    /// corner taken faster delivers its whole change of direction within one period, and
    /// excites the frame more than the sharp corner it replaced. For a Prusa-class belt
    /// printer (`A_n` 1000 mm/s², 43 Hz) that is 43 m/s³; servo CNC controllers are set to
    /// 100–1000 m/s³.
    pub normal_jerk_mm_s3: Option<f64>,
    /// Nozzle diameter (`R_n` is half of it), mm (default 0.4).
    pub nozzle_diameter_mm: f64,
    /// Lower the feed rate where the curvature exceeds `K_cr` (default true).
    pub limit_feed: bool,
    /// Run the dynamics model ([`crate::dynamics`]) on both files for the deviation rows of
    /// Table 2, and rewrite again with faster VTG eq. 29 speeds if the rewrite rings more than the
    /// original (default true; it costs about as much as the rewrite itself, more when it
    /// rewrites again). See `closed_loop::with_simulated_deviation`.
    pub dynamics: bool,
    /// Write runs of new points that lie on a circle as arcs (`G2`/`G3`) to cut the line
    /// count: `auto` (default) where the firmware runs them ([`ArcsMode::Auto`]: a file that
    /// already has arcs, Marlin, RepRapFirmware, Smoothieware and Repetier flavours, Klipper
    /// only with `[gcode_arcs]` in the printer config given), `on` or `off`.
    pub arcs: ArcsMode,
    /// Print time the rewrite may add to round corners that cost time, percent of the
    /// original's (default [`DEFAULT_ALLOW_SLOWER_PCT`], the bar). On a machine whose
    /// firmware takes sharp corners faster than any fillet within the tolerance (Klipper with a
    /// square-corner velocity of 50–100 mm/s) rounding costs time, and motor and standby
    /// energy with it: this buys the corners that remove the most sharp turns for their time
    /// first, energy weighed in, while the file's energy stays within
    /// [`VtgOptions::allow_more_energy_pct`]. Where rounding costs nothing
    /// (every Marlin file of the corpus) it changes nothing. 0: the print gets no slower and
    /// uses no more energy, the corners that would cost being paid only out of what the other
    /// rewrites save. 100 rounds every corner the tolerance allows.
    pub allow_slower_pct: f64,
    /// Total energy the rewrite may add, percent of the original's (default 0: the rewritten
    /// file uses no more energy than the original). The time [`VtgOptions::allow_slower_pct`]
    /// allows is spent only while the whole file's energy, as `analyze` measures it, stays
    /// within this; where it would not, the allowance is cut until it does.
    pub allow_more_energy_pct: f64,
    /// Round corners only on the inside, with fillets tangent to the legs (default false: where
    /// the path has room, a corner takes the racing line, easing out by up to the tolerance
    /// before it and back after it, round a circle 2.4 times wider at 90°; see
    /// `blend::racing`). The racing line moves a wall's edge outward by up to the tolerance
    /// near a corner, as the inside fillet moves it inward at the corner; this keeps every
    /// new point on or inside the corner's legs.
    pub inside_corners: bool,
    /// Rewrite the file's time comments and `M73` lines from the planner when the toolpath
    /// changed (default true; see [`crate::estimate`]).
    pub estimates: bool,
    /// The firmware's minimum segment time, ms (default: the file's last `M205 B`, else
    /// Marlin's 20 ms; see [`firmware::SegmentBudget`]). Algorithm 1's steps are joined up to
    /// `v · t_min` wherever the tolerance allows, so the firmware's buffer stays full; 0 joins
    /// as far as the tolerance and the turn allow.
    pub min_segment_time_ms: Option<f64>,
    /// Lines the rewritten file may have over the original's, percent (default 0: never more
    /// lines). Each rounded corner is walked in several steps where the original had one
    /// vertex; a firmware fed over a serial link or from an SD card reads only so many lines a
    /// second, and Marlin slows segments when its planner buffer runs low (see [`firmware`]).
    /// The rewrites that save lines pay for those that add them, the corners that cost the
    /// fewest lines first; the paths that do not fit are kept as they were (`kept_for_lines`).
    pub allow_more_lines_pct: f64,
    /// Where the dynamics model asks for quieter whole-file variants, write and simulate each
    /// whole (default false: on a file of 512 kB and 64 layers or more they race on every
    /// eighth layer first, and only the one that rings least there is written whole; the
    /// verdict is the whole file's either way). Slower on large files; the corpus files give
    /// the same output both ways.
    pub exhaustive: bool,
}

/// The print time the rewrite may add by default, percent: the bar. More rounds more
/// corners on machines that take sharp corners faster than round ones; 0 keeps every print
/// from getting slower (figures in `docs/method/vtg-tuning-notes.md`).
pub const DEFAULT_ALLOW_SLOWER_PCT: f64 = 1.0;

impl Default for VtgOptions {
    fn default() -> Self {
        Self {
            analyze: AnalyzeOptions::default(),
            tolerance_mm: 0.1,
            critical_angle_deg: crate::analyze::toolpath::DEFAULT_CRITICAL_ANGLE_DEG,
            interpolation_period_s: 0.001,
            normal_jerk_mm_s3: None,
            nozzle_diameter_mm: 0.4,
            limit_feed: true,
            dynamics: true,
            arcs: ArcsMode::Auto,
            allow_slower_pct: DEFAULT_ALLOW_SLOWER_PCT,
            allow_more_energy_pct: 0.0,
            inside_corners: false,
            estimates: true,
            min_segment_time_ms: None,
            allow_more_lines_pct: 0.0,
            exhaustive: false,
        }
    }
}

impl VtgOptions {
    fn validate(&self) -> Result<(), Error> {
        let bad = |reason: &'static str| Err(Error::new(0, 0, ErrorKind::InvalidOption { reason }));
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !pos(self.tolerance_mm) || self.tolerance_mm > 5.0 {
            return bad("tolerance_mm must be a number in (0, 5]");
        }
        if !self.critical_angle_deg.is_finite()
            || self.critical_angle_deg < 1.0
            || self.critical_angle_deg > 179.0
        {
            return bad("critical_angle_deg must be a number in [1, 179]");
        }
        if !pos(self.interpolation_period_s) || self.interpolation_period_s > 1.0 {
            return bad("interpolation_period_s must be a number in (0, 1]");
        }
        if !self.normal_jerk_mm_s3.is_none_or(pos) {
            return bad("normal_jerk_mm_s3 must be a positive number");
        }
        if !pos(self.nozzle_diameter_mm) || self.nozzle_diameter_mm > 10.0 {
            return bad("nozzle_diameter_mm must be a number in (0, 10]");
        }
        if !(0.0..=100.0).contains(&self.allow_slower_pct) {
            return bad("allow_slower_pct must be a number in [0, 100]");
        }
        if !(0.0..=100.0).contains(&self.allow_more_energy_pct) {
            return bad("allow_more_energy_pct must be a number in [0, 100]");
        }
        if !self
            .min_segment_time_ms
            .is_none_or(|v| (0.0..=1000.0).contains(&v))
        {
            return bad("min_segment_time_ms must be a number in [0, 1000]");
        }
        if !(0.0..=1000.0).contains(&self.allow_more_lines_pct) {
            return bad("allow_more_lines_pct must be a number in [0, 1000]");
        }
        Ok(())
    }
}

/// Rewrites `input` as a vibration-suppressed toolpath; see the module documentation.
pub fn vtg(input: &[u8], options: &VtgOptions) -> Result<VtgReport, Error> {
    vtg_with_progress(input, options, &mut |_| true)
}

/// [`vtg`] with progress reports (fraction done; return `false` to cancel). The fraction never
/// goes back: the closed loop's attempts report over spans of their own, but how many it makes
/// is known only as it goes, so the caller sees the furthest any has reached.
pub fn vtg_with_progress(
    input: &[u8],
    options: &VtgOptions,
    progress: Progress<'_>,
) -> Result<VtgReport, Error> {
    options.validate()?;
    let mut furthest = crate::progress::Furthest::new(progress);
    rewrite_file(input, options, &mut |f| furthest.report(f))
}

/// [`vtg_with_progress`] once the options are checked. Every rewrite starts from the original
/// with its feed-only lines folded into its moves ([`feeds`]): the same motion in fewer lines,
/// which the rewrite may spend on rounded corners. Where no path is rewritten the original
/// itself is handed back.
fn rewrite_file(
    input: &[u8],
    options: &VtgOptions,
    progress: Progress<'_>,
) -> Result<VtgReport, Error> {
    let cancelled = || Error::new(0, 0, ErrorKind::Cancelled);
    let folded = feeds::fold(input);
    let work = folded.as_ref().map_or(input, |f| &f.bytes[..]);
    let Original {
        before,
        before_segments,
        sources,
        path,
        path_metrics,
    } = read_original(input, (work, folded.as_ref()), options)?;
    if !progress(0.3) {
        return Err(cancelled());
    }
    // Arcs where the firmware runs them, decided once for every variant tried.
    let options = &VtgOptions {
        arcs: options.arcs.resolved(input, &before, &options.analyze),
        ..options.clone()
    };
    let folded_lines = folded.as_ref().map_or(0, |f| f.lines());
    let run = Run::new(
        (input, work, folded_lines),
        (&path, &sources, path_metrics),
        options,
    );
    let first = search::Variant::default();
    // The original's simulated deviation does not depend on the rewrite: where there are
    // threads, it runs beside the first one (on a long print it takes as long).
    let expected_s = before.time_s;
    let (original_deviation, report) = crate::parallel::join(
        || {
            options
                .dynamics
                .then(|| closed_loop::printing_deviation(work, expected_s, options))
        },
        || run.report((first, &[]), before, &mut |f| progress(0.3 + 0.4 * f)),
    );
    let mut report = report?;
    if !progress(0.7) {
        return Err(cancelled());
    }
    if let Some(original) = original_deviation {
        let mut again = Retry {
            run: &run,
            progress,
        };
        report =
            closed_loop::with_simulated_deviation(work, original, report, options, &mut again)?;
    }
    let report = unfolded_if_unchanged(report, (input, work), (folded_lines, options));
    // The move lists and the offers kept are done with (the estimates and the firmware's
    // figures stream): on the 34 MB file the lists are 450 MB of the peak, freed beside the
    // finish where there are threads (90 ms on one).
    let budget =
        firmware::SegmentBudget::for_file(input, path.junction_model, options.min_segment_time_ms);
    let Run {
        known, smoothings, ..
    } = run;
    let done_with = (known, smoothings, path, sources, folded);
    let ((), report) = crate::parallel::join(
        move || drop(done_with),
        || finish(input, report, options, (budget, before_segments)),
    );
    let report = report?;
    progress(1.0);
    Ok(report)
}

/// `report` as handed back: where nothing was rewritten, with the original `input` as it
/// came (not `work`, its feed lines folded, [`rewrite_file`]), else with the `folded` lines
/// counted. A report without a message, nothing rewritten, says why.
fn unfolded_if_unchanged(
    mut report: VtgReport,
    (input, work): (&[u8], &[u8]),
    (folded, options): (u64, &VtgOptions),
) -> VtgReport {
    if report.message.is_none() {
        report.message = report.paths.nothing_rewritten(options.critical_angle_deg);
    }
    if report.output == work {
        report.output = input.to_vec();
        report.after.file = report.before.file.clone();
    } else {
        report.feed_lines_folded = folded;
    }
    report
}

/// The original as every rewrite reads it: its analysis (with the firmware's segment figures
/// counted in its pass), its moves' sources, its planned path and that path's trajectory
/// metrics.
struct Original {
    before: Report,
    before_segments: Option<SegmentCounts>,
    sources: source::Sources,
    path: PrintPath,
    path_metrics: PathMetrics,
}

/// A file's trajectory metrics and its layers' ([`metrics::from_path`]).
type PathMetrics = (ToolpathMetrics, Vec<ToolpathMetrics>);

/// Reads [`Original`] in two passes side by side where there are threads: the analysis, which
/// plans the file and keeps each move's timing, and one pass for the path (unplanned), its
/// moves' sources and its metrics. The path takes its timing from the analysis: the same
/// planner fed the same moves, so the same timing to the bit as planning it again, which took
/// a sixth of the reading's CPU time on one thread while the analysis' threads were done.
/// The analysis is the original `input`'s (its lines and bytes are the report's), the path and
/// sources those of `work`, the file every rewrite starts from ([`rewrite_file`]), which moves
/// as it does, move for move.
fn read_original(
    input: &[u8],
    (work, folded): (&[u8], Option<&feeds::Folded>),
    options: &VtgOptions,
) -> Result<Original, Error> {
    let (read, path) = crate::parallel::join(
        || {
            let min_segment_s = firmware::min_segment_time_s(input, options.min_segment_time_ms);
            let keep = crate::analyze::Keep {
                starts: false,
                min_segment_s: Some(min_segment_s),
                layer_metrics_deg: None,
                timed_moves: options.limit_feed,
            };
            crate::analyze::analyze_keeping(input, &options.analyze, keep)
        },
        || {
            let (path, sources) = source::path_and_sources(work, &options.analyze, false)?;
            let metrics = metrics::from_path(&path, options.critical_angle_deg);
            Ok::<_, Error>((path, sources, metrics))
        },
    );
    let ((before, kept), (mut path, sources, path_metrics)) = (read?, path?);
    if let Some(mut timed) = kept.timed_moves {
        // Matched by line: the analysis numbers the original's lines.
        if let Some(folded) = folded {
            timed
                .iter_mut()
                .for_each(|t| t.line = folded.line_in_folded(t.line));
        }
        path.set_timing(&timed, before.time_s);
    }
    Ok(Original {
        before,
        before_segments: kept.segments,
        sources,
        path,
        path_metrics,
    })
}

/// The bytes of smoothed paths a run keeps for its later variants ([`smoothings`]): none
/// without the dynamics model (only its closed loop tries other variants), else eight times
/// the file's size, at most 48 MB. Smoothed paths are a few times the size of the lines they
/// replace (28 MB for every way of the 4.1 MB fabtotum file), so this keeps every path of a
/// file of a few megabytes, and a share of a large one's that adds little to the run's peak
/// (the 34 MB file's: 0.70 → 0.75 GB natively, the run 50 → 42 s).
fn smoothings_bound(input: &[u8], options: &VtgOptions) -> usize {
    if !options.dynamics {
        return 0;
    }
    input.len().saturating_mul(8).min(48 << 20)
}

/// One file being rewritten: what every whole-file attempt shares.
struct Run<'a> {
    /// The original with its feed-only lines folded ([`feeds`]).
    input: &'a [u8],
    path: &'a PrintPath,
    /// The original's trajectory metrics, file and layers ([`metrics::from_path`]).
    path_metrics: PathMetrics,
    sources: &'a source::Sources,
    /// What every rewrite's offers take from the file alone ([`rewrite::FilePaths`]).
    paths: rewrite::FilePaths,
    options: &'a VtgOptions,
    limits: KinematicLimits,
    /// Lines a rewrite may add to `input` ([`search::allowed_lines`]).
    allowed_lines: i64,
    /// The offers of the last rewrite and the layers it kept: a later rewrite of the same
    /// variant that keeps those layers and more (the closed loop's rounds) drops the offers of
    /// the others ([`rewrite::Offers::keep_layers`]) instead of making every path's again.
    known: std::sync::Mutex<Option<(rewrite::Offers, Vec<bool>)>>,
    /// The paths smoothed so far, for the variants that smooth them the same way.
    smoothings: std::sync::Mutex<smoothings::Smoothings>,
}

/// What a rewrite's attempt measures of its output beside its analysis ([`Run::attempt`]).
type Also<'a, X> = &'a (dyn Fn(&[u8]) -> X + Sync);

impl<'a> Run<'a> {
    /// The run of `work`, the original `input` with its `folded` feed-only lines folded
    /// ([`feeds`]), read as `path`, `sources` and `metrics` ([`read_original`]).
    fn new(
        (input, work, folded): (&[u8], &'a [u8], u64),
        (path, sources, metrics): (&'a PrintPath, &'a source::Sources, PathMetrics),
        options: &'a VtgOptions,
    ) -> Self {
        Run {
            input: work,
            path,
            path_metrics: metrics,
            sources,
            paths: rewrite::FilePaths::of(work, path, sources, options),
            options,
            limits: rewrite::limits_for(path, options),
            // The original's lines, and those its folded lines free.
            allowed_lines: search::allowed_lines(input, options) + folded as i64,
            known: std::sync::Mutex::new(None),
            smoothings: std::sync::Mutex::new(smoothings::Smoothings::new(smoothings_bound(
                input, options,
            ))),
        }
    }

    /// One rewrite tried as `variant`, the layers `kept` marks left as they are, analysed and
    /// reported (`before`: the original's analysis), and what `also` measures of its output,
    /// beside its analysis.
    fn attempt<X: Send>(
        &self,
        (variant, kept): (search::Variant, &[bool]),
        before: Report,
        (progress, also): (Progress<'_>, Also<'_, X>),
    ) -> Result<(VtgReport, X), Error> {
        let Run {
            options, limits, ..
        } = *self;
        let beside = |output: &[u8]| also(output);
        let (rewritten, measured) =
            self.rewrite((variant, kept), &before, Some(&beside), progress)?;
        let (after, mut kept, also) = match measured {
            Some((after, kept, Some(beside))) => (after, kept, beside),
            Some((after, kept, None)) => (after, kept, also(&rewritten.output)),
            // Analysed even where [`finish`] analyses the file again with its estimates
            // refreshed: the clock and the segments kept here spare it a planning walk for
            // each, which take longer on one thread than this pass takes on two.
            None => {
                let (analysed, alongside) = crate::parallel::join(
                    || search::analysed(&rewritten.output, self.input, options),
                    || also(&rewritten.output),
                );
                let (after, kept) = analysed?;
                (after, kept, alongside)
            }
        };
        // The output's metrics, taken by its analysis (streamed: rounding corners can
        // multiply the moves tenfold).
        let after_metrics = std::mem::take(&mut kept.metrics);
        let mut report = report::build(
            options,
            &limits,
            (before, after),
            &self.path_metrics,
            after_metrics,
            rewritten,
        );
        report.output_kept = Some(kept);
        Ok((report, also))
    }

    /// [`Run::attempt`] with nothing measured beside the analysis.
    fn report(
        &self,
        tried: (search::Variant, &[bool]),
        before: Report,
        progress: Progress<'_>,
    ) -> Result<VtgReport, Error> {
        let (report, ()) = self.attempt(tried, before, (progress, &|_: &[u8]| ()))?;
        Ok(report)
    }

    /// The last rewrite's offers with the layers `kept` marks dropped, where it was of `variant`
    /// and kept no layer that `kept` does not. Either way they are taken: the rewrite about to
    /// be made replaces them when it is done, so offers it cannot use are freed before it
    /// makes its own (on the 34 MB file, up to 40 MB of the closed loop's peak).
    fn known_offers(&self, variant: search::Variant, kept: &[bool]) -> Option<rewrite::Offers> {
        let (mut offers, was_kept) = self.known.lock().ok()?.take()?;
        let covered = (was_kept.iter().enumerate()).all(|(l, &k)| !k || kept.get(l) == Some(&true));
        if offers.variant() != variant || !covered {
            return None;
        }
        offers.keep_layers(kept);
        Some(offers)
    }

    /// The file rewritten as `variant`, the layers `kept` marks left as they are, within the
    /// time and lines allowed (`before`: the original's analysis), and its analysis where the
    /// allowance measured it, with what `beside` measured of it meanwhile; progress to 0.8.
    fn rewrite<T>(
        &self,
        (variant, kept): (search::Variant, &[bool]),
        before: &Report,
        beside: Option<search::Beside<'_, T>>,
        progress: Progress<'_>,
    ) -> Result<(rewrite::Rewritten, Option<search::Measured<T>>), Error> {
        let offers = self.offers((variant, kept), progress)?;
        let written =
            search::within_allowed_time(self.input, &offers, (self.options, before), beside);
        self.remember(offers, kept);
        written
    }

    /// [`Run::rewrite`] as a race's trial needs it: the first choice within the time allowed
    /// written as its own forecast keeps it, not analysed ([`search::within_forecast_time`]).
    fn rewrite_for_trial(
        &self,
        (variant, kept): (search::Variant, &[bool]),
        before: &Report,
        progress: Progress<'_>,
    ) -> Result<rewrite::Rewritten, Error> {
        let offers = self.offers((variant, kept), progress)?;
        let written = search::within_forecast_time(self.input, &offers, (self.options, before));
        self.remember(offers, kept);
        Ok(written)
    }

    /// The offers of a rewrite as `variant`, the layers `kept` marks left as they are: the last
    /// rewrite's where they serve ([`Run::known_offers`]), else made; progress to 0.8.
    fn offers(
        &self,
        (variant, kept): (search::Variant, &[bool]),
        progress: Progress<'_>,
    ) -> Result<rewrite::Offers, Error> {
        let offers = match self.known_offers(variant, kept) {
            Some(offers) => offers,
            None => {
                let mut kept_smoothings = self.smoothings.lock().ok();
                let mut none = smoothings::Smoothings::new(0);
                let smoothings = kept_smoothings.as_deref_mut().unwrap_or(&mut none);
                rewrite::offers(
                    self.input,
                    (self.path, self.sources, &self.paths),
                    (self.options, &self.limits, self.allowed_lines),
                    (variant, kept),
                    (smoothings, &mut |f: f64| progress(0.8 * f)),
                )?
            }
        };
        if !progress(0.8) {
            return Err(Error::new(0, 0, ErrorKind::Cancelled));
        }
        Ok(offers)
    }

    /// `offers`, made for the layers `kept` marks left as they are, kept for the next rewrite.
    fn remember(&self, offers: rewrite::Offers, kept: &[bool]) {
        if let Ok(mut known) = self.known.lock() {
            *known = Some((offers, kept.to_vec()));
        }
    }
}

/// The closed loop's rewrites of one file ([`closed_loop::Again`]), each reporting its progress
/// over the span of the job's the loop gives it.
struct Retry<'r, 'p> {
    run: &'r Run<'r>,
    progress: Progress<'p>,
}

impl closed_loop::Again for Retry<'_, '_> {
    fn report(
        &mut self,
        variant: search::Variant,
        kept: &[bool],
        before: Report,
        (from, width): closed_loop::Span,
    ) -> Result<VtgReport, Error> {
        let progress = &mut |g| (self.progress)(from + width * g);
        self.run.report((variant, kept), before, progress)
    }

    fn simulated(
        &mut self,
        variant: search::Variant,
        kept: &[bool],
        before: Report,
        (from, width): closed_loop::Span,
    ) -> Result<(VtgReport, Option<closed_loop::Simulated>), Error> {
        // The split of a long print's run depends on the original alone: a rewrite plans within
        // a percent of its time, and its own is known only once the analysis beside it is done.
        let expected_s = before.time_s;
        let options = self.run.options;
        let simulate = |output: &[u8]| closed_loop::printing_deviation(output, expected_s, options);
        let progress = &mut |g| (self.progress)(from + width * g);
        (self.run).attempt((variant, kept), before, (progress, &simulate))
    }

    fn measured(
        &mut self,
        variant: search::Variant,
        kept: &[bool],
        before: &Report,
        ((from, width), measure): (closed_loop::Span, closed_loop::Measure<'_>),
    ) -> Result<(closed_loop::Sampled, u64), Error> {
        let progress = &mut *self.progress;
        let rewritten = (self.run)
            .rewrite_for_trial((variant, kept), before, &mut |g| progress(from + width * g))?;
        Ok((measure(&rewritten.output), rewritten.corners_removed))
    }
}

/// Lines the refreshed time estimates add to the file's header ([`finish`]): its note and the
/// estimate's own line.
pub(crate) const ESTIMATE_HEADER_LINES: i64 = 2;

/// The report as handed back: its file's time comments and `M73` lines rewritten from the
/// planner ([`crate::estimate::refresh`]) when the toolpath changed and the options ask for
/// it, and the file measured against the machine's segment budget ([`firmware`]) beside the
/// original's figures. Each file's figures are read from the segments its analysis counted
/// where it kept them (`before`: the original's; the output's in its report), else by a
/// planning walk of their own, side by side with other work where there are threads; the
/// estimates are refreshed from the clock the output's analysis kept, where it did.
fn finish(
    input: &[u8],
    mut report: VtgReport,
    options: &VtgOptions,
    (budget, before): (firmware::SegmentBudget, Option<SegmentCounts>),
) -> Result<VtgReport, Error> {
    let figures = |bytes: &[u8], counted: Option<SegmentCounts>| match counted {
        Some(counts) => Ok(firmware::FirmwareFigures::of(bytes, counts, &budget)),
        None => firmware::figures(bytes, &options.analyze, &budget),
    };
    let note = format!("vtg: corners rounded within {} mm", options.tolerance_mm);
    let kept = report.output_kept.take();
    let after_counts = kept.as_ref().map(|k| k.segments);
    let (refreshed, before) = crate::parallel::join(
        || {
            let after_figures = |bytes: &[u8]| figures(bytes, after_counts);
            // Where the file carries estimates: `refresh_beside` asks (on a file without any
            // it reads every line).
            if options.estimates && report.output != input {
                let clock = kept.as_ref().and_then(|k| k.clock.as_ref());
                let job = (note.as_str(), clock, Some(&report.after));
                crate::estimate::refresh_beside(
                    &report.output,
                    &options.analyze,
                    job,
                    after_figures,
                )
            } else {
                Ok((None, after_figures(&report.output)))
            }
        },
        || figures(input, before),
    );
    let (refreshed, after) = refreshed?;
    if let Some((output, analysis)) = refreshed {
        report.output = output;
        report.table2 = report::table2(&report.before, &analysis, report.table2.deviation);
        report.after = analysis;
    }
    report.firmware = Some(firmware::FirmwareReport::new(budget, before?, after?));
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Without the model, the report's `after` and Table 2 are the analysis of the file handed
    /// back, estimates refreshed (not of the rewrite before the refresh), and the firmware
    /// figures, counted in the analyses' passes, those a planning walk of each file counts.
    #[test]
    fn the_report_analyses_the_file_handed_back() {
        let demo = include_bytes!("../../../www/demo/demo.gcode");
        let options = VtgOptions {
            dynamics: false,
            ..VtgOptions::default()
        };
        let r = vtg(demo, &options).unwrap();
        assert!(crate::estimate::has_estimates(&r.output) && r.output != demo);
        let written = crate::analyze::analyze(&r.output, &options.analyze).unwrap();
        assert_eq!(r.after, written);
        assert_eq!(r.table2.time_s.after, written.time_s);
        assert_eq!(r.table2.energy_j.after, written.energy.total_j);
        assert_eq!(r.table2.material_g.after, written.material_g);
        assert_ne!(r.after, r.before);
        let f = r.firmware.expect("figures");
        let walked = |bytes: &[u8]| firmware::figures(bytes, &options.analyze, &f.budget).unwrap();
        assert_eq!((f.before, f.after), (walked(demo), walked(&r.output)));
    }

    /// A race's trial writes what the whole-file rewrite writes where the analysis confirms
    /// the time allowance's first choice, without that analysis: on a Klipper square whose
    /// corners are bought with time, with the allowance spent (2 %) and none allowed.
    #[test]
    fn a_trial_writes_the_confirmed_choice_without_analysing_it() {
        let mut src =
            String::from("SET_VELOCITY_LIMIT ACCEL=5000 SQUARE_CORNER_VELOCITY=50\nM83\n");
        src.push_str("G1 X60 Y50 F30000\nG1 Z0.2\nG1 F12000\n");
        for _ in 0..10 {
            for (x, y) in [(70, 50), (70, 70), (50, 70), (50, 50)] {
                src.push_str(&format!("G1 X{x} Y{y} E0.6\n"));
            }
        }
        for (allow, bought) in [(2.0, true), (0.0, false)] {
            let options = VtgOptions {
                dynamics: false,
                allow_slower_pct: allow,
                allow_more_energy_pct: 10.0,
                allow_more_lines_pct: 1000.0,
                ..Default::default()
            };
            let input = src.as_bytes();
            let o = read_original(input, (input, None), &options).unwrap();
            let run = Run::new(
                (input, input, 0),
                (&o.path, &o.sources, o.path_metrics),
                &options,
            );
            let tried = (search::Variant::default(), &[][..]);
            let (whole, measured) = run
                .rewrite::<()>(tried, &o.before, None, &mut |_| true)
                .unwrap();
            let trial = run
                .rewrite_for_trial(tried, &o.before, &mut |_| true)
                .unwrap();
            assert_eq!(trial.output, whole.output);
            assert_eq!(trial.corners_removed, whole.corners_removed);
            // Analysed where time was allowed, and bought within it; else written free.
            assert_eq!(measured.is_some(), bought);
            if let Some((after, _, _)) = measured {
                assert!(after.time_s > o.before.time_s);
                assert!(after.time_s <= o.before.time_s * (1.0 + allow / 100.0));
            }
        }
    }

    /// A file that comes back as it was, nothing rewritten, says why: here no corner is sharp.
    #[test]
    fn a_file_with_nothing_to_rewrite_says_so() {
        let straight = b"G21\nG90\nM83\nG1 Z0.2 F600\nG1 X10 Y10 F6000\nG1 X60 Y10 E2 F1800\n\
G1 X110 Y12 E2\n";
        for dynamics in [false, true] {
            let options = VtgOptions {
                dynamics,
                ..VtgOptions::default()
            };
            let r = vtg(straight, &options).unwrap();
            assert_eq!(r.output, straight);
            assert_eq!(
                r.message.as_deref(),
                Some("kept the original: no path turns by more than the critical angle (30°)")
            );
        }
    }

    #[test]
    fn out_of_range_options_are_refused_by_name() {
        let demo = include_bytes!("../../../www/demo/demo.gcode");
        let d = VtgOptions::default;
        let cases = [
            (
                "tolerance_mm",
                VtgOptions {
                    tolerance_mm: 0.0,
                    ..d()
                },
            ),
            (
                "critical_angle_deg",
                VtgOptions {
                    critical_angle_deg: 180.0,
                    ..d()
                },
            ),
            (
                "allow_slower_pct",
                VtgOptions {
                    allow_slower_pct: -1.0,
                    ..d()
                },
            ),
            (
                "allow_slower_pct",
                VtgOptions {
                    allow_slower_pct: f64::NAN,
                    ..d()
                },
            ),
            (
                "allow_slower_pct",
                VtgOptions {
                    allow_slower_pct: 100.5,
                    ..d()
                },
            ),
        ];
        for (name, options) in &cases {
            let e = vtg(demo, options).expect_err(name);
            assert!(matches!(e.kind, ErrorKind::InvalidOption { .. }), "{e}");
            assert!(e.to_string().contains(name), "{e}");
        }
    }
}
