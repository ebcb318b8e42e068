//! The thesis stepper model (Somade 2023, thesis eq. 20–28): energy of the X and Y stepper motors
//! from the motion profile of every move.
//!
//! For a move of length `d` with displacement `δ`, axis `j` ∈ {X, Y} moves at the path speed
//! times `s_j = |δ_j| / d` and accelerates at the path acceleration times `s_j` (a coordinated
//! move: every axis follows the same trapezoid, scaled). With the move's profile (entry `v₀`,
//! peak `v_m`, exit `v_f`, acceleration `a`, phase times `t_a`, `t_c`, `t_d`):
//!
//! - `A = Σ t_a·a_x·(v_x0 + v_xm)/2 + t_d·a_x·(v_xm + v_xf)/2` (thesis eq. 24), where
//!   `a_x = s_x·a`, `v_x0 = s_x·v₀`… so a move adds `s_x²·[t_a·a·(v₀+v_m)/2 + t_d·a·(v_m+v_f)/2]`.
//!   Unit: (mm/s)² — time × acceleration × speed. (For an exact trapezoid this is
//!   `s_x²·(2v_m² − v₀² − v_f²)/2`, the change of "specific kinetic energy".)
//! - `B`: the same for Y (thesis eq. 25), (mm/s)².
//! - `C = Σ_j t_c·v_jm` (thesis eq. 26): distance both axes cover while coasting, mm.
//! - `H = Σ_j t_h` (thesis eq. 27): seconds during which an axis is energised but does not move.
//!
//! Choices the thesis leaves open, made here:
//! - An axis "does not move" in a move when `|δ_j| ≤` [`HOLD_EPS_MM`] (less than a microstep);
//!   it then holds for the whole duration of the move. Extruder-only moves (retractions,
//!   primes) and Z-only moves therefore add their whole duration twice to `H` (X and Y both
//!   hold), and nothing to `A`, `B`, `C`.
//! - Dwells (`G4`) count as holding for both axes too: the drivers stay enabled and keep their
//!   holding current. Waits for heaters are not timed by the planner and add nothing.
//!
//! `E = k_a·m_x·A + k_a·m_y·B + k_c·C + k_h·H` (thesis eq. 28) in the thesis's unit, W·ms; the
//! report gives joules (÷ 1000).

use serde::{Deserialize, Serialize};

use crate::math::Bound;
use crate::plan::PlannedMove;

/// Displacement below which an axis counts as holding during a move, mm.
pub const HOLD_EPS_MM: f64 = 1e-6;

/// The regression coefficients of thesis eq. 28. Units make `E` come out in W·ms:
/// `k_a_mx`, `k_a_my` in W·ms per (mm/s)², `k_c` in W·ms per mm, `k_h` in W·ms per s (so
/// `k_h` = 832.7 is 0.83 W of holding power per axis).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct ThesisCoefficients {
    /// `k_a·m_x`: acceleration factor of X.
    pub k_a_mx: f64,
    /// `k_a·m_y`: acceleration factor of Y.
    pub k_a_my: f64,
    /// `k_c`: coasting factor (both axes).
    pub k_c: f64,
    /// `k_h`: holding factor (both axes).
    pub k_h: f64,
}

impl ThesisCoefficients {
    /// The published fit (thesis eq. 28, from Table 3).
    pub const PUBLISHED: ThesisCoefficients = ThesisCoefficients {
        k_a_mx: 0.134857071,
        k_a_my: 0.131575661,
        k_c: 69.14025683,
        k_h: 832.7358875,
    };

    /// Energy of terms `[A, B, C, H]`, W·ms.
    #[inline]
    pub fn energy_wms(&self, t: &[f64; 4]) -> f64 {
        self.k_a_mx * t[0] + self.k_a_my * t[1] + self.k_c * t[2] + self.k_h * t[3]
    }

    /// Energy of terms `[A, B, C, H]`, J.
    #[inline]
    pub fn energy_j(&self, t: &[f64; 4]) -> f64 {
        self.energy_wms(t) * 1e-3
    }

    /// Whether every coefficient is a finite number.
    pub fn is_finite(&self) -> bool {
        [self.k_a_mx, self.k_a_my, self.k_c, self.k_h]
            .iter()
            .all(|v| v.is_finite())
    }
}

impl Default for ThesisCoefficients {
    fn default() -> Self {
        Self::PUBLISHED
    }
}

