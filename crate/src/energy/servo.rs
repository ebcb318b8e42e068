//! A physical model of servo (or any closed-loop) X/Y drives, for machines such as the VTG
//! paper's large-format ball-screw printer, where the thesis's stepper regression does not apply.
//!
//! Per move and per axis `j` ∈ {X, Y} (the axis follows the path trapezoid scaled by
//! `s_j = |δ_j|/d`, as in the thesis model), with moving mass `m_j`, friction force `F_j`:
//!
//! - kinetic energy given while accelerating: `½·m_j·s_j²·(v_m² − v₀²)`;
//! - friction work over the axis's travel: `F_j·|δ_j|`;
//!   both drawn through the drive's efficiency `η` (electrical → mechanical);
//! - braking: the kinetic energy `½·m_j·s_j²·(v_m² − v_f²)` is dissipated, and a fraction
//!   `regeneration` of it is returned (0 unless the drive has a regenerative DC bus);
//! - copper loss `c·F²` while the motor exerts force `F`: `m_j·a_j + F_j` while accelerating,
//!   `F_j` while coasting, `|m_j·a_j − F_j|` while braking (friction helps);
//! - standby: every drive enabled draws `standby_w` for the whole move (and dwells).
//!
//! SI units inside: speeds are converted from mm/s, accelerations from mm/s², distances from mm.
//! Z and the extruder are left out, as in the thesis model (their energy is small).

use serde::{Deserialize, Serialize};

use crate::math::Bound;
use crate::plan::PlannedMove;

/// Parameters of the physical servo model. Defaults describe a large-format ball-screw gantry
/// like the VTG paper's printer (1000 × 800 × 350 mm); they are engineering estimates, not
/// measurements, and should be replaced with the machine's own values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct ServoProfile {
    /// Moving mass per axis X, Y, kg (print head carriage on X; the gantry, which carries X,
    /// on Y; ball-screw rotors add their reflected inertia).
    pub moving_mass_kg: [f64; 2],
    /// Friction force per axis (linear guides, ball-screw preload, seals), N.
    pub friction_n: [f64; 2],
    /// Electrical-to-mechanical efficiency of drive, motor and screw, 0..=1 (ball screws ~0.9,
    /// servo motor and amplifier ~0.85–0.9).
    pub efficiency: f64,
    /// Copper-loss coefficient per axis, W per N² of axial force (winding resistance over the
    /// square of the force constant through the screw).
    pub copper_w_per_n2: [f64; 2],
    /// Power each enabled drive draws at standstill (amplifier logic, holding loop), W.
    pub standby_w: [f64; 2],
    /// Fraction of braking energy the drives return, 0..=1.
    pub regeneration: f64,
}

impl Default for ServoProfile {
    fn default() -> Self {
        Self {
            moving_mass_kg: [10.0, 25.0],
            friction_n: [15.0, 20.0],
            efficiency: 0.8,
            copper_w_per_n2: [2e-5, 2e-5],
            standby_w: [10.0, 10.0],
            regeneration: 0.0,
        }
    }
}

/// The physical model's energy, by kind, J.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct ServoReport {
    /// Kinetic energy drawn while accelerating (net of regeneration), J.
    pub kinetic_j: f64,
    /// Friction work, J.
    pub friction_j: f64,
    /// Copper losses, J.
    pub copper_j: f64,
    /// Standby draw of the enabled drives, J.
    pub standby_j: f64,
}

impl ServoReport {
    /// Sum of the parts, J.
    pub fn total_j(&self) -> f64 {
        self.kinetic_j + self.friction_j + self.copper_j + self.standby_j
    }
}

