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
/// and the smoothing ramps in and out ([`anchor_weights`]). Points near the kinematic
/// singularity are smoothed in joint space instead (`joint_smoothed`) and anchor the vector
/// smoothing of their neighbours. Fixed samples still take part in the filter.
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
    let marks = Marks::new(run, &smoothed, &s, kin, settings, fixed_ends);
    let weights = anchor_weights(&marks.fixed, &s, settings.window);
    let fixed = &marks.fixed;
    let joint = Joint {
        singular: &marks.singular,
        weights: &marks.end_weights,
        s: &s,
    };
    let run = &joint_smoothed(run, &joint, kin, settings);
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

/// Which points of a run the vector filter leaves alone.
struct Marks {
    /// Smoothed in joint space (`joint_smoothed`).
    singular: Vec<bool>,
    /// Not smoothed as vectors: the joint-space points and the run's kept ends.
    fixed: Vec<bool>,
    /// Ramp of the smoothing from the run's kept ends.
    end_weights: Vec<f64>,
}

impl Marks {
    /// Points whose original, or whose filtered vector, is near the singular direction (a path
    /// crossing near the axis), and their neighbours within a window (so that the joint-space
    /// average at the edge of the set no longer reaches them and meets the vector-smoothed
    /// points without a step) go to joint space; with `fixed_ends` the run's ends stay.
    fn new(
        run: &[Sample],
        smoothed: &[V3],
        s: &[f64],
        kin: &Kinematics,
        settings: &RunSettings,
        fixed_ends: bool,
    ) -> Self {
        let ends = |i: usize| fixed_ends && (i == 0 || i + 1 == run.len());
        let near_axis: Vec<bool> = run
            .iter()
            .zip(smoothed)
            .map(|(x, t)| {
                in_singular_zone(kin, x.v, settings.singular_angle)
                    || in_singular_zone(kin, *t, settings.singular_angle)
            })
            .collect();
        let wider = match settings.window {
            Window::Points(w) => Window::Points(2 * w),
            Window::Millimetres(mm) => Window::Millimetres(2.0 * mm),
        };
        let reach = anchor_weights(&near_axis, s, wider);
        let singular: Vec<bool> = reach
            .iter()
            .enumerate()
            .map(|(i, w)| *w < 1.0 && !ends(i))
            .collect();
        let fixed = (0..run.len())
            .map(|i| singular.get(i).copied().unwrap_or(false) || ends(i))
            .collect();
        let end_flags: Vec<bool> = (0..run.len()).map(ends).collect();
        Marks {
            singular,
            fixed,
            end_weights: anchor_weights(&end_flags, s, settings.window),
        }
    }
}

/// Which points [`joint_smoothed`] changes, and how far.
#[derive(Debug, Clone, Copy)]
struct Joint<'a> {
    /// The points smoothed in joint space.
    singular: &'a [bool],
    /// Weight of the smoothing at each point (0 at the run's kept ends).
    weights: &'a [f64],
    /// Cumulative path length, mm.
    s: &'a [f64],
}

