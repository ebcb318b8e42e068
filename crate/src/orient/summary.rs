//! Assembling a [`SmoothReport`] from the runs before and after smoothing.

use super::core::{self, RunSettings};
use super::filter::Window;
use super::kinematics::Kinematics;
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

/// A warning when most points sit in runs shorter than the filter's window: there the filter
/// has too few neighbours to average (travel moves, tool-tip jumps over `max_gap_mm` or the
/// path numbering cut every path apart).
pub(super) fn short_run_warning(
    runs: &[Vec<Sample>],
    skip_first: bool,
    options: &SmoothOptions,
) -> Option<Warning> {
    let skip = usize::from(skip_first);
    let short_run = |r: &Vec<Sample>| match options.window {
        Window::Points(w) => r.len().saturating_sub(skip) < w,
        Window::Millimetres(mm) => {
            let p: Vec<_> = r.iter().map(|x| x.p).collect();
            core::arc_length(&p).last().copied().unwrap_or(0.0) < mm
        }
    };
    let total: usize = runs.iter().map(|r| r.len().saturating_sub(skip)).sum();
    let short: usize = runs
        .iter()
        .filter(|r| short_run(r))
        .map(|r| r.len().saturating_sub(skip))
        .sum();
    (total > 0 && 2 * short > total).then(|| Warning {
        line: 0,
        message: format!(
            "{short} of {total} points are in runs shorter than the filter window ({}), which \
             smooths them little or not at all; runs break at travel moves and where the tool \
             tip jumps more than max_gap_mm (--max-gap, now {} mm): a larger max_gap_mm or a \
             smaller window (--window / --window-mm) changes it",
            window_text(options.window),
            options.max_gap_mm
        ),
    })
}

fn window_text(window: Window) -> String {
    match window {
        Window::Points(n) => format!("{n} points"),
        Window::Millimetres(mm) => format!("{mm} mm"),
    }
}

/// A warning for runs whose tool vector varies but which came out unchanged, with the reason:
/// every point inside the singular keep-out cone, or too few points for the filter.
pub(super) fn unsmoothed_warning(
    before: &[Vec<Sample>],
    after: &[Vec<Sample>],
    kin: &Kinematics,
    settings: &RunSettings,
    max_gap_mm: f64,
) -> Option<Warning> {
    let (mut singular, mut short, mut points) = (0usize, 0usize, 0usize);
    for (b, a) in before.iter().zip(after) {
        let varies = b.windows(2).any(|w| match w {
            [x, y] => vec3::angle(x.v, y.v) > 1e-9,
            _ => false,
        });
        let unchanged = b.iter().zip(a).all(|(x, y)| x.v == y.v);
        if !(varies && unchanged) {
            continue;
        }
        points += b.len();
        if b.iter()
            .all(|x| core::in_singular_zone(kin, x.v, settings.singular_angle))
        {
            singular += 1;
        } else {
            short += 1;
        }
    }
    (singular + short > 0).then(|| Warning {
        line: 0,
        message: format!(
            "{} runs ({points} points) whose tool vector varies were left as written: {singular} \
             have every point within singular_deg ({:.1}°) of the kinematic singularity \
             (--singular-deg / singular_deg lowers it), {short} are too short for the filter \
             (runs break at travel moves and at tool-tip jumps over max_gap_mm; --max-gap, \
             now {max_gap_mm} mm)",
            singular + short,
            vec3::deg(settings.singular_angle)
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
        coordinates: options.coordinates,
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
