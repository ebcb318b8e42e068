//! Junction speeds: how fast the machine may pass from one move into the next.

use super::limits::Limits;
use crate::math::Bound;

/// Marlin's `MINIMUM_PLANNER_SPEED`, mm/s: the speed junction-deviation planners start and stop
/// at, and pass a reversal with.
pub const MINIMUM_PLANNER_SPEED: f64 = 0.05;

/// What the junction models need to know about a move.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Signed per-axis speed at cruise (X, Y, Z, E), mm/s.
    pub axis_feedrate: [f64; 4],
    /// Cruise (nominal) speed along the path, mm/s.
    pub cruise: f64,
    /// Jerk-limited speed at which the move could start or stop from rest, mm/s.
    pub safe: f64,
    /// Unit direction in X, Y, Z (zero for E-only moves).
    pub unit: [f64; 3],
    /// Path length, mm.
    pub distance: f64,
    /// Acceleration, mm/s².
    pub acceleration: f64,
    /// Klipper: the toolhead's junction deviation when the move was queued,
    /// [`klipper_junction_deviation`] of the square-corner velocity and the toolhead's
    /// `max_accel` then (not the move's own, lower acceleration), mm. Unused by other models.
    pub klipper_jd: f64,
}

/// Jerk-limited "safe" speed of a move: the speed from which every axis can stop at once
/// within its jerk limit (classic-jerk firmware and PrusaSlicer's estimator).
pub fn safe_speed(axis_feedrate: &[f64; 4], cruise: f64, limits: &Limits) -> f64 {
    let mut safe = cruise;
    for (v, jerk) in axis_feedrate.iter().zip(&limits.max_jerk) {
        if v.abs() > jerk.value {
            safe = safe.at_most(jerk.value);
        }
    }
    safe
}

/// Classic per-axis jerk (Marlin 1.x, Prusa firmware, PrusaSlicer's estimator; the thesis's
/// Appendix A): the largest junction speed at which no axis changes speed by more than its
/// jerk limit.
pub fn classic_jerk(prev: &Segment, curr: &Segment, limits: &Limits) -> f64 {
    let mut vmax_junction = curr.safe;
    if prev.cruise <= 1e-4 {
        return vmax_junction;
    }
    let prev_speed_larger = prev.cruise > curr.cruise;
    let smaller_speed_factor = if prev_speed_larger {
        curr.cruise / prev.cruise
    } else {
        prev.cruise / curr.cruise
    };
    // Pick the smaller of the nominal speeds: no higher speed at the junction than cruising.
    vmax_junction = if prev_speed_larger {
        curr.cruise
    } else {
        prev.cruise
    };
    // Marlin scales every later axis by the factor the earlier ones imposed and, when an axis
    // is over its limit, multiplies the factor by limit / scaled jerk. Jerk is homogeneous in
    // the speeds, so that product is simply limit / jerk of the unscaled speeds, and the final
    // factor is the smallest limit / jerk over the axes (or 1): the same number without the
    // dependent chain of branches, which mispredicts at every other corner.
    let exit_scale = if prev_speed_larger {
        smaller_speed_factor
    } else {
        1.0
    };
    let mut v_factor: f64 = 1.0;
    for axis in 0..4 {
        let v_exit = prev.axis_feedrate[axis] * exit_scale;
        let v_entry = curr.axis_feedrate[axis];
        // Coasting in the same direction: the change of speed; reversing (or from or to rest):
        // the larger of the two speeds, as Marlin's four cases come to.
        let jerk = if v_exit * v_entry > 0.0 {
            (v_exit - v_entry).abs()
        } else {
            v_exit.abs().at_least(v_entry.abs())
        };
        let max_jerk = limits.max_jerk[axis].value;
        if jerk > max_jerk {
            v_factor = v_factor.at_most(max_jerk / jerk);
        }
    }
    vmax_junction *= v_factor;
    // If both moves could start from rest at the junction speed anyway, start at the safe speed.
    let threshold = vmax_junction * 0.99;
    if prev.safe > threshold && curr.safe > threshold {
        vmax_junction = curr.safe;
    }
    vmax_junction
}

