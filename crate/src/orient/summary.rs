//! Assembling a [`SmoothReport`] from the runs before and after smoothing.

use super::metrics::{self, Sample};
use super::{InputFormat, Series, SmoothOptions, SmoothReport, SERIES_MAX};
use crate::error::{Error, ErrorKind, Warning};
use crate::vec3;

/// Calls `progress`, turning a `false` into [`ErrorKind::Cancelled`].
pub(super) fn tick(progress: crate::progress::Progress<'_>, fraction: f64) -> Result<(), Error> {
    if progress(fraction) {
        Ok(())
    } else {
        Err(Error::new(0, 0, ErrorKind::Cancelled))
    }
}

/// Counts the caller knows.
pub(super) struct Counts {
    pub format: InputFormat,
    pub motion_lines: usize,
    pub corrected: usize,
    pub changed: usize,
    /// Whether each run's first sample is only where it starts (G-code) rather than a point.
    pub skip_first: bool,
}

/// A warning when most points sit in runs too short to smooth (the gap limit or the path
/// numbering cuts every path apart).
pub(super) fn short_run_warning(runs: &[Vec<Sample>], skip_first: bool) -> Option<Warning> {
    let skip = usize::from(skip_first);
    let total: usize = runs.iter().map(|r| r.len().saturating_sub(skip)).sum();
    let short: usize = runs
        .iter()
        .map(|r| r.len().saturating_sub(skip))
        .filter(|&n| n < 3)
        .sum();
    (total > 0 && 2 * short > total).then(|| Warning {
        line: 0,
        message: format!(
            "{short} of {total} points are in runs of fewer than 3 points and cannot be smoothed; \
             is max_gap_mm (--max-gap) shorter than the point spacing?"
        ),
    })
}

pub(super) fn assemble(
    options: &SmoothOptions,
    counts: Counts,
    before: &[Vec<Sample>],
    after: &[Vec<Sample>],
    warnings: Vec<Warning>,
    output: Vec<u8>,
) -> SmoothReport {
    let letters = options.kinematics.model.rotary_letters();
    let m_before = metrics::measure(before.iter().map(Vec::as_slice), letters);
    let m_after = metrics::measure(after.iter().map(Vec::as_slice), letters);
    let skip = usize::from(counts.skip_first);
    let mut points = 0usize;
    let mut max_angle = 0.0f64;
    let mut sum_angle = 0.0f64;
    let mut max_tip = 0.0f64;
    let mut rows: Vec<([f64; 2], [f64; 2], f64)> = Vec::new();
    for (b_run, a_run) in before.iter().zip(after) {
        for (b, a) in b_run.iter().zip(a_run).skip(skip) {
            let ang = vec3::deg(vec3::angle(a.v, b.v));
            max_angle = max_angle.max(ang);
            sum_angle += ang;
            max_tip = max_tip.max(vec3::norm(vec3::sub(a.p, b.p)));
            points += 1;
            rows.push((b.rot, a.rot, ang));
        }
    }
    let stride = rows.len().div_ceil(SERIES_MAX).max(1);
    let mut series = Series {
        axes: letters.iter().map(|c| c.to_string()).collect(),
        ..Series::default()
    };
    for (i, (b, a, ang)) in rows.iter().enumerate().step_by(stride) {
        series.point.push(u32::try_from(i).unwrap_or(u32::MAX));
        series.first_before.push(b[0]);
        series.first_after.push(a[0]);
        series.second_before.push(b[1]);
        series.second_after.push(a[1]);
        series.angle_to_original_deg.push(*ang);
    }
    let roughness_reduction = if m_before.roughness > 0.0 {
        1.0 - m_after.roughness / m_before.roughness
    } else {
        0.0
    };
    SmoothReport {
        format: counts.format,
        kinematics: options.kinematics.model,
        filter: options.filter,
        window: options.window,
        cone_deg: options.cone_deg,
        motion_lines: counts.motion_lines,
        points,
        runs: before.len(),
        corrected: counts.corrected,
        changed: counts.changed,
        max_angle_to_original_deg: max_angle,
        mean_angle_to_original_deg: if points > 0 {
            sum_angle / points as f64
        } else {
            0.0
        },
        before: m_before,
        after: m_after,
        roughness_reduction,
        max_tip_deviation_mm: max_tip,
        planned_time_before_s: 0.0,
        planned_time_after_s: 0.0,
        series,
        warnings,
        output,
    }
}
