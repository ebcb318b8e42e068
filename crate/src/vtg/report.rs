//! The VTG report: tolerance and measured deviation, the paper's Table 1 (toolpath metrics) and
//! Table 2 (kinematic and energy figures), and `before` / `after` analyses.

use serde::Serialize;

use super::kinematics::KinematicLimits;
use super::rewrite::Rewritten;
use super::VtgOptions;
use crate::analyze::toolpath::ToolpathMetrics;
use crate::analyze::Report;

/// A figure before and after, and the relative change.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Comparison {
    /// Before VTG.
    pub before: f64,
    /// After VTG.
    pub after: f64,
    /// `(after − before) / before`, percent (0 when `before` is 0).
    pub change_pct: f64,
}

impl Comparison {
    /// Compares two figures.
    pub fn new(before: f64, after: f64) -> Self {
        let change_pct = if before != 0.0 && before.is_finite() && after.is_finite() {
            (after - before) / before * 100.0
        } else {
            0.0
        };
        Self {
            before,
            after,
            change_pct,
        }
    }
}

/// The paper's Table 1: toolpath parameters before and after.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Table1 {
    /// `L_total`, mm.
    pub l_total_mm: Comparison,
    /// `n_total`.
    pub n_total: Comparison,
    /// `L_infill`, mm.
    pub l_infill_mm: Comparison,
    /// `n_infill`.
    pub n_infill: Comparison,
    /// `n_turning` (turns above the critical angle).
    pub n_turning: Comparison,
    /// Mean turning angle, degrees.
    pub mean_turn_deg: Comparison,
    /// `mean(e_c)`, mm.
    pub mean_chord_error_mm: Comparison,
}

/// Deviation of the simulated tool from the programmed path (the paper's Table 2 kinematic
/// rows), from the dynamics model; filled in when that model is run on both files.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct DeviationComparison {
    /// Largest deviation, mm.
    pub max_mm: Comparison,
    /// Smallest deviation, mm.
    pub min_mm: Comparison,
    /// Mean deviation, mm.
    pub mean_mm: Comparison,
}

/// The paper's Table 2: kinematic and energy performance before and after.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Table2 {
    /// Simulated toolpath deviation (dynamics model); `null` until that model is run.
    pub deviation: Option<DeviationComparison>,
    /// Total energy `E`, J (VTG eq. 16).
    pub energy_j: Comparison,
    /// Servo (X/Y drive) energy, J.
    pub servo_energy_j: Comparison,
    /// Material, g.
    pub material_g: Comparison,
    /// Carbon emission, g CO₂ (VTG eq. 17).
    pub co2_g: Comparison,
    /// Print time, s.
    pub time_s: Comparison,
}

/// What the rewrite did to the paths.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct PathCounts {
    /// Extrusion paths with a turn above the critical angle.
    pub candidates: u64,
    /// Of those, paths rewritten (the rest could not be rounded within the tolerance, or their
    /// lines could not be replaced safely, and were kept).
    pub rewritten: u64,
    /// Moves replaced.
    pub replaced_moves: u64,
    /// Moves written in their place.
    pub written_moves: u64,
    /// Written segments whose curvature is above `K_cr`.
    pub above_k_cr_segments: u64,
    /// Of those, segments written with a lower feed rate (VTG eq. 29).
    pub lowered_feed_segments: u64,
    /// Rewritten paths whose VTG eq. 29 speeds were raised (up to 3×) so they cost no time.
    pub raised_caps: u64,
    /// Rewritten paths written without the VTG eq. 29 feed caps because even raised they would
    /// have made them slower than the original (the firmware's own cornering sets their
    /// speed).
    pub uncapped: u64,
    /// Rewritten paths that plan slower, or cost more motor energy, than the original even
    /// without caps, paid for out of half of what the other rewrites saved (a firmware that
    /// takes sharp corners faster than any fillet within the tolerance allows). With
    /// `allow_slower_pct`, also those bought with the time it allows.
    pub paid_from_savings: u64,
    /// Paths like those that the savings could not pay for, kept as they were.
    pub kept_for_time: u64,
    /// Paths kept as they were because rounding them would add more lines than the file's
    /// line budget had left (`allow_more_lines_pct`).
    pub kept_for_lines: u64,
    /// Paths without sharp corners written with arcs, as their own points lie, for the lines
    /// they save (only as many as the corners rounded elsewhere need).
    pub compacted: u64,
    /// Mean speed fluctuation of the interpolation steps, percent (VTG eq. 28).
    pub mean_speed_fluctuation_pct: f64,
    /// The scale the VTG eq. 29 speeds of every rewrite started from: 1, or higher where the
    /// dynamics model found that the rewrite at 1 left the machine ringing more than the
    /// original (see [`crate::vtg::VtgOptions::dynamics`]).
    pub feed_cap_scale: f64,
    /// Whether the walked steps were joined up to the firmware's segment budget
    /// ([`crate::vtg::VtgOptions::min_segment_time_ms`]); `false` where the dynamics model
    /// found the joined rewrite ringing more than the original and the steps as walked
    /// quieter (see [`crate::vtg::VtgOptions::dynamics`]).
    pub steps_joined: bool,
    /// Whether a segment that joins walked steps was also offered the VTG eq. 29 speed of the
    /// stretch it stands for (its mean curvature), not only that of the tightest of its steps:
    /// `true` where, with the dynamics model, that rewrite kept the no-dearer rule and left
    /// fewer sharp corners (see [`crate::vtg::VtgOptions::dynamics`]).
    pub stretch_caps: bool,
    /// Arcs (`G2`/`G3`) written (with the `arcs` option), each in place of several steps.
    pub arcs_written: u64,
    /// Single corners too tight to fillet that were turned round a keyhole loop instead
    /// (`keyhole`); 0 where the dynamics model found the loops left the machine
    /// ringing more than the original (see [`crate::vtg::VtgOptions::dynamics`]).
    pub keyholes: u64,
}

