//! The kinematic limits of the VTG paper: the critical curvature `K_cr` (VTG eq. 30) and the feed
//! rate that keeps `v`, `a_n` and `j_n` within VTG eq. 29 on a stretch of curvature `κ`.
//!
//! Tangential acceleration and jerk (`a_t ≤ A_t`, `j_t ≤ J_t`) are the firmware planner's
//! business: it accelerates every block within the machine's limits, so the rewriter only
//! writes feed rates, and lowers them where the curvature asks for it.

use serde::Serialize;

/// The limits VTG eq. 30 is built from.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct KinematicLimits {
    /// Highest feed rate `v_max`, mm/s.
    pub v_max_mm_s: f64,
    /// Interpolation period `T_s`, s.
    pub interpolation_period_s: f64,
    /// Chord tolerance `δ`, mm.
    pub chord_tolerance_mm: f64,
    /// Normal acceleration limit `A_n`, mm/s².
    pub normal_accel_mm_s2: f64,
    /// Normal jerk limit `J_n`, mm/s³.
    pub normal_jerk_mm_s3: f64,
    /// Nozzle radius `R_n`, mm.
    pub nozzle_radius_mm: f64,
}

impl KinematicLimits {
    /// VTG eq. 30, in 1/mm:
    /// `K_cr = min(8δ/((v_max T_s)² + 4δ²), A_n/v_max², sqrt(J_n/v_max³), 1/R_n)`.
    pub(crate) fn critical_curvature(&self) -> f64 {
        let v = self.v_max_mm_s;
        let d = self.chord_tolerance_mm;
        let vt = v * self.interpolation_period_s;
        let k = (8.0 * d / (vt * vt + 4.0 * d * d))
            .min(self.normal_accel_mm_s2 / (v * v))
            .min((self.normal_jerk_mm_s3 / (v * v * v)).sqrt())
            .min(1.0 / self.nozzle_radius_mm);
        if k.is_finite() && k > 0.0 {
            k
        } else {
            0.0
        }
    }

    /// The highest feed rate (mm/s) at which a stretch of curvature `kappa` keeps VTG eq. 30's
    /// first three terms, i.e. the chord error of one interpolation period, `a_n = v²κ` and
    /// `j_n = v³κ²`, within their limits; `v_max` on straights.
    pub(crate) fn feed_limit(&self, kappa: f64) -> f64 {
        if kappa.is_nan() || kappa <= 1e-12 {
            return self.v_max_mm_s;
        }
        let d = self.chord_tolerance_mm;
        let chord = (8.0 * d / kappa - 4.0 * d * d).max(0.0).sqrt() / self.interpolation_period_s;
        let accel = (self.normal_accel_mm_s2 / kappa).sqrt();
        let jerk = libm::cbrt(self.normal_jerk_mm_s3 / (kappa * kappa));
        let v = chord.min(accel).min(jerk).min(self.v_max_mm_s);
        if v.is_finite() {
            v.max(0.0)
        } else {
            self.v_max_mm_s
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> KinematicLimits {
        KinematicLimits {
            v_max_mm_s: 100.0,
            interpolation_period_s: 0.001,
            chord_tolerance_mm: 0.05,
            normal_accel_mm_s2: 2000.0,
            normal_jerk_mm_s3: 1e6,
            nozzle_radius_mm: 0.2,
        }
    }

    #[test]
    fn critical_curvature_is_the_tightest_term() {
        let l = limits();
        // Terms: 8·0.05/(0.01 + 0.01) = 20; 2000/1e4 = 0.2; sqrt(1e6/1e6) = 1; 1/0.2 = 5.
        assert!((l.critical_curvature() - 0.2).abs() < 1e-12);
    }

    #[test]
    fn feed_limit_meets_each_bound_at_k_cr() {
        let l = limits();
        let k = l.critical_curvature();
        // At K_cr the full speed is allowed (the binding term is equality).
        assert!((l.feed_limit(k) - 100.0).abs() < 1e-9);
        let v = l.feed_limit(4.0 * k);
        assert!(v * v * 4.0 * k <= 2000.0 * (1.0 + 1e-12));
        assert!(v.powi(3) * (4.0 * k).powi(2) <= 1e6 * (1.0 + 1e-12));
        assert!((v - 50.0).abs() < 1e-9);
    }
}
