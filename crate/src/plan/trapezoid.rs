//! Constant-acceleration velocity profiles (trapezoids and triangles) along one move.

use crate::math::Bound;

/// Distance needed to go from speed `v0` to `v1` at acceleration `a` (negative to brake).
#[inline]
pub fn acceleration_distance(v0: f64, v1: f64, a: f64) -> f64 {
    if a == 0.0 {
        0.0
    } else {
        (v1 * v1 - v0 * v0) / (2.0 * a)
    }
}

/// Highest speed at the start of a distance `d` from which speed `v_target` can still be
/// reached with acceleration `a` (`a` negative: braking, as firmware calls it).
#[inline]
pub fn max_allowable_speed(a: f64, v_target: f64, d: f64) -> f64 {
    (v_target * v_target - 2.0 * a * d).at_least(0.0).sqrt()
}

/// Where acceleration from `v0` must stop so that braking at the same rate ends at `v1` after
/// `d` (the peak of a triangular profile).
#[inline]
pub fn intersection_distance(v0: f64, v1: f64, a: f64, d: f64) -> f64 {
    if a == 0.0 {
        0.0
    } else {
        (2.0 * a * d - v0 * v0 + v1 * v1) / (4.0 * a)
    }
}

/// The phases of one move's speed profile along its path.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct Profile {
    /// Speed at the start, mm/s.
    pub entry: f64,
    /// Highest speed reached (the cruise speed, or the peak of a triangle), mm/s.
    pub peak: f64,
    /// Speed at the end, mm/s.
    pub exit: f64,
    /// Acceleration (and deceleration) magnitude, mm/s².
    pub acceleration: f64,
    /// Time accelerating, s.
    pub accel_s: f64,
    /// Time at constant speed, s.
    pub cruise_s: f64,
    /// Time decelerating, s.
    pub decel_s: f64,
    /// Distance accelerating, mm.
    pub accel_mm: f64,
    /// Distance at constant speed, mm.
    pub cruise_mm: f64,
}

impl Profile {
    /// Total time, s.
    pub fn duration(&self) -> f64 {
        self.accel_s + self.cruise_s + self.decel_s
    }

    /// Distance covered (mm) and speed (mm/s) `tau` seconds into the move: accelerating,
    /// cruising, then braking (`tau` is clamped to the move).
    #[inline]
    pub fn at_time(&self, tau: f64) -> (f64, f64) {
        let a = self.acceleration;
        if tau <= self.accel_s {
            let t = tau.at_least(0.0);
            (self.entry * t + 0.5 * a * t * t, self.entry + a * t)
        } else if tau <= self.accel_s + self.cruise_s {
            let t = tau - self.accel_s;
            (self.accel_mm + self.peak * t, self.peak)
        } else {
            let t = (tau - self.accel_s - self.cruise_s).at_most(self.decel_s);
            (
                self.accel_mm + self.cruise_mm + self.peak * t - 0.5 * a * t * t,
                (self.peak - a * t).at_least(0.0),
            )
        }
    }

    /// Highest speed between distances `x0 ≤ x1` (mm) from the start of the move, mm/s: the
    /// profile rises, holds, then falls, so it is the peak if the interval reaches the top,
    /// else the speed at the interval's end nearer to it.
    pub fn max_speed_between(&self, x0: f64, x1: f64) -> f64 {
        if x1 < self.accel_mm {
            self.speed_at(x1)
        } else if x0 > self.accel_mm + self.cruise_mm {
            self.speed_at(x0)
        } else {
            self.peak
        }
    }

    /// Speed at distance `x` (mm) from the start of the move, mm/s: accelerating, cruising,
    /// then braking to the exit speed (`x` is clamped to the move).
    pub fn speed_at(&self, x: f64) -> f64 {
        let a = self.acceleration;
        let decel_from = self.accel_mm + self.cruise_mm;
        if x < self.accel_mm && a > 0.0 {
            (self.entry * self.entry + 2.0 * a * x.at_least(0.0)).sqrt()
        } else if x <= decel_from || a <= 0.0 {
            self.peak
        } else {
            let decel_mm = acceleration_distance(self.peak, self.exit, -a);
            let left = (decel_from + decel_mm - x).at_least(0.0);
            (self.exit * self.exit + 2.0 * a * left)
                .sqrt()
                .at_most(self.peak)
        }
    }