/// The run with the points near the singular direction (`singular`) smoothed in joint space:
/// their rotary angles become the centred moving average of the file's own angles over the
/// window, where that keeps the tool vector inside the cone.
///
/// Near the table axis the tool vector is a poor thing to average: a path that crosses near the
/// axis has its azimuth, and so the turntable angle, change by half a turn over a few points,
/// and an averaged vector (pushed out of the keep-out) would go round the axis where the input
/// crosses it. The file's own B and C are continuous there (Zhang's generator takes B through
/// 0 and turns C), so their average is a smooth crossing with the same winding of the table.
/// Table-BC only (the head's angles wrap).
fn joint_smoothed(
    run: &[Sample],
    joint: &Joint<'_>,
    kin: &Kinematics,
    settings: &RunSettings,
) -> Vec<Sample> {
    let Joint {
        singular,
        weights,
        s,
    } = *joint;
    let mut out = run.to_vec();
    if kin.model != super::kinematics::KinematicModel::TableBc {
        return out;
    }
    let near = |i: usize, j: usize| match settings.window {
        Window::Points(w) => i.abs_diff(j) <= w / 2,
        Window::Millimetres(mm) => {
            (s.get(i).copied().unwrap_or(0.0) - s.get(j).copied().unwrap_or(0.0)).abs() <= mm / 2.0
        }
    };
    for (i, x) in out.iter_mut().enumerate() {
        if !singular.get(i).copied().unwrap_or(false) {
            continue;
        }
        let lo = (0..=i)
            .rev()
            .take_while(|&j| near(i, j))
            .last()
            .unwrap_or(i);
        let hi = (i..run.len())
            .take_while(|&j| near(i, j))
            .last()
            .unwrap_or(i);
        let window = run.get(lo..=hi).unwrap_or_default();
        let n = window.len().max(1) as f64;
        let rot = window
            .iter()
            .fold([0.0; 2], |a, y| [a[0] + y.rot[0], a[1] + y.rot[1]]);
        // Ramped in from the run's kept ends, as the vector smoothing is.
        let w = weights.get(i).copied().unwrap_or(1.0);
        let rot = [
            x.rot[0] + w * (rot[0] / n - x.rot[0]),
            x.rot[1] + w * (rot[1] / n - x.rot[1]),
        ];
        let v = kin.tool_vector(rot);
        if vec3::angle(v, x.v) <= settings.half_angle {
            x.rot = rot;
            x.v = v;
        }
    }
    out
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
/// Such points are not smoothed as vectors: there the rotary angles are what the CAM's own
/// motion planning chose to cross the singularity (Zhang's generator interpolates B through 0
/// while C turns), and a change of the vector, however small, could ask the turntable for a
/// large, fast turn or a flip to the other solution branch. They are smoothed in joint space
/// (`joint_smoothed`), which keeps the crossing's winding.
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
    fn a_crossing_of_the_table_axis_is_spread_in_joint_space() {
        // The tool crosses the C axis in one step (B −6° → +6°, C turning 40°), as Zhang's
        // generator writes it: smoothed, B goes through 0 over several points and C follows.
        let kin = Kinematics::default();
        let run: Vec<Sample> = (0..41)
            .map(|i| {
                let rot = if i < 20 { [-6.0, 10.0] } else { [6.0, 50.0] };
                Sample {
                    p: [i as f64 * 0.5, 0.0, 0.0],
                    v: kin.tool_vector(rot),
                    rot,
                    dt: 0.1,
                    profile: None,
                }
            })
            .collect();
        let settings = RunSettings {
            filter: FilterKind::ZeroPhaseMovingAverage,
            window: Window::Points(15),
            half_angle: vec3::rad(30.0),
            singular_angle: vec3::rad(6.0),
        };
        let out = smooth_run(&run, &kin, &settings, true);
        let steps = |k: usize| {
            out.samples
                .windows(2)
                .map(|w| (w[1].rot[k] - w[0].rot[k]).abs())
                .fold(0.0, f64::max)
        };
        assert!(steps(0) < 1.5, "B step {}", steps(0));
        assert!(steps(1) < 5.0, "C step {}", steps(1));
        assert_eq!(out.samples.first(), run.first());
        assert_eq!(out.samples.last(), run.last());
        for (a, b) in out.samples.iter().zip(&run) {
            assert!(vec3::angle(a.v, b.v) <= settings.half_angle);
        }
    }

    #[test]
    fn blend_scales_the_angle() {
        let b = [0.0, 0.0, 1.0];
        let t = [0.6f64.sin(), 0.0, 0.6f64.cos()];
        let m = blend(b, t, 0.25);
        assert!((vec3::angle(m, b) - 0.15).abs() < 1e-12);
    }
}