impl PathCounts {
    /// Whether no path was rewritten, with its corners rounded or compacted into arcs: the
    /// output is then the original's toolpath.
    pub(crate) fn rewrote_nothing(&self) -> bool {
        self.rewritten == 0 && self.compacted == 0
    }

    /// Why the file comes back as it was where no path was rewritten
    /// ([`PathCounts::rewrote_nothing`]), in the words the closed loop's hand-back uses;
    /// `None` where something was rewritten.
    pub(crate) fn nothing_rewritten(&self, critical_angle_deg: f64) -> Option<String> {
        if !self.rewrote_nothing() {
            return None;
        }
        let why = if self.candidates == 0 {
            format!("no path turns by more than the critical angle ({critical_angle_deg}°)")
        } else if self.kept_for_lines > 0 && self.kept_for_time > 0 {
            format!(
                "rounding the corners of any of the {} paths that have them would add lines \
                 (--allow-more-lines) or cost time or energy (--allow-slower) the file has none \
                 of to spare",
                self.candidates
            )
        } else if self.kept_for_lines > 0 {
            format!(
                "rounding the corners of any of the {} paths that have them would add lines, \
                 and the line budget has none to spare (--allow-more-lines)",
                self.candidates
            )
        } else if self.kept_for_time > 0 {
            format!(
                "rounding the corners of any of the {} paths that have them would cost time or \
                 energy the file has none of to spare (--allow-slower)",
                self.candidates
            )
        } else {
            format!(
                "none of the {} paths with sharp corners could be rounded within the tolerance \
                 at no cost",
                self.candidates
            )
        };
        Some(format!("kept the original: {why}"))
    }
}

/// Per-layer toolpath metrics before and after.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct LayerMetrics {
    /// Layer index.
    pub index: usize,
    /// Before.
    pub before: ToolpathMetrics,
    /// After.
    pub after: ToolpathMetrics,
}

/// Everything `vtg` says about a rewrite.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct VtgReport {
    /// Tolerance asked for, mm.
    pub tolerance_mm: f64,
    /// Largest distance of any written point or segment from the original path, mm (measured on
    /// the output polylines, sampled every tolerance/10).
    pub max_deviation_mm: f64,
    /// Critical angle δθ, degrees.
    pub critical_angle_deg: f64,
    /// Critical curvature `K_cr` (VTG eq. 30), 1/mm.
    pub k_cr_per_mm: f64,
    /// The limits `K_cr` is built from.
    pub limits: KinematicLimits,
    /// What was rewritten.
    pub paths: PathCounts,
    /// Table 1: toolpath parameters.
    pub table1: Table1,
    /// Table 2: kinematic and energy performance.
    pub table2: Table2,
    /// Per-layer toolpath metrics.
    pub layers: Vec<LayerMetrics>,
    /// Analysis of the input.
    pub before: Report,
    /// Analysis of the output.
    pub after: Report,
    /// Both files against the machine's segment budget: lines, bytes, short segments, the
    /// peak segment rate ([`super::firmware`]); `None` only while the report is assembled.
    pub firmware: Option<super::firmware::FirmwareReport>,
    /// Why the original was handed back unchanged, or why some layers were kept as they were,
    /// when either happened (`None`: the rewrite is the output as it is).
    pub message: Option<String>,
    /// Layers (0-based) kept as they were because, rewritten, they rang above the original's
    /// peak deviation in the dynamics model (empty: none).
    pub peak_layers_kept: Vec<usize>,
    /// Feed-only lines of the original (`G1 F6000` alone) folded into the moves that read
    /// them, or dropped where the next move sets its own feed: the same motion in fewer lines,
    /// spent on rounded corners (0 where the original is handed back).
    pub feed_lines_folded: u64,
    /// The rewritten G-code.
    #[serde(skip)]
    pub output: Vec<u8>,
    /// What the analysis of `output` kept of its planning pass, where it was analysed: its
    /// time estimates are refreshed, and its firmware figures read, from it instead of
    /// planning the file again.
    #[serde(skip)]
    pub(crate) output_kept: Option<OutputKept>,
}

