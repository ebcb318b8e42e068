//! Vibration-suppressed toolpath generation (VTG paper section 3, eq. 18–31, Algorithm 1).
//!
//! [`vtg`] reads a file, finds its extrusion paths (runs of consecutive printing moves within
//! one feature), and rewrites each path that has a sharp corner (a turn above the critical
//! angle δθ): its corners are blended with the largest fillets the tolerance and the legs
//! allow ([`blend`]; two sharp corners across a short leg, such as infill turning back, are
//! rounded as one arc, [`hairpin`]), a cubic B-spline is fitted to the blended path by least squares
//! ([`fit`]), walked with the second-order Taylor interpolator and Newton correction of
//! Algorithm 1 ([`resample`]) in steps that each turn by less than 0.9 δθ, and the path's
//! filament is spread over the new points ([`rewrite`]). Where the curvature is above `K_cr`
//! (eq. 30, [`kinematics`]) the feed is lowered so `a_n`, `j_n` and the interpolation chord
//! error stay within eq. 29, never below the speed the machine had at the same place on the
//! original, and on classic-jerk firmware rising feeds are ramped so no junction stalls
//! ([`smooth`]). Travels, retractions and every other line are kept byte for byte. The result
//! is checked against the original independently ([`deviation`]) and compared with
//! [`metrics`] (Table 1) and the analysis (Table 2).

pub mod blend;
pub mod bspline;
pub mod deviation;
pub mod fit;
pub mod hairpin;
pub mod kinematics;
pub mod metrics;
pub mod report;
pub mod resample;
pub mod rewrite;
pub mod smooth;
pub mod source;

use serde::{Deserialize, Serialize};

use crate::analyze::{AnalyzeOptions, Progress};
use crate::error::{Error, ErrorKind};
pub use report::{Comparison, Table1, Table2, VtgReport};

/// Options of [`vtg`]. Every field is optional in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
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
    /// Interpolation period `T_s` of eq. 30, s (default 0.001: a 1 kHz firmware step planner).
    pub interpolation_period_s: f64,
    /// Normal jerk limit `J_n` of eq. 29–30, mm/s³. By default the machine's own: `A_n · f₁`,
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
    /// Table 2 (default true; it costs about as much as the rewrite itself).
    pub dynamics: bool,
}

impl Default for VtgOptions {
    fn default() -> Self {
        Self {
            analyze: AnalyzeOptions::default(),
            tolerance_mm: 0.1,
            critical_angle_deg: metrics::DEFAULT_CRITICAL_ANGLE_DEG,
            interpolation_period_s: 0.001,
            normal_jerk_mm_s3: None,
            nozzle_diameter_mm: 0.4,
            limit_feed: true,
            dynamics: true,
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
        Ok(())
    }
}

/// Rewrites `input` as a vibration-suppressed toolpath; see the module documentation.
pub fn vtg(input: &[u8], options: &VtgOptions) -> Result<VtgReport, Error> {
    vtg_with_progress(input, options, &mut |_| true)
}

/// [`vtg`] with progress reports (fraction done; return `false` to cancel).
pub fn vtg_with_progress(
    input: &[u8],
    options: &VtgOptions,
    progress: Progress<'_>,
) -> Result<VtgReport, Error> {
    options.validate()?;
    let cancelled = || Error::new(0, 0, ErrorKind::Cancelled);
    // Independent reads of the same bytes, side by side where there are threads. Extracting
    // the planned path costs about as much as the other two together (34 MB: 550 ms against
    // 150 + 220 ms), so it runs on its own.
    let (read, path) = crate::parallel::join(
        || {
            let before = crate::analyze::analyze(input, &options.analyze)?;
            let sources = source::move_sources(input, &options.analyze)?;
            Ok::<_, Error>((before, sources))
        },
        || crate::path::extract(input, &options.analyze, options.limit_feed),
    );
    let ((before, sources), path) = (read?, path?);
    if !progress(0.3) {
        return Err(cancelled());
    }
    let limits = rewrite::limits_for(&path, options);
    let mut step = |f: f64| progress(0.3 + 0.4 * f);
    let rewritten = rewrite::rewrite(input, &path, &sources, options, &limits, &mut step)?;
    if !progress(0.7) {
        return Err(cancelled());
    }
    // The output's metrics streamed, not from a kept move list: rounding corners can multiply
    // the moves tenfold.
    let (after, after_metrics) = crate::parallel::join(
        || crate::analyze::analyze(&rewritten.output, &options.analyze),
        || {
            metrics::from_input(
                &rewritten.output,
                &options.analyze,
                options.critical_angle_deg,
            )
        },
    );
    let (after, after_metrics) = (after?, after_metrics?);
    if !progress(0.9) {
        return Err(cancelled());
    }
    let mut report = report::build(
        options,
        &limits,
        before,
        after,
        &path,
        after_metrics,
        rewritten,
    );
    if options.dynamics {
        report.table2.deviation = simulated_deviation(input, &report.output, &options.analyze);
    }
    progress(1.0);
    Ok(report)
}

/// Table 2's deviation rows: the dynamics model on the original and on the rewritten file,
/// over printing moves (travels are not rewritten). `None` when the model cannot run (a print
/// too long to simulate, for instance): the rest of the report stands without it.
fn simulated_deviation(
    input: &[u8],
    output: &[u8],
    analyze: &AnalyzeOptions,
) -> Option<report::DeviationComparison> {
    let options = crate::dynamics::VibrationOptions {
        analyze: analyze.clone(),
        ..Default::default()
    };
    let before = crate::dynamics::vibration(input, &options).ok()?;
    let after = crate::dynamics::vibration(output, &options).ok()?;
    let (b, a) = (before.printing_deviation_mm, after.printing_deviation_mm);
    Some(report::DeviationComparison {
        max_mm: Comparison::new(b.max, a.max),
        min_mm: Comparison::new(b.min, a.min),
        mean_mm: Comparison::new(b.mean, a.mean),
    })
}
