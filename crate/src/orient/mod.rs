//! Tool-orientation smoothing for multi-axis toolpaths.
//!
//! Implements the hybrid approach of "Tool orientation smoothing for multi-axis additive
//! manufacturing" (CIRP CMS 2022, seed `002`): the tool vectors along each continuous path are
//! smoothed with a median or moving-average filter (causal or zero-phase, section 3.2), and every
//! smoothed vector that leaves the tolerance cone of opening `γ` around its original build
//! direction is rotated back onto the cone's edge (CIRP eq. 4–7). The result is written back
//! through a kinematic model ([`kinematics`]) as new rotary angles and, in machine coordinates,
//! the machine XYZ that keeps the tool tip on the same workpiece path (in workpiece coordinates,
//! [`Coordinates::Workpiece`], X, Y, Z are the tip and stay). The paper's test parts are
//! [`quarter_torus`] (CIRP eq. 1) and [`square_tube`] (CIRP eq. 2).
//!
//! ```
//! use quietpath::orient::{smooth, SmoothOptions};
//! // Table-tilting B / rotary C: a kink of the tool tilt in the middle of a printed line.
//! let gcode = b"G90\nG0 X10 Y0 Z1 B-10 C0\nG1 X10 Y1 Z1 B-10 C0 E1 F600\n\
//! G1 X10 Y2 Z1 B-30 C0 E2\nG1 X10 Y3 Z1 B-10 C0 E3\nG1 X10 Y4 Z1 B-10 C0 E4\n";
//! let report = smooth(gcode, &SmoothOptions::default()).unwrap();
//! assert_eq!(report.points, 4);
//! assert!(report.max_angle_to_original_deg <= 30.0);
//! assert!(report.after.roughness < report.before.roughness);
//! assert_eq!(report.output.split(|&b| b == b'\n').count(), 7);
//! ```

pub mod cone;
pub mod core;
pub mod drawing;
pub mod filter;
pub mod frames;
pub mod generators;
pub mod kinematics;
pub mod metrics;
pub mod points;
mod program;
mod words;

use serde::{Deserialize, Serialize};

use crate::analyze::AnalyzeOptions;
use crate::error::{Error, ErrorKind, Warning};
use crate::progress::Progress;

pub use drawing::{layer_geometries, tool_vectors};
pub use filter::{FilterKind, Window};
pub use generators::{quarter_torus, square_tube, PartOptions};
pub use kinematics::{KinematicModel, Kinematics, Pose};
pub use metrics::{OrientationMetrics, RotaryMetrics, Sample};
pub use points::PointVector;

/// Input format of [`smooth`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum InputFormat {
    /// G-code unless the data looks like JSON (`[`) or CSV (a first row of six numbers or an
    /// `x,y,z,i,j,k` header).
    #[default]
    Auto,
    /// Multi-axis G-code.
    Gcode,
    /// CSV `x,y,z,i,j,k[,path]`.
    Csv,
    /// JSON array of `{x, y, z, i, j, k, path?}`.
    Json,
}

/// What the X, Y, Z words of multi-axis G-code are.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "snake_case")]
pub enum Coordinates {
    /// Machine axes: the tool tip in the workpiece frame follows through the kinematic model
    /// (no RTCP); smoothing rewrites X, Y, Z and the rotary words.
    #[default]
    Machine,
    /// The tool tip in the workpiece frame, as a controller with RTCP / TCPM active reads them
    /// (the paper's robot cell, many 5-axis printers); the rotary words give the orientation
    /// through the kinematic model. Smoothing keeps X, Y, Z and rewrites only the rotary words.
    Workpiece,
}

/// Options of [`smooth`]. Every field is optional in JSON.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct SmoothOptions {
    /// Kinematic model (default: table-tilting B then rotary C, axes through the origin, as in
    /// the corpus 5-axis file).
    pub kinematics: Kinematics,
    /// G-code: what X, Y, Z are (default machine axes).
    pub coordinates: Coordinates,
    /// Filter (default: zero-phase moving average, the paper's choice).
    pub filter: FilterKind,
    /// Window (default: 15 points).
    pub window: Window,
    /// Opening `γ` of the tolerance cone, degrees (default 60, the paper's FFF value); every
    /// output vector stays within `γ/2` of its original.
    pub cone_deg: f64,
    /// Keep-out angle around the kinematic singularity (the table's C axis, the head's B = ±90°),
    /// degrees; 0 disables. Points whose original vector is inside it are kept as written, and a
    /// smoothed vector is kept at least `min(singular_deg, tilt of its original)` away from it.
    /// Default (`None`): 6° for G-code (the λ of the corpus file's generator), 0 for point-vector
    /// data (a robot cell has no turntable singularity; the kinematics only serve the metrics).
    pub singular_deg: Option<f64>,
    /// Longest tool-tip step between two points of one continuous path, mm, measured in the
    /// workpiece frame (default 5, the jump length of the corpus file's generator). A longer
    /// step is a jump to another section: the filter does not average across it (in G-code the
    /// jumping move stays as written). Machine-axis travel is no criterion: the table swinging
    /// round a corner of the path moves the axes far for a short tip step (CIRP section 2.2).
    pub max_gap_mm: f64,
    /// Decimals written for the rewritten axis words (default 3).
    pub decimals: u8,
    /// Input format (default: detected).
    pub format: InputFormat,
    /// Point-vector data: feed used for the rotary-axis timing, mm/s (default 6, the paper's
    /// 36 cm/min travel speed).
    pub feed_mm_s: f64,
    /// How G-code is read and planned (machine preset, limits).
    pub analyze: AnalyzeOptions,
    /// Rewrite a G-code file's time comments and `M73` lines from the planner when the file
    /// changed (default true; see [`crate::estimate`]).
    pub estimates: bool,
}