fn cos_theta(prev: &Segment, curr: &Segment) -> f64 {
    // Marlin's junction_cos_theta: minus the cosine of the angle between the directions, so -1
    // is straight on and +1 a full reversal.
    -(prev.unit[0] * curr.unit[0] + prev.unit[1] * curr.unit[1] + prev.unit[2] * curr.unit[2])
}

/// Marlin 2 junction deviation, including `JD_HANDLE_SMALL_SEGMENTS`: short moves through a
/// gentle bend (more than 135°) are limited as the arc they approximate.
pub fn junction_deviation(prev: &Segment, curr: &Segment, limits: &Limits) -> f64 {
    if prev.cruise <= 1e-4 || is_e_only(prev) || is_e_only(curr) {
        // Held to both moves' cruise speeds, as the bend's speed is below: a move slower than
        // the planner's minimum (a feed capped near the floor) would otherwise start faster than
        // it runs, and end slower than the next one starts.
        return MINIMUM_PLANNER_SPEED
            .at_most(curr.cruise)
            .at_most(prev.cruise);
    }
    let cos = cos_theta(prev, curr);
    let v_sqr = if cos > 0.999_999 {
        MINIMUM_PLANNER_SPEED * MINIMUM_PLANNER_SPEED
    } else {
        let cos = cos.at_least(-0.999_999);
        let sin_d2 = (0.5 * (1.0 - cos)).sqrt();
        let a = curr.acceleration;
        let mut v_sqr = a * limits.junction_deviation.value * sin_d2 / (1.0 - sin_d2);
        if curr.distance < 1.0 && cos < -std::f64::consts::FRAC_1_SQRT_2 {
            // The change of direction, acos(-cos) (Marlin approximates it by a polynomial).
            let theta = crate::math::acos((-cos).clamp(-1.0, 1.0));
            if theta > 0.0 {
                v_sqr = v_sqr.at_most(curr.distance * a / theta);
            }
        }
        v_sqr
    };
    v_sqr.sqrt().at_most(curr.cruise).at_most(prev.cruise)
}

/// Klipper's extruder `instantaneous_corner_velocity` (its default), mm/s: the largest step
/// in filament speed a junction may ask of the extruder.
pub const KLIPPER_INSTANT_CORNER_V: f64 = 1.0;

/// Klipper's junction speed (`toolhead.py` `calc_junction`): the square-corner velocity as
/// an equivalent junction deviation (`scv² (√2 − 1) / max_accel`, the toolhead's), times each
/// move's own acceleration, so a move with a lower one (a Z hop) passes its corners slower;
/// the centripetal limit of both moves; and the extruder's limit: where the filament per
/// millimetre changes by Δr (a travel straight into a print, a change of line width), the
/// junction is held to `instantaneous_corner_velocity / |Δr|`, so the filament speed steps by
/// at most that much. Older Klipper (`max_accel_to_decel` in force: v0.12, Creality's K1
/// firmware) stops at a full reversal and bounds a straight junction by the centripetal limit
/// of an angle of 0.999999; current Klipper passes both at the cruise speeds.
pub fn klipper(prev: &Segment, curr: &Segment, limits: &Limits) -> f64 {
    if is_e_only(prev) || is_e_only(curr) {
        return 0.0;
    }
    let mut max_v2 = curr.cruise * curr.cruise;
    max_v2 = max_v2.at_most(prev.cruise * prev.cruise);
    let e_ratio = |s: &Segment| {
        if s.cruise > 0.0 {
            s.axis_feedrate[3] / s.cruise
        } else {
            0.0
        }
    };
    let step = (e_ratio(curr) - e_ratio(prev)).abs();
    if step > 0.0 {
        let icv = limits
            .instantaneous_corner_velocity
            .map_or(KLIPPER_INSTANT_CORNER_V, |l| l.value);
        let v = icv / step;
        max_v2 = max_v2.at_most(v * v);
    }
    let mut cos = cos_theta(prev, curr);
    if limits.accel_to_decel.value > 0.0 {
        if cos > 0.999_999 {
            return 0.0;
        }
        cos = cos.at_least(-0.999_999);
    }
    let sin_d2 = (0.5 * (1.0 - cos)).at_least(0.0).sqrt();
    let cos_d2 = (0.5 * (1.0 + cos)).at_least(0.0).sqrt();
    let one_minus_sin = 1.0 - sin_d2;
    if one_minus_sin > 0.0 && cos_d2 > 0.0 {
        let r_jd = sin_d2 / one_minus_sin;
        let quarter_tan = 0.25 * sin_d2 / cos_d2;
        max_v2 = max_v2
            .at_most(r_jd * curr.klipper_jd * curr.acceleration)
            .at_most(r_jd * prev.klipper_jd * prev.acceleration)
            .at_most(2.0 * curr.distance * curr.acceleration * quarter_tan)
            .at_most(2.0 * prev.distance * prev.acceleration * quarter_tan);
    }
    max_v2.at_least(0.0).sqrt()
}