/// The thesis terms of one move, `[A, B, C, H]` (units in the module docs). A few flops, no
/// branches beyond the two hold tests.
#[inline]
pub fn move_terms(pm: &PlannedMove) -> [f64; 4] {
    move_terms_and_holds(pm).0
}

/// [`move_terms`] and the number of axes (0, 1 or 2 of X, Y) that hold during the move.
#[inline]
pub fn move_terms_and_holds(pm: &PlannedMove) -> ([f64; 4], f64) {
    let p = &pm.profile;
    let (dx, dy) = (pm.delta[0].abs(), pm.delta[1].abs());
    let (sx, sy) = if pm.distance > 0.0 {
        let inv = 1.0 / pm.distance;
        (dx * inv, dy * inv)
    } else {
        (0.0, 0.0)
    };
    // Path-level bracket of thesis eq. 24/25; each axis scales it by s_j²
    // (a_j = s_j a, v_j = s_j v).
    let k = 0.5 * p.acceleration * (p.accel_s * (p.entry + p.peak) + p.decel_s * (p.peak + p.exit));
    let c = p.cruise_s * p.peak * (sx + sy);
    let holds = f64::from(u8::from(dx <= HOLD_EPS_MM)) + f64::from(u8::from(dy <= HOLD_EPS_MM));
    ([sx * sx * k, sy * sy * k, c, holds * pm.duration()], holds)
}

/// The terms of a dwell of `secs`: both axes hold.
#[inline]
pub fn dwell_terms(secs: f64) -> [f64; 4] {
    [0.0, 0.0, 0.0, 2.0 * secs.at_least(0.0)]
}

/// The sums `A`, `B`, `C`, `H` over a file, and the coefficients they are weighed with.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct ThesisReport {
    /// `A`: X acceleration/deceleration term (thesis eq. 24), (mm/s)².
    pub a: f64,
    /// `B`: Y acceleration/deceleration term (thesis eq. 25), (mm/s)².
    pub b: f64,
    /// `C`: coasting distance of X and Y (thesis eq. 26), mm.
    pub c: f64,
    /// `H`: holding time of X and Y (thesis eq. 27), s.
    pub h: f64,
    /// Coefficients used (thesis eq. 28).
    pub coefficients: ThesisCoefficients,
    /// `E` in the thesis's unit, W·ms.
    pub e_wms: f64,
    /// Seconds X and Y spend accelerating or decelerating (both axes counted), for
    /// diagnosis: the thesis's finding is that this time drives the energy.
    pub accel_decel_s: f64,
    /// Seconds X and Y spend coasting (both axes counted).
    pub coast_s: f64,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{MoveClass, Profile};

    fn mv(delta: [f64; 4], profile: Profile) -> PlannedMove {
        let xyz = (delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]).sqrt();
        PlannedMove {
            line: 1,
            tag: 0,
            class: MoveClass::Travel,
            delta,
            distance: if xyz > 0.0 { xyz } else { delta[3].abs() },
            profile,
            start_s: 0.0,
        }
    }

    #[test]
    fn x_move_from_rest_to_rest() {
        // 100 mm at 50 mm/s, 1000 mm/s²: t_a = t_d = 0.05 s, t_c = 1.95 s.
        let p = Profile::new(100.0, 0.0, 50.0, 0.0, 1000.0);
        let t = move_terms(&mv([100.0, 0.0, 0.0, 0.0], p));
        // t_a·a·(0 + 50)/2 + t_d·a·(50 + 0)/2 = 0.05·1000·25·2 = 2500 = v_m².
        assert!((t[0] - 2500.0).abs() < 1e-9, "{}", t[0]);
        assert_eq!(t[1], 0.0);
        assert!((t[2] - 1.95 * 50.0).abs() < 1e-9);
        assert!((t[3] - 2.05).abs() < 1e-12, "Y holds for the whole move");
    }

    #[test]
    fn extruder_only_move_holds_both_axes() {
        let p = Profile::new(1.0, 0.0, 35.0, 0.0, 1250.0);
        let t = move_terms(&mv([0.0, 0.0, 0.0, -1.0], p));
        assert_eq!([t[0], t[1], t[2]], [0.0; 3]);
        assert!((t[3] - 2.0 * p.duration()).abs() < 1e-12);
    }

    #[test]
    fn published_coefficients_in_joules() {
        let t = [1000.0, 1000.0, 10.0, 1.0];
        let e = ThesisCoefficients::default().energy_j(&t);
        let by_hand = (134.857071 + 131.575661 + 691.4025683 + 832.7358875) / 1000.0;
        assert!((e - by_hand).abs() < 1e-12);
    }
}