impl Default for SmoothOptions {
    fn default() -> Self {
        SmoothOptions {
            kinematics: Kinematics::default(),
            coordinates: Coordinates::Machine,
            filter: FilterKind::default(),
            window: Window::default(),
            cone_deg: 60.0,
            singular_deg: None,
            max_gap_mm: 5.0,
            decimals: 3,
            format: InputFormat::Auto,
            feed_mm_s: 6.0,
            analyze: AnalyzeOptions::default(),
            estimates: true,
        }
    }
}

impl SmoothOptions {
    /// Checks every setting.
    pub fn validate(&self) -> Result<(), Error> {
        let bad = |reason| Err(Error::new(0, 0, ErrorKind::InvalidOption { reason }));
        if !(self.cone_deg.is_finite() && self.cone_deg > 0.0 && self.cone_deg <= 360.0) {
            return bad("cone_deg must be in (0, 360]");
        }
        if self
            .singular_deg
            .is_some_and(|d| !(d.is_finite() && (0.0..=90.0).contains(&d)))
        {
            return bad("singular_deg must be in [0, 90]");
        }
        if self.max_gap_mm.is_nan() || self.max_gap_mm <= 0.0 {
            return bad("max_gap_mm must be positive (may be infinite)");
        }
        if !(1..=9).contains(&self.decimals) {
            return bad("decimals must be between 1 and 9");
        }
        if !(self.feed_mm_s.is_finite() && self.feed_mm_s > 0.0) {
            return bad("feed_mm_s must be finite and positive");
        }
        if let Err(reason) = self.window.validate() {
            return bad(reason);
        }
        if let Err(reason) = self.kinematics.validate() {
            return bad(reason);
        }
        Ok(())
    }
}

/// Rotary angles per point before and after, decimated to at most [`SERIES_MAX`] points (for a
/// chart). `first_*` is the tilt axis (`axes[0]`), `second_*` the other.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(test, ts(rename = "SmoothSeries"))]
pub struct Series {
    /// Axis letters, e.g. `["B", "C"]`.
    pub axes: Vec<String>,
    /// Index of each kept point among all smoothed points.
    pub point: Vec<u32>,
    /// First rotary axis before, degrees.
    pub first_before: Vec<f64>,
    /// First rotary axis after, degrees.
    pub first_after: Vec<f64>,
    /// Second rotary axis before, degrees.
    pub second_before: Vec<f64>,
    /// Second rotary axis after, degrees.
    pub second_after: Vec<f64>,
    /// Angle between the tool vector after and before, degrees.
    pub angle_to_original_deg: Vec<f64>,
}

/// Most points kept in [`Series`].
pub const SERIES_MAX: usize = 2000;

