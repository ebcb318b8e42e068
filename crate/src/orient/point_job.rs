//! Smoothing point-vector data.

use super::core::{self, RunSettings};
use super::metrics::Sample;
use super::points::PointVector;
use super::summary::{self, Counts};
use super::{InputFormat, SmoothOptions, SmoothReport};
use crate::error::{Error, ErrorKind};
use crate::progress::Progress;
use crate::vec3::{self, V3};

pub(super) fn run(
    input: &[PointVector],
    options: &SmoothOptions,
    progress: Progress<'_>,
) -> Result<(SmoothReport, Vec<PointVector>), Error> {
    let kin = &options.kinematics;
    summary::tick(progress, 0.0)?;
    let runs = sample_runs(input, options)?;
    summary::tick(progress, 0.2)?;
    let settings = RunSettings {
        filter: options.filter,
        window: options.window,
        half_angle: vec3::rad(0.5 * options.cone_deg),
        singular_angle: vec3::rad(options.singular_deg.unwrap_or(0.0)),
    };
    let mut after = Vec::with_capacity(runs.len());
    let mut corrected = 0usize;
    for run in &runs {
        let out = core::smooth_run(run, kin, &settings, false);
        corrected += out.corrected;
        after.push(out.samples);
    }
    summary::tick(progress, 0.8)?;
    let (points, changed) = smoothed_points(input, &after);
    let report = summary::assemble(
        options,
        Counts {
            format: InputFormat::Json,
            motion_lines: input.len(),
            corrected,
            changed,
            skip_first: false,
        },
        &runs,
        &after,
        summary::short_run_warning(&runs, false, options)
            .into_iter()
            .collect(),
        Vec::new(),
    );
    summary::tick(progress, 1.0)?;
    Ok((report, points))
}

/// The points as samples, split into runs where the path number changes or the points jump
/// farther than `max_gap_mm`.
fn sample_runs(input: &[PointVector], options: &SmoothOptions) -> Result<Vec<Vec<Sample>>, Error> {
    let kin = &options.kinematics;
    let mut runs: Vec<Vec<Sample>> = Vec::new();
    let mut last_path = None;
    let mut prev_rot = [0.0; 2];
    let mut prev_p: Option<V3> = None;
    for (idx, q) in input.iter().enumerate() {
        let line = u32::try_from(idx + 1).unwrap_or(u32::MAX);
        let p = [q.x, q.y, q.z];
        let v = if vec3::is_finite(p) {
            vec3::normalize([q.i, q.j, q.k])
        } else {
            None
        };
        let Some(v) = v else {
            return Err(Error::new(
                line,
                0,
                ErrorKind::InvalidOption {
                    reason: "every point needs a finite position and a non-zero finite vector",
                },
            ));
        };
        let jump = prev_p.is_some_and(|a| vec3::norm(vec3::sub(p, a)) > options.max_gap_mm);
        if last_path != Some(q.path) || jump {
            runs.push(Vec::new());
            last_path = Some(q.path);
            prev_p = None;
        }
        let rot = kin.rotary_for(v, prev_rot);
        prev_rot = rot;
        let dt = prev_p.map_or(0.0, |a| vec3::norm(vec3::sub(p, a)) / options.feed_mm_s);
        prev_p = Some(p);
        if let Some(r) = runs.last_mut() {
            r.push(Sample {
                p,
                v,
                rot,
                dt,
                profile: None,
            });
        }
    }
    Ok(runs)
}

/// The input points with their smoothed vectors, and how many of them changed.
fn smoothed_points(input: &[PointVector], after: &[Vec<Sample>]) -> (Vec<PointVector>, usize) {
    let mut points = Vec::with_capacity(input.len());
    let mut changed = 0usize;
    for (q, s) in input.iter().zip(after.iter().flatten()) {
        let was = vec3::normalize([q.i, q.j, q.k]).unwrap_or(s.v);
        changed += usize::from(was != s.v);
        points.push(PointVector {
            i: s.v[0],
            j: s.v[1],
            k: s.v[2],
            ..*q
        });
    }
    (points, changed)
}
