//! The hybrid smoothing of one continuous run (section 3.2): filter the tool vectors, correct
//! them into the tolerance cone (CIRP eq. 4–7), and solve the rotary axes for the new vectors.

use super::cone;
use super::filter::{self, FilterKind, Window};
use super::kinematics::Kinematics;
use super::metrics::Sample;
use crate::vec3::{self, V3};

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
    /// How many vectors CIRP eq. 7 put back on the cone's edge.
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

/// Smooths one run. With `fixed_ends` its first sample (where the run starts: the end of the
/// move before it, in G-code) and its last stay as they are: the lines after the run then mean
/// what they meant (a following line that omits an axis word inherits the run's last values),
/// and the smoothing ramps in and out ([`anchor_weights`]). Fixed samples still take part in the
/// filter.
pub fn smooth_run(
    run: &[Sample],
    kin: &Kinematics,
    settings: &RunSettings,
    fixed_ends: bool,
) -> RunOutput {
    let p: Vec<V3> = run.iter().map(|s| s.p).collect();
    let b: Vec<V3> = run.iter().map(|s| s.v).collect();
    let s = arc_length(&p);
    let smoothed = filter::smooth(&b, &s, settings.filter, settings.window);
    // Kept as written: the ends, points whose original is near the singular direction, and
    // points the filter would pull into it (a path crossing near the axis: pushed back out, the
    // smoothed vectors would go round the axis where the input crosses it, and the turntable
    // would then owe half a turn that only a branch flip pays back).
    let fixed: Vec<bool> = run
        .iter()
        .zip(&smoothed)
        .enumerate()
        .map(|(i, (x, t))| {
            (fixed_ends && (i == 0 || i + 1 == run.len()))
                || in_singular_zone(kin, x.v, settings.singular_angle)
                || in_singular_zone(kin, *t, settings.singular_angle)
        })
        .collect();
    let weights = anchor_weights(&fixed, &s, settings.window);
    // The new tool vectors (fixed points keep theirs).
    let mut vectors = Vec::with_capacity(run.len());
    let mut corrected = 0usize;
    for (i, (sample, ts)) in run.iter().zip(&smoothed).enumerate() {
        if fixed.get(i).copied().unwrap_or(true) {
            vectors.push(None);
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
        vectors.push(Some(blend(
            sample.v,
            vector,
            weights.get(i).copied().unwrap_or(1.0),
        )));
    }
    let rots = choose_rotary(kin, run, &vectors);
    let samples = run
        .iter()
        .zip(&vectors)
        .zip(&rots)
        .map(|((sample, v), rot)| match v {
            Some(v) => Sample {
                v: *v,
                rot: *rot,
                ..*sample
            },
            None => *sample,
        })
        .collect();
    RunOutput { samples, corrected }
}

/// Rotary angles for the new vectors of a run (`None`: the point keeps its original angles),
/// chosen over the whole run at once: among both inverse-kinematics branches and the nearest
/// turns of the table (see [`Kinematics::candidates`]), the sequence with the least total axis
/// motion (dynamic programming, Viterbi-style). A greedy point-by-point choice can drift a whole
/// turn (or onto the other branch) away from the original and then has to jump back at the next
/// point that is kept as written; the path-wide choice never steps by a turn when a continuous
/// sequence exists, and it meets kept points and the run's ends on the file's own branch.
pub fn choose_rotary(kin: &Kinematics, run: &[Sample], vectors: &[Option<V3>]) -> Vec<[f64; 2]> {
    let cands: Vec<Vec<[f64; 2]>> = run
        .iter()
        .zip(vectors)
        .map(|(s, v)| match v {
            Some(v) => kin.candidates(*v, s.rot),
            None => vec![s.rot],
        })
        .collect();
    // cost[i][j]: least motion to reach candidate j of point i; back[i][j]: predecessor.
    let mut cost: Vec<f64> = cands.first().map_or(Vec::new(), |c| vec![0.0; c.len()]);
    let mut back: Vec<Vec<usize>> = Vec::with_capacity(cands.len());
    back.push(vec![0; cost.len()]);
    for w in cands.windows(2) {
        let [prev, cur] = w else { continue };
        let mut next_cost = Vec::with_capacity(cur.len());
        let mut next_back = Vec::with_capacity(cur.len());
        for c in cur {
            let mut best = (f64::INFINITY, 0usize);
            for (k, p) in prev.iter().enumerate() {
                let total =
                    cost.get(k).copied().unwrap_or(f64::INFINITY) + transition_cost(kin, *p, *c);
                if total < best.0 {
                    best = (total, k);
                }
            }
            next_cost.push(best.0);
            next_back.push(best.1);
        }
        cost = next_cost;
        back.push(next_back);
    }
    // Backtrack from the cheapest end.
    let mut j = cost
        .iter()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map_or(0, |(j, _)| j);
    let mut out = vec![[0.0; 2]; cands.len()];
    for i in (0..cands.len()).rev() {
        if let (Some(o), Some(c)) = (out.get_mut(i), cands.get(i).and_then(|c| c.get(j))) {
            *o = *c;
        }
        j = back.get(i).and_then(|b| b.get(j)).copied().unwrap_or(0);
    }
    out
}

/// Cost of moving the rotary axes from `a` to `b` in one move: the square of the axis motion,
/// plus a penalty that makes a step of half a turn or more of the second axis the last resort.
///
/// The square, not the motion itself: summed over a run, the motion alone is the same whether
/// a turn of the table is spread over many moves or made in one, so the choice could gather it
/// into one move just short of the half-turn penalty (a peak of angular velocity the input did
/// not have). The sum of squares is least when the motion is spread evenly.
fn transition_cost(kin: &Kinematics, a: [f64; 2], b: [f64; 2]) -> f64 {
    let step = kin.step(a, b);
    let cost = step * step;
    if (a[1] - b[1]).abs() >= 180.0 {
        cost + 1e12
    } else {
        cost
    }
}

/// Weight of the smoothing at each point: 0 at points kept as written (anchors), rising linearly
/// to 1 over half a window away from the nearest anchor (in points or millimetres, as the
/// window is counted). Without it the smoothed vectors would meet a kept point with a step.
pub fn anchor_weights(fixed: &[bool], s: &[f64], window: Window) -> Vec<f64> {
    let n = fixed.len();
    let ramp = match window {
        Window::Points(w) => (w as f64 / 2.0).max(1.0),
        Window::Millimetres(mm) => (mm / 2.0).max(1e-9),
    };
    let pos = |i: usize| match window {
        Window::Points(_) => i as f64,
        Window::Millimetres(_) => s.get(i).copied().unwrap_or(0.0),
    };
    let mut dist = vec![f64::INFINITY; n];
    let mut last: Option<f64> = None;
    for i in 0..n {
        if fixed.get(i).copied().unwrap_or(false) {
            last = Some(pos(i));
        }
        if let (Some(a), Some(d)) = (last, dist.get_mut(i)) {
            *d = pos(i) - a;
        }
    }
    let mut next: Option<f64> = None;
    for i in (0..n).rev() {
        if fixed.get(i).copied().unwrap_or(false) {
            next = Some(pos(i));
        }
        if let (Some(a), Some(d)) = (next, dist.get_mut(i)) {
            *d = d.min(a - pos(i));
        }
    }
    dist.into_iter()
        .map(|d| (d / ramp).clamp(0.0, 1.0))
        .collect()
}

/// The vector a fraction `w` of the way from `b` to `t` along the great circle (slerp). Its
/// angle to `b` is `w` times that of `t`, so it stays inside any cone `t` is inside.
pub fn blend(b: V3, t: V3, w: f64) -> V3 {
    if w >= 1.0 {
        return t;
    }
    if w <= 0.0 {
        return b;
    }
    let Some(h) = vec3::normalize(vec3::cross(b, t)) else {
        return if w < 0.5 { b } else { t };
    };
    vec3::normalize(vec3::rotate(b, h, w * vec3::angle(b, t))).unwrap_or(b)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_ramp_from_anchors() {
        let fixed = [
            true, false, false, false, false, false, false, false, false, true,
        ];
        let s: Vec<f64> = (0..10).map(f64::from).collect();
        let w = anchor_weights(&fixed, &s, Window::Points(4));
        assert_eq!(w, vec![0.0, 0.5, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0, 0.5, 0.0]);
        let w = anchor_weights(&fixed, &s, Window::Millimetres(8.0));
        assert_eq!(w[1], 0.25);
        assert_eq!(w[4], 1.0);
        let none = anchor_weights(&[false; 5], &s[..5], Window::Points(4));
        assert!(none.iter().all(|&x| x == 1.0));
    }

    #[test]
    fn blend_scales_the_angle() {
        let b = [0.0, 0.0, 1.0];
        let t = [0.6f64.sin(), 0.0, 0.6f64.cos()];
        let m = blend(b, t, 0.25);
        assert!((vec3::angle(m, b) - 0.15).abs() < 1e-12);
    }
}