/// What [`smooth`] did.
#[derive(Debug, Clone, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct SmoothReport {
    /// Input format that was read.
    pub format: InputFormat,
    /// Kinematic model used.
    pub kinematics: KinematicModel,
    /// What X, Y, Z were read as (G-code).
    pub coordinates: Coordinates,
    /// Filter used.
    pub filter: FilterKind,
    /// Window used.
    pub window: Window,
    /// Cone opening `γ`, degrees.
    pub cone_deg: f64,
    /// Motion lines in the input (G-code `G0`/`G1`; point count for point data); the output has
    /// the same number.
    pub motion_lines: usize,
    /// Points smoothed (extruding straight moves of G-code).
    pub points: usize,
    /// Continuous runs (paths) they form.
    pub runs: usize,
    /// Points whose smoothed vector left the cone and was put back on its edge (CIRP eq. 7).
    pub corrected: usize,
    /// Lines (points) whose written values changed.
    pub changed: usize,
    /// Largest angle between an output tool vector and its original, degrees (≤ `γ/2`,
    /// measured on the written values).
    pub max_angle_to_original_deg: f64,
    /// Mean of the same angle, degrees.
    pub mean_angle_to_original_deg: f64,
    /// Orientation metrics of the input.
    pub before: OrientationMetrics,
    /// Orientation metrics of the output (G-code: re-read and re-planned).
    pub after: OrientationMetrics,
    /// `1 − after.roughness / before.roughness` (0 when there is nothing to smooth).
    pub roughness_reduction: f64,
    /// Largest tool-tip displacement in the workpiece frame between input and output, mm (only
    /// the rounding of the written words).
    pub max_tip_deviation_mm: f64,
    /// G-code: the input's planned print time, s (quietpath's planner limits X, Y, Z and E).
    pub planned_time_before_s: f64,
    /// G-code: the output's planned print time, s. Without RTCP the feed applies to the machine
    /// XYZ motion, and smoother orientation needs less compensating XYZ motion, so the output
    /// usually plans faster. The planner knows no rotary-axis limits, so a rewritten move whose
    /// XYZ motion shrinks would get an unbounded rotary speed; the rotary rates in
    /// [`SmoothReport::before`] and [`SmoothReport::after`] are therefore both measured on the
    /// tool tip's planned schedule (the file's X, Y, Z replaced by the tip, as an RTCP
    /// controller runs it; the same for both files, whose tips agree within rounding).
    pub planned_time_after_s: f64,
    /// Per-point rotary angles for a chart.
    pub series: Series,
    /// Warnings met while reading.
    pub warnings: Vec<Warning>,
    /// The output file (same format as the input).
    #[serde(skip)]
    pub output: Vec<u8>,
}

/// Smooths the tool orientation of `input` (multi-axis G-code or point-vector CSV/JSON).
pub fn smooth(input: &[u8], options: &SmoothOptions) -> Result<SmoothReport, Error> {
    smooth_with_progress(input, options, &mut |_| true)
}

/// [`smooth`] with a progress callback (fraction done; `false` cancels).
pub fn smooth_with_progress(
    input: &[u8],
    options: &SmoothOptions,
    progress: Progress<'_>,
) -> Result<SmoothReport, Error> {
    options.validate()?;
    let format = match options.format {
        InputFormat::Auto => detect(input),
        f => f,
    };
    match format {
        InputFormat::Csv | InputFormat::Json => {
            let pts = if format == InputFormat::Csv {
                points::parse_csv(input)?
            } else {
                points::parse_json(input)?
            };
            let (mut report, out) = smooth_points_with_progress(&pts, options, progress)?;
            report.format = format;
            report.output = if format == InputFormat::Csv {
                points::write_csv(&out)
            } else {
                points::write_json(&out)
            };
            Ok(report)
        }
        _ => {
            let mut report = gcode_job::run(input, options, progress)?;
            if options.estimates && report.output != input {
                let note = format!(
                    "smooth: tool orientation within a {}° cone",
                    options.cone_deg
                );
                // The job reports no analysis of its output: the estimates alone, no pass to
                // analyse the file they are written into.
                if crate::estimate::has_estimates(&report.output) {
                    let notes = [note];
                    let e = crate::estimate::rewrite_estimates(
                        &report.output,
                        &options.analyze,
                        &notes,
                    )?;
                    report.output = e.output;
                }
            }
            Ok(report)
        }
    }
}

/// Guesses the input format.
pub fn detect(input: &[u8]) -> InputFormat {
    let text = input
        .iter()
        .position(|b| !b.is_ascii_whitespace())
        .and_then(|i| input.get(i..))
        .unwrap_or(&[]);
    if text.first() == Some(&b'[') {
        return InputFormat::Json;
    }
    let first = text.split(|&b| b == b'\n').next().unwrap_or(&[]);
    let first = String::from_utf8_lossy(first);
    let fields: Vec<&str> = first.split(',').map(str::trim).collect();
    let header = fields.first().is_some_and(|f| f.eq_ignore_ascii_case("x")) && fields.len() >= 6;
    let numbers =
        (6..=7).contains(&fields.len()) && fields.iter().all(|f| f.parse::<f64>().is_ok());
    if header || numbers {
        InputFormat::Csv
    } else {
        InputFormat::Gcode
    }
}

/// Smooths point-vector data; returns the report (without output bytes) and the new points
/// (same positions, smoothed unit vectors).
pub fn smooth_points(
    input: &[PointVector],
    options: &SmoothOptions,
) -> Result<(SmoothReport, Vec<PointVector>), Error> {
    smooth_points_with_progress(input, options, &mut |_| true)
}

/// [`smooth_points`] with a progress callback.
pub fn smooth_points_with_progress(
    input: &[PointVector],
    options: &SmoothOptions,
    progress: Progress<'_>,
) -> Result<(SmoothReport, Vec<PointVector>), Error> {
    options.validate()?;
    point_job::run(input, options, progress)
}

mod gcode_job;
mod point_job;
mod schedule;
mod summary;