impl ServoProfile {
    /// Whether every parameter is finite and in range.
    pub fn is_valid(&self) -> bool {
        let nonneg = |v: f64| v.is_finite() && v >= 0.0;
        self.moving_mass_kg.iter().all(|&v| nonneg(v))
            && self.friction_n.iter().all(|&v| nonneg(v))
            && self.copper_w_per_n2.iter().all(|&v| nonneg(v))
            && self.standby_w.iter().all(|&v| nonneg(v))
            && self.efficiency.is_finite()
            && self.efficiency > 0.0
            && self.efficiency <= 1.0
            && (0.0..=1.0).contains(&self.regeneration)
    }

    /// Adds the energy of one move to `r`; returns it, J.
    #[inline]
    pub fn add_move(&self, pm: &PlannedMove, r: &mut ServoReport) -> f64 {
        let p = &pm.profile;
        let inv_d = if pm.distance > 0.0 {
            1.0 / pm.distance
        } else {
            0.0
        };
        let inv_eta = 1.0 / self.efficiency;
        let (v0, vm, vf) = (p.entry * 1e-3, p.peak * 1e-3, p.exit * 1e-3);
        let a = p.acceleration * 1e-3;
        let (mut kinetic, mut friction, mut copper) = (0.0, 0.0, 0.0);
        for j in 0..2 {
            let dj = pm.delta[j].abs();
            let s = dj * inv_d;
            let m = self.moving_mass_kg[j];
            let f = self.friction_n[j];
            let gained = 0.5 * m * s * s * (vm * vm - v0 * v0);
            let braked = 0.5 * m * s * s * (vm * vm - vf * vf);
            kinetic += gained * inv_eta - self.regeneration * self.efficiency * braked;
            friction += f * dj * 1e-3 * inv_eta;
            let push = m * s * a;
            copper += self.copper_w_per_n2[j]
                * ((push + f) * (push + f) * p.accel_s
                    + f * f * p.cruise_s
                    + (push - f) * (push - f) * p.decel_s);
        }
        let standby = (self.standby_w[0] + self.standby_w[1]) * pm.duration();
        r.kinetic_j += kinetic;
        r.friction_j += friction;
        r.copper_j += copper;
        r.standby_j += standby;
        kinetic + friction + copper + standby
    }

    /// Adds a dwell of `secs` (standby only) to `r`; returns its energy, J.
    #[inline]
    pub fn add_dwell(&self, secs: f64, r: &mut ServoReport) -> f64 {
        let e = (self.standby_w[0] + self.standby_w[1]) * secs.at_least(0.0);
        r.standby_j += e;
        e
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{MoveClass, Profile};

    #[test]
    fn x_move_by_hand() {
        let s = ServoProfile {
            moving_mass_kg: [2.0, 5.0],
            friction_n: [10.0, 10.0],
            efficiency: 0.5,
            copper_w_per_n2: [0.0, 0.0],
            standby_w: [1.0, 1.0],
            regeneration: 0.0,
        };
        // 100 mm at 100 mm/s from rest to rest, 1000 mm/s².
        let profile = Profile::new(100.0, 0.0, 100.0, 0.0, 1000.0);
        let pm = PlannedMove {
            line: 1,
            tag: 0,
            class: MoveClass::Travel,
            delta: [100.0, 0.0, 0.0, 0.0],
            distance: 100.0,
            profile,
            start_s: 0.0,
        };
        let mut r = ServoReport::default();
        let e = s.add_move(&pm, &mut r);
        // ½·2 kg·(0.1 m/s)² = 0.01 J, over η: 0.02 J; friction 10 N·0.1 m / 0.5 = 2 J;
        // standby 2 W over 0.1 s + 0.9 s + 0.1 s (5 mm accelerating, 90 mm cruising, 5 mm
        // braking).
        let standby = 2.0 * 1.1;
        assert!((profile.duration() - 1.1).abs() < 1e-12);
        assert!((r.kinetic_j - 0.02).abs() < 1e-12);
        assert!((r.friction_j - 2.0).abs() < 1e-12);
        assert!((e - (0.02 + 2.0 + standby)).abs() < 1e-12);
    }
}
