//! The hybrid smoothing of one continuous run (section 3.2): filter the tool vectors, correct
//! them into the tolerance cone (eq. 4–7), and solve the rotary axes for the new vectors.

use super::cone;
use super::filter::{self, FilterKind, Window};
use super::kinematics::Kinematics;
use super::metrics::Sample;
use super::vec3::{self, V3};

/// Settings of the per-run smoothing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunSettings {
    /// Filter.
    pub filter: FilterKind,
    /// Window.
    pub window: Window,
    /// Half the cone opening the result must stay within, radians (`γ/2` minus any margin
    /// the output's rounding needs).
    pub half_angle: f64,
    /// Keep-out angle around the kinematic singularity, radians (0: none).
    pub singular_angle: f64,
}

/// Smoothed orientation of one run.
#[derive(Debug, Clone, PartialEq)]
pub struct RunOutput {
    /// New samples (same positions; the first, where the run starts, is unchanged).
    pub samples: Vec<Sample>,
    /// How many vectors eq. 7 put back on the cone's edge.
    pub corrected: usize,
}

/// Cumulative tool-tip path length along a run, mm.
pub fn arc_length(p: &[V3]) -> Vec<f64> {
    let mut s = Vec::with_capacity(p.len());
    let mut acc = 0.0;
    let mut prev: Option<V3> = None;
    for &x in p {
        if let Some(q) = prev {
            let d = vec3::norm(vec3::sub(x, q));
            if d.is_finite() {
                acc += d;
            }
        }
        s.push(acc);
        prev = Some(x);
    }
    s
}

/// Smooths one run. With `fixed_first` its first sample is where the run starts (the end of the
/// move before it, in G-code) and stays as it is; it still takes part in the filter so the run
/// begins continuously.
pub fn smooth_run(
    run: &[Sample],
    kin: &Kinematics,
    settings: &RunSettings,
    fixed_first: bool,
) -> RunOutput {
    let p: Vec<V3> = run.iter().map(|s| s.p).collect();
    let b: Vec<V3> = run.iter().map(|s| s.v).collect();
    let s = arc_length(&p);
    let smoothed = filter::smooth(&b, &s, settings.filter, settings.window);
    let mut out = Vec::with_capacity(run.len());
    let mut corrected = 0usize;
    let mut prev_rot = run.first().map_or([0.0; 2], |s| s.rot);
    let mut prev_orig = prev_rot;
    for (i, (sample, ts)) in run.iter().zip(&smoothed).enumerate() {
        if (i == 0 && fixed_first) || in_singular_zone(kin, sample.v, settings.singular_angle) {
            out.push(*sample);
            prev_rot = sample.rot;
            prev_orig = sample.rot;
            continue;
        }
        let c = cone::correct(sample.v, *ts, settings.half_angle);
        corrected += usize::from(c.corrected);
        let vector = keep_out_of_singularity(
            c.vector,
            sample.v,
            kin.singular_direction(),
            settings.singular_angle,
            settings.half_angle,
        );
        let rot = kin.rotary_following(vector, prev_rot, sample.rot, prev_orig);
        prev_orig = sample.rot;
        prev_rot = rot;
        out.push(Sample {
            v: vector,
            rot,
            ..*sample
        });
    }
    RunOutput {
        samples: out,
        corrected,
    }
}

/// Whether the original vector `b` is within `keep_out` of the singular direction.
///
/// Such points are left exactly as written: there the rotary angles are what the CAM's own
/// motion planning chose to cross the singularity (Zhang's generator interpolates B through 0
/// while C turns), and any change of the vector, however small, would ask the turntable for a
/// large, fast turn or a flip to the other solution branch.
pub fn in_singular_zone(kin: &Kinematics, b: V3, keep_out: f64) -> bool {
    if keep_out <= 0.0 {
        return false;
    }
    let axis = kin.singular_direction();
    let tilt = vec3::angle(b, axis).min(vec3::angle(b, vec3::scale(axis, -1.0)));
    tilt + 1e-9 < keep_out
}

/// Keeps a smoothed vector `t` out of the cone of half-angle `keep_out` around the singular
/// direction `axis` (and its opposite), or at least as far out as the original `b` was.
///
/// Averaging vectors that circle the singular direction (a table's C axis) pulls them toward
/// it, where the turntable must spin ever faster to follow a small change of the vector: the
/// smoothing would trade a smooth tool vector for a jerky C axis. Zhang et al.'s generator
/// (the corpus 5-axis file) treats tilts below λ = 6° as singular for the same reason. The
/// vector is moved along its meridian out to `min(keep_out, tilt of b)`; if that would leave the
/// tolerance cone, the original vector is used (it satisfies both constraints).
pub fn keep_out_of_singularity(t: V3, b: V3, axis: V3, keep_out: f64, half_angle: f64) -> V3 {
    if keep_out <= 0.0 {
        return t;
    }
    let pole = if vec3::dot(t, axis) >= 0.0 {
        axis
    } else {
        vec3::scale(axis, -1.0)
    };
    let tilt_b = vec3::angle(b, axis).min(vec3::angle(b, vec3::scale(axis, -1.0)));
    let need = keep_out.min(tilt_b);
    let tilt_t = vec3::angle(t, pole);
    if tilt_t >= need {
        return t;
    }
    // Meridian direction of t (or of b when t sits on the pole).
    let side = vec3::sub(t, vec3::scale(pole, vec3::dot(t, pole)));
    let side = vec3::normalize(side)
        .or_else(|| vec3::normalize(vec3::sub(b, vec3::scale(pole, vec3::dot(b, pole)))))
        .unwrap_or_else(|| vec3::any_perpendicular(pole));
    let moved = vec3::add(
        vec3::scale(pole, crate::math::cos(need)),
        vec3::scale(side, crate::math::sin(need)),
    );
    match vec3::normalize(moved) {
        Some(m) if vec3::angle(m, b) <= half_angle => m,
        _ => b,
    }
}
