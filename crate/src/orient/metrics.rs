//! Orientation-variation metrics (what the smoothing is for): angle change per point and per
//! millimetre, roughness, and the rotary axes' angular velocity, acceleration and jerk under
//! the move timing (the planner's for G-code, a constant feed for point-vector data).
//!
//! The rotary rates are read off the timed motion, not off per-move averages. Each move
//! interpolates its axes linearly along its path (as G-code controllers do), so an axis's
//! angle at time `t` is the move's start angle plus its share of the angle change at the
//! distance the planner's speed profile has covered. That angle is sampled every
//! [`RATE_RESOLUTION_S`] and differenced three times. Per-move averages would make a move's
//! length the unit of time: a 90° turn inside one long move would look gentle, and the
//! same turn spread over fifteen short moves would look violent.

use serde::Serialize;

use crate::plan::Profile;
use crate::vec3::{self, V3};

/// One path point as the metrics see it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Tool-tip position in the workpiece frame, mm.
    pub p: V3,
    /// Unit tool vector in the workpiece frame.
    pub v: V3,
    /// Rotary axes, degrees.
    pub rot: [f64; 2],
    /// Duration of the move ending here, s (unused for a run's first sample).
    pub dt: f64,
    /// The planner's speed profile of that move; `None` travels it at constant speed.
    pub profile: Option<Profile>,
}

/// Motion of one rotary axis.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct RotaryMetrics {
    /// Axis letter.
    pub axis: String,
    /// Total angle travelled, degrees.
    pub travel_deg: f64,
    /// Largest angular velocity, °/s.
    pub max_velocity_deg_s: f64,
    /// Root-mean-square angular velocity, °/s.
    pub rms_velocity_deg_s: f64,
    /// Largest angular acceleration between consecutive moves, °/s².
    pub max_acceleration_deg_s2: f64,
    /// Root-mean-square angular acceleration, °/s².
    pub rms_acceleration_deg_s2: f64,
    /// Largest angular jerk, °/s³.
    pub max_jerk_deg_s3: f64,
    /// Root-mean-square angular jerk, °/s³.
    pub rms_jerk_deg_s3: f64,
}

/// Orientation metrics of a set of runs.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct OrientationMetrics {
    /// Orientation roughness: root mean square of the second difference of the unit tool
    /// vector, `‖T_{m+1} − 2 T_m + T_{m−1}‖`, over the interior points of every run (consecutive
    /// points of one continuous path; the discrete curvature the CIRP paper's filters act on).
    pub roughness: f64,
    /// Mean of the same norm.
    pub mean_second_difference: f64,
    /// Largest second-difference norm.
    pub max_second_difference: f64,
    /// Mean angle between consecutive tool vectors, degrees.
    pub mean_angle_change_deg: f64,
    /// Largest angle between consecutive tool vectors, degrees.
    pub max_angle_change_deg: f64,
    /// Mean angle change per millimetre of tool-tip path, °/mm (segments longer than 1 µm).
    pub mean_angle_change_per_mm_deg: f64,
    /// Largest angle change per millimetre, °/mm.
    pub max_angle_change_per_mm_deg: f64,
    /// The two rotary axes.
    pub rotary: Vec<RotaryMetrics>,
}

/// Time step the rotary angles are sampled and differenced at, s. Velocity is the angle
/// change over one step, acceleration the change of that over the next, jerk likewise, so a
/// speed step of `Δω` between two moves reads as `Δω / h` and `Δω / h²`. 10 ms is the order of
/// a rotary servo's position-loop bandwidth and of the smoothing time of Klipper's input
/// shapers: what an axis can follow, not the step rate.
pub const RATE_RESOLUTION_S: f64 = 0.01;

#[derive(Default)]
struct Acc {
    sum: f64,
    sq: f64,
    max: f64,
    n: usize,
}

impl Acc {
    fn push(&mut self, x: f64) {
        if x.is_finite() {
            self.sum += x.abs();
            self.sq += x * x;
            self.max = self.max.max(x.abs());
            self.n += 1;
        }
    }
    fn mean(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            self.sum / self.n as f64
        }
    }
    fn rms(&self) -> f64 {
        if self.n == 0 {
            0.0
        } else {
            (self.sq / self.n as f64).sqrt()
        }
    }
}