/// What an analysis of a rewrite's output kept of its planning pass
/// ([`crate::analyze::analyze_keeping`]).
#[derive(Debug, Clone)]
pub(crate) struct OutputKept {
    /// The planner's clock at every line, where it was kept.
    pub(crate) clock: Option<crate::estimate::Clock>,
    /// Its segments, counted against the input's minimum segment time.
    pub(crate) segments: crate::plan::segments::SegmentCounts,
    /// Its trajectory metrics, the file's and its layers', at the run's critical angle.
    pub(crate) metrics: (ToolpathMetrics, Vec<ToolpathMetrics>),
}

/// Table 2 of the analyses `before` and `after`, with the dynamics model's `deviation` rows
/// where it ran.
pub(crate) fn table2(
    before: &Report,
    after: &Report,
    deviation: Option<DeviationComparison>,
) -> Table2 {
    let c = Comparison::new;
    Table2 {
        deviation,
        energy_j: c(before.energy.total_j, after.energy.total_j),
        servo_energy_j: c(before.energy.servo_j, after.energy.servo_j),
        material_g: c(before.material_g, after.material_g),
        co2_g: c(before.energy.co2_g, after.energy.co2_g),
        time_s: c(before.time_s, after.time_s),
    }
}

/// Assembles the report from the two files' analyses and trajectory metrics (the original's
/// measured once per run, [`super::metrics::from_path`]).
pub(crate) fn build(
    options: &VtgOptions,
    limits: &KinematicLimits,
    (before, after): (Report, Report),
    (mb, lb): &(ToolpathMetrics, Vec<ToolpathMetrics>),
    (ma, la): (ToolpathMetrics, Vec<ToolpathMetrics>),
    rewritten: Rewritten,
) -> VtgReport {
    let c = Comparison::new;
    let table1 = Table1 {
        l_total_mm: c(mb.l_total_mm, ma.l_total_mm),
        n_total: c(mb.n_total as f64, ma.n_total as f64),
        l_infill_mm: c(mb.l_infill_mm, ma.l_infill_mm),
        n_infill: c(mb.n_infill as f64, ma.n_infill as f64),
        n_turning: c(mb.n_turning as f64, ma.n_turning as f64),
        mean_turn_deg: c(mb.mean_turn_deg, ma.mean_turn_deg),
        mean_chord_error_mm: c(mb.mean_chord_error_mm, ma.mean_chord_error_mm),
    };
    let table2 = table2(&before, &after, None);
    let layers = lb
        .iter()
        .cloned()
        .zip(la)
        .enumerate()
        .map(|(index, (before, after))| LayerMetrics {
            index,
            before,
            after,
        })
        .collect();
    let w = rewritten.walk;
    VtgReport {
        tolerance_mm: options.tolerance_mm,
        max_deviation_mm: rewritten.max_deviation_mm,
        critical_angle_deg: options.critical_angle_deg,
        k_cr_per_mm: limits.critical_curvature(),
        limits: *limits,
        paths: PathCounts {
            candidates: rewritten.candidate_paths,
            rewritten: rewritten.rewritten_paths,
            replaced_moves: rewritten.replaced_moves,
            written_moves: rewritten.written_moves,
            above_k_cr_segments: rewritten.above_k_cr_segments,
            lowered_feed_segments: rewritten.lowered_segments,
            raised_caps: rewritten.raised_caps_paths,
            uncapped: rewritten.uncapped_paths,
            paid_from_savings: rewritten.paid_paths,
            kept_for_time: rewritten.kept_for_time,
            kept_for_lines: rewritten.kept_for_lines,
            compacted: rewritten.compacted_paths,
            mean_speed_fluctuation_pct: if w.steps > 0 {
                w.fluctuation_sum / w.steps as f64 * 100.0
            } else {
                0.0
            },
            feed_cap_scale: rewritten.feed_cap_scale,
            steps_joined: rewritten.steps_joined,
            stretch_caps: rewritten.stretch_caps,
            arcs_written: rewritten.arcs_written,
            keyholes: rewritten.keyholes,
        },
        table1,
        table2,
        layers,
        before,
        after,
        firmware: None,
        output: rewritten.output,
        output_kept: None,
        message: None,
        peak_layers_kept: Vec::new(),
        feed_lines_folded: 0,
    }
}