    /// The profile of a move of length `d` entered at `entry`, left at `exit`, cruising at most
    /// at `cruise`, with acceleration `a` (firmware `calculate_trapezoid`). Entry and exit must
    /// be reachable (the look-ahead guarantees it); if not, they are lowered.
    pub fn new(d: f64, entry: f64, cruise: f64, exit: f64, a: f64) -> Profile {
        let cruise = cruise.at_least(entry).at_least(exit);
        if d <= 0.0 || a <= 0.0 || cruise <= 0.0 {
            let t = if cruise > 0.0 {
                d.at_least(0.0) / cruise
            } else {
                0.0
            };
            return Profile {
                entry,
                peak: cruise,
                exit,
                acceleration: a,
                cruise_s: t,
                cruise_mm: d.at_least(0.0),
                ..Profile::default()
            };
        }
        let mut accel_mm = acceleration_distance(entry, cruise, a).at_least(0.0);
        let decel_mm = acceleration_distance(cruise, exit, -a).at_least(0.0);
        let mut cruise_mm = d - accel_mm - decel_mm;
        let mut peak = cruise;
        let (mut entry, mut exit) = (entry, exit);
        if cruise_mm < 0.0 {
            // Triangle: the cruise speed is never reached.
            accel_mm = intersection_distance(entry, exit, a, d).clamp(0.0, d);
            cruise_mm = 0.0;
            peak = (entry * entry + 2.0 * a * accel_mm).sqrt();
            // Unreachable end speeds (only with inconsistent input) are clipped to the peak.
            entry = entry.at_most(peak);
            exit = exit.at_most(peak);
        }
        let accel_s = (peak - entry) / a;
        let decel_s = (peak - exit) / a;
        let cruise_s = if peak > 0.0 { cruise_mm / peak } else { 0.0 };
        Profile {
            entry,
            peak,
            exit,
            acceleration: a,
            accel_s,
            cruise_s,
            decel_s,
            accel_mm,
            cruise_mm,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9 * (1.0 + b.abs())
    }

    #[test]
    fn trapezoid_closed_form() {
        // 100 mm at up to 50 mm/s from and to rest with 1000 mm/s²: 1.25 mm each way,
        // 97.5 mm cruising.
        let p = Profile::new(100.0, 0.0, 50.0, 0.0, 1000.0);
        assert!(close(p.accel_s, 0.05) && close(p.decel_s, 0.05));
        assert!(close(p.cruise_mm, 97.5));
        assert!(close(p.duration(), 0.1 + 97.5 / 50.0));
    }

    #[test]
    fn triangle_closed_form() {
        // 1 mm from rest to rest at 1000 mm/s², cruise 100 mm/s never reached:
        // peak sqrt(a d) = 31.62 mm/s, time 2 sqrt(d/a).
        let p = Profile::new(1.0, 0.0, 100.0, 0.0, 1000.0);
        assert!(close(p.peak, 1000f64.sqrt()));
        assert!(close(p.duration(), 2.0 * (1.0f64 / 1000.0).sqrt()));
        assert_eq!(p.cruise_s, 0.0);
    }

    #[test]
    fn asymmetric_entry_and_exit() {
        let p = Profile::new(10.0, 20.0, 40.0, 10.0, 500.0);
        let d = p.accel_mm + p.cruise_mm + acceleration_distance(p.peak, p.exit, -500.0);
        assert!(close(d, 10.0));
        assert!(close(p.accel_s, 20.0 / 500.0));
        assert!(close(p.decel_s, 30.0 / 500.0));
    }

    #[test]
    fn speed_along_a_trapezoid() {
        // From 10 to 50 mm/s over 1.2 mm at 1000 mm/s², 97.5 mm cruising, down to 0 over 1.25.
        let p = Profile::new(100.0, 10.0, 50.0, 0.0, 1000.0);
        assert!(close(p.speed_at(0.0), 10.0));
        assert!(close(p.speed_at(0.6), (100.0f64 + 1200.0).sqrt()));
        assert!(close(p.speed_at(50.0), 50.0));
        // 0.25 mm before the end: v² = 2 a · 0.25.
        assert!(close(p.speed_at(99.75), 500f64.sqrt()));
        assert!(close(p.speed_at(100.0), 0.0));
        assert!(close(p.speed_at(-1.0), 10.0) && close(p.speed_at(101.0), 0.0));
        // A triangle peaks where acceleration meets braking.
        let t = Profile::new(1.0, 0.0, 100.0, 0.0, 1000.0);
        assert!(close(t.speed_at(0.5), t.peak));
        // The highest speed over a stretch: on the ramp up, its far end; on the way down, its
        // near end; across the top, the peak.
        assert!(close(p.max_speed_between(0.1, 0.6), p.speed_at(0.6)));
        assert!(close(p.max_speed_between(99.0, 99.75), p.speed_at(99.0)));
        assert!(close(p.max_speed_between(0.5, 99.5), 50.0));
        assert!(close(t.max_speed_between(0.2, 0.8), t.peak));
    }

    #[test]
    fn allowable_speed_inverts_braking() {
        let v = max_allowable_speed(-1000.0, 10.0, 2.0);
        assert!(close(acceleration_distance(v, 10.0, -1000.0), 2.0));
    }
}