/// Metrics of `runs` (each a continuous path; its first sample is where it starts).
pub fn measure<'a>(
    runs: impl Iterator<Item = &'a [Sample]>,
    letters: [char; 2],
) -> OrientationMetrics {
    let mut second = Acc::default();
    let mut turn = Acc::default();
    let mut per_mm = Acc::default();
    let mut travel = [0.0f64; 2];
    let mut vel: [Acc; 2] = Default::default();
    let mut acc: [Acc; 2] = Default::default();
    let mut jerk: [Acc; 2] = Default::default();
    for run in runs {
        for w in run.windows(3) {
            if let [a, b, c] = w {
                second.push(vec3::norm(vec3::add(
                    vec3::sub(a.v, vec3::scale(b.v, 2.0)),
                    c.v,
                )));
            }
        }
        for w in run.windows(2) {
            if let [a, b] = w {
                let ang = vec3::deg(vec3::angle(a.v, b.v));
                turn.push(ang);
                let len = vec3::norm(vec3::sub(b.p, a.p));
                if len > 1e-3 {
                    per_mm.push(ang / len);
                }
            }
        }
        for k in 0..2 {
            for w in run.windows(2) {
                if let [a, b] = w {
                    travel[k] += (b.rot[k] - a.rot[k]).abs();
                }
            }
            rates(run, k, [&mut vel[k], &mut acc[k], &mut jerk[k]]);
        }
    }
    OrientationMetrics {
        roughness: second.rms(),
        mean_second_difference: second.mean(),
        max_second_difference: second.max,
        mean_angle_change_deg: turn.mean(),
        max_angle_change_deg: turn.max,
        mean_angle_change_per_mm_deg: per_mm.mean(),
        max_angle_change_per_mm_deg: per_mm.max,
        rotary: (0..2)
            .map(|k| RotaryMetrics {
                axis: letters[k].to_string(),
                travel_deg: travel[k],
                max_velocity_deg_s: vel[k].max,
                rms_velocity_deg_s: vel[k].rms(),
                max_acceleration_deg_s2: acc[k].max,
                rms_acceleration_deg_s2: acc[k].rms(),
                max_jerk_deg_s3: jerk[k].max,
                rms_jerk_deg_s3: jerk[k].rms(),
            })
            .collect(),
    }
}

/// Share of a move's path covered `tau` seconds into it (0 to 1).
fn fraction(sample: &Sample, tau: f64) -> f64 {
    if sample.dt <= 0.0 {
        return 1.0;
    }
    match sample.profile {
        Some(p) if p.duration() > 0.0 => {
            // An arc's stored profile is its last segment's: scale it to the whole move.
            let total = p.at_time(p.duration()).0;
            let (d, _) = p.at_time(tau * p.duration() / sample.dt);
            if total > 0.0 {
                (d / total).clamp(0.0, 1.0)
            } else {
                (tau / sample.dt).clamp(0.0, 1.0)
            }
        }
        _ => (tau / sample.dt).clamp(0.0, 1.0),
    }
}

/// Angle of axis `k` along a run, every [`RATE_RESOLUTION_S`] from its start.
fn sampled_angles(run: &[Sample], k: usize) -> Vec<f64> {
    let total: f64 = run.iter().skip(1).map(|s| s.dt.max(0.0)).sum();
    let (Some(first), true) = (run.first(), total.is_finite()) else {
        return Vec::new();
    };
    let steps = (total / RATE_RESOLUTION_S).floor() as usize;
    let mut out = Vec::with_capacity(steps + 1);
    let (mut j, mut start) = (1usize, 0.0f64);
    let mut from = first.rot[k];
    for i in 0..=steps {
        let t = i as f64 * RATE_RESOLUTION_S;
        while let Some(m) = run.get(j) {
            if t <= start + m.dt || j + 1 == run.len() {
                break;
            }
            start += m.dt.max(0.0);
            from = m.rot[k];
            j += 1;
        }
        let Some(m) = run.get(j) else { break };
        out.push(from + (m.rot[k] - from) * fraction(m, t - start));
    }
    out
}

/// Velocity, acceleration and jerk of axis `k` along a run, on the sampled angles.
fn rates(run: &[Sample], k: usize, acc: [&mut Acc; 3]) {
    let h = RATE_RESOLUTION_S;
    let mut d: Vec<f64> = sampled_angles(run, k);
    for a in acc {
        d = d.windows(2).map(|w| (w[1] - w[0]) / h).collect();
        for &x in &d {
            a.push(x);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_rotation_rate_has_no_acceleration() {
        let run: Vec<Sample> = (0..10)
            .map(|i| {
                let a = vec3::rad(i as f64);
                Sample {
                    p: [i as f64, 0.0, 0.0],
                    v: [a.sin(), 0.0, a.cos()],
                    rot: [0.0, 2.0 * i as f64],
                    dt: 0.5,
                    profile: None,
                }
            })
            .collect();
        let m = measure(std::iter::once(&run[..]), ['B', 'C']);
        assert!((m.mean_angle_change_deg - 1.0).abs() < 1e-9);
        assert!((m.mean_angle_change_per_mm_deg - 1.0).abs() < 1e-9);
        assert!((m.rotary[1].max_velocity_deg_s - 4.0).abs() < 1e-12);
        assert!(m.rotary[1].max_acceleration_deg_s2 < 1e-9);
        assert!((m.rotary[1].travel_deg - 18.0).abs() < 1e-12);
        // Second difference of a uniform rotation by δ: 2 (1 − cos δ) = 4 sin²(δ/2).
        let d = vec3::rad(1.0);
        assert!((m.roughness - 4.0 * (d / 2.0).sin().powi(2)).abs() < 1e-12);
        assert!((m.mean_second_difference - m.roughness).abs() < 1e-12);
    }
}