/// Klipper's junction deviation for a square-corner velocity and acceleration:
/// `scv² (√2 − 1) / accel`, the deviation at which a 90° corner runs at exactly `scv`.
pub fn klipper_junction_deviation(scv: f64, accel: f64) -> f64 {
    scv * scv * (std::f64::consts::SQRT_2 - 1.0) / accel.at_least(1e-9)
}

fn is_e_only(s: &Segment) -> bool {
    s.unit == [0.0; 3]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::profiles::MachineProfile;

    fn seg(dir: [f64; 2], speed: f64, accel: f64, distance: f64) -> Segment {
        let n = dir[0].hypot(dir[1]);
        let unit = [dir[0] / n, dir[1] / n, 0.0];
        Segment {
            axis_feedrate: [unit[0] * speed, unit[1] * speed, 0.0, 0.0],
            cruise: speed,
            safe: 0.0,
            unit,
            distance,
            acceleration: accel,
            klipper_jd: klipper_junction_deviation(5.0, accel),
        }
    }

    fn limits() -> Limits {
        let mut l = MachineProfile::preset("prusa-mk3s").expect("preset").limits;
        l.max_jerk[0].value = 8.0;
        l.max_jerk[1].value = 8.0;
        l.junction_deviation.value = 0.013;
        l.square_corner_velocity.value = 5.0;
        l
    }

    #[test]
    fn classic_jerk_at_a_right_angle() {
        // X at 100 mm/s then Y at 100 mm/s: X must drop to 0 and Y rise from 0 with at most
        // 8 mm/s jerk each, so the junction speed is 8 mm/s.
        let l = limits();
        let mut a = seg([1.0, 0.0], 100.0, 1000.0, 10.0);
        let mut b = seg([0.0, 1.0], 100.0, 1000.0, 10.0);
        a.safe = safe_speed(&a.axis_feedrate, a.cruise, &l);
        b.safe = safe_speed(&b.axis_feedrate, b.cruise, &l);
        let v = classic_jerk(&a, &b, &l);
        assert!((v - 8.0).abs() < 1e-9, "{v}");
        // Straight on: no jerk at all, the junction runs at the cruise speed.
        let c = seg([1.0, 0.0], 100.0, 1000.0, 10.0);
        assert!((classic_jerk(&a, &c, &l) - 100.0).abs() < 1e-9);
    }

    #[test]
    fn junction_deviation_at_a_right_angle() {
        // v² = a · jd · sin(θ/2) / (1 − sin(θ/2)) with θ/2 = 45°.
        let l = limits();
        let a = seg([1.0, 0.0], 100.0, 1000.0, 10.0);
        let b = seg([0.0, 1.0], 100.0, 1000.0, 10.0);
        let s = std::f64::consts::FRAC_1_SQRT_2;
        let expected = (1000.0 * 0.013 * s / (1.0 - s)).sqrt();
        assert!((junction_deviation(&a, &b, &l) - expected).abs() < 1e-9);
        // A reversal passes at the minimum planner speed.
        let back = seg([-1.0, 0.0], 100.0, 1000.0, 10.0);
        assert_eq!(junction_deviation(&a, &back, &l), MINIMUM_PLANNER_SPEED);
    }

    #[test]
    fn klipper_square_corner_is_the_scv() {
        // By construction a 90° corner at Klipper's junction deviation runs at the square
        // corner velocity, whatever the acceleration.
        let l = limits();
        for accel in [500.0, 3000.0, 20000.0] {
            let a = seg([1.0, 0.0], 200.0, accel, 50.0);
            let b = seg([0.0, 1.0], 200.0, accel, 50.0);
            let v = klipper(&a, &b, &l);
            assert!((v - 5.0).abs() < 1e-9, "{accel}: {v}");
        }
    }

    #[test]
    fn klipper_corners_of_a_slower_move_use_the_toolheads_junction_deviation() {
        // A Z hop accelerating at 350 mm/s² on a 3000 mm/s² printer: the junction deviation
        // stays the toolhead's, so the square corner runs at 5 √(350 / 3000) mm/s, not at 5.
        let l = limits();
        let a = seg([1.0, 0.0], 200.0, 3000.0, 50.0);
        let mut hop = seg([0.0, 1.0], 200.0, 350.0, 50.0);
        hop.klipper_jd = klipper_junction_deviation(5.0, 3000.0);
        let v = klipper(&a, &hop, &l);
        assert!((v - 5.0 * (350.0f64 / 3000.0).sqrt()).abs() < 1e-9, "{v}");
    }

    #[test]
    fn klipper_holds_a_change_of_flow_to_the_extruder_corner_velocity() {
        // Straight on from a travel into a print of 0.04 mm of filament per mm: only the
        // extruder limits the junction, to 1 mm/s / 0.04 = 25 mm/s.
        let l = limits();
        let travel = seg([1.0, 0.0], 200.0, 3000.0, 50.0);
        let mut print = seg([1.0, 0.0], 200.0, 3000.0, 50.0);
        print.axis_feedrate[3] = 0.04 * 200.0;
        let v = klipper(&travel, &print, &l);
        assert!((v - 25.0).abs() < 1e-9, "{v}");
        // The same flow on both sides: no limit from the extruder.
        let v = klipper(&print, &print, &l);
        assert!((v - 200.0).abs() < 1e-9, "{v}");
    }

    #[test]
    fn klipper_junction_deviation_value() {
        // Klipper defaults: scv 5 mm/s, accel 3000 mm/s² -> 0.0034518 mm.
        let jd = klipper_junction_deviation(5.0, 3000.0);
        assert!((jd - 25.0 * (2f64.sqrt() - 1.0) / 3000.0).abs() < 1e-15);
        assert!((jd - 0.003_451_8).abs() < 1e-7, "{jd}");
    }

    #[test]
    fn small_segment_rule_limits_gentle_bends_of_short_moves() {
        let mut l = limits();
        l.junction_deviation.value = 0.5;
        // 10° bend on 0.2 mm segments: the arc limit v² = d a / θ is lower than the JD limit.
        let t = 10f64.to_radians();
        let a = seg([1.0, 0.0], 200.0, 1000.0, 0.2);
        let b = seg([t.cos(), t.sin()], 200.0, 1000.0, 0.2);
        let v = junction_deviation(&a, &b, &l);
        assert!((v - (0.2 * 1000.0 / t).sqrt()).abs() < 1e-6, "{v}");
    }
}
