//! The equivalent lumped-mass model of one axis drive (VTG eq. 1–14).
//!
//! Generalised coordinates `q = [x1, x2, x3, x4, θM, θS]`: axial displacement of ball screws 1
//! and 2, slave pedestal, working table (m), motor and screw angle (rad). Kinetic energy
//! (VTG eq. 11) `E_k = ½ Σ m_i ẋ_i² + ½ J_M θ̇M² + ½ J_S θ̇S²`; potential energy (VTG eq. 12) and
//! dissipation (VTG eq. 13), read with these conventions:
//!
//! - `E_p = ½ k_n x1² + ½ k_n x2² + ½ k_t (θS − θM)² + ½ k_mn (x3 − x_s − i_s θS)² + k_mw (x4 − x3)²`
//!   with `x_s = (x1 + x2)/2`. The paper writes only screw 1's bearing term "for brevity" and
//!   `(θM + θS)` for the twist (angles counted in opposite senses); here both screws are
//!   supported alike and both angles turn the same way. `k_mw (x4 − x3)²` is two flexure hinges of
//!   `½ k_mw` energy each.
//! - `D = ½ C_mn ẋ3² + ½ (2 C_mw) ẋ4²`: one nut damper and two hinge dampers (VTG eq. 13 without
//!   the Rayleigh factor ½, which the paper leaves out).
//!
//! Lagrange's equations (VTG eq. 10) then give `M q̈ + C q̇ + K q = F` (VTG eq. 14) with constant
//! diagonal `M`, `C = ∂²D/∂q̇²` and `K = ∂²E_p/∂q²`. `K` depends on the nut position through the
//! screw's axial and torsional stiffness (VTG eq. 5, 6, 8, 9).
//!
//! Two corrections to the paper's printed formulas, both dimensional: the screw's inertia about
//! its axis is `J_sc = π ρ l_s r_s⁴ / 2` (½ m r², VTG eq. 4 prints /4), and its torsional stiffness
//! is `G J_p / l_n = G π r_s⁴ / (2 l_n)` in N·m/rad (VTG eq. 6 prints `G π r_s² / (4 l_n)`, which
//! is not a torsional stiffness). VTG eq. 3 adds `i_s² m_3` to the screw inertia; that is the
//! pedestal reflected onto the screw in a model without `x3`. Here `x3` is a coordinate of its
//! own, so that term would count the pedestal twice and is left out.

use nalgebra::{SMatrix, SVector};

use super::parameters::{BallScrew, Belt, Drive, ServoLoop};

/// 6 × 6 matrix over `q`.
pub type Mat6 = SMatrix<f64, 6, 6>;
/// Vector over `q`.
pub type Vec6 = SVector<f64, 6>;

/// Index of each coordinate in `q`.
pub mod dof {
    /// Ball screw 1 axial displacement.
    pub const X1: usize = 0;
    /// Ball screw 2 axial displacement.
    pub const X2: usize = 1;
    /// Slave pedestal.
    pub const X3: usize = 2;
    /// Working table.
    pub const X4: usize = 3;
    /// Motor angle.
    pub const THETA_M: usize = 4;
    /// Screw angle.
    pub const THETA_S: usize = 5;
}

/// The coefficients of VTG eq. 11–13 at one nut position.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Coefficients {
    /// Equivalent masses `m1..m4`, kg (VTG eq. 1–2).
    pub m: [f64; 4],
    /// Motor inertia `J_M`, kg·m².
    pub j_m: f64,
    /// Screw inertia `J_S`, kg·m² (VTG eq. 3–4).
    pub j_s: f64,
    /// Axial composite stiffness of screw and bearing `k_n` (VTG eq. 5, 8), N/m.
    pub k_n: f64,
    /// Torsional composite stiffness of screw and coupling `k_t` (VTG eq. 6, 9), N·m/rad.
    pub k_t: f64,
    /// Nut contact stiffness `k_mn` (VTG eq. 7), N/m.
    pub k_mn: f64,
    /// One flexure hinge `k_mw`, N/m.
    pub k_mw: f64,
    /// Nut damping `C_mn`, N·s/m.
    pub c_mn: f64,
    /// One hinge's damping `C_mw`, N·s/m.
    pub c_mw: f64,
    /// Transmission ratio `i_s`, m/rad.
    pub i_s: f64,
}

/// Mass, damping and stiffness matrices (VTG eq. 14).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Matrices {
    /// `M`.
    pub m: Mat6,
    /// `C`.
    pub c: Mat6,
    /// `K`.
    pub k: Mat6,
}

/// VTG eq. 7: contact stiffness of a preloaded nut, `0.8 k_c (F_z / 0.1 C_a)^⅓`.
pub fn nut_contact_stiffness(k_c: f64, preload: f64, dynamic_load_rating: f64) -> f64 {
    0.8 * k_c * libm::cbrt(preload / (0.1 * dynamic_load_rating))
}

/// Series combination of two springs (VTG eq. 8, 9).
fn series(a: f64, b: f64) -> f64 {
    1.0 / (1.0 / a + 1.0 / b)
}

/// Inertia the motor sees when the whole ball-screw axis moves rigidly, kg·m².
pub fn rigid_inertia_ball_screw(d: &BallScrew) -> f64 {
    let c = ball_screw(d, 0.5 * d.screw_length_m);
    c.j_m + c.j_s + c.i_s * c.i_s * (c.m[2] + c.m[3])
}

/// Inertia the motor sees when the whole belt axis moves rigidly, kg·m².
pub fn rigid_inertia_belt(b: &Belt) -> f64 {
    let i = b.pulley_radius_m;
    b.motor_inertia_kg_m2
        + b.pulley_inertia_kg_m2
        + i * i * (b.carriage_mass_kg + b.payload_mass_kg)
}

/// Coefficients of a ball-screw drive with the nut `l_n` from the coupling (m).
pub fn ball_screw(d: &BallScrew, l_n: f64) -> Coefficients {
    let pi = core::f64::consts::PI;
    let r = d.screw_radius_m;
    let l_n = l_n.clamp(0.01 * d.screw_length_m, d.screw_length_m);
    let m_sc = pi * d.density_kg_m3 * d.screw_length_m * r * r; // VTG eq. 2
    let m1 = m_sc + d.rotor_mass_kg + d.coupling_mass_kg; // VTG eq. 1
    let j_sc = pi * d.density_kg_m3 * d.screw_length_m * r.powi(4) / 2.0; // VTG eq. 4 (½ m r²)
    let k_sn = pi * r * r * d.youngs_modulus_pa / l_n; // VTG eq. 5
    let k_st = d.shear_modulus_pa * pi * r.powi(4) / (2.0 * l_n); // VTG eq. 6 (G J_p / l)
    Coefficients {
        m: [m1, m1, d.pedestal_mass_kg, d.table_mass_kg],
        j_m: d.motor_inertia_kg_m2,
        j_s: j_sc + d.coupling_inertia_kg_m2,       // VTG eq. 3
        k_n: series(d.bearing_stiffness_n_m, k_sn), // VTG eq. 8
        k_t: series(d.coupling_stiffness_nm_rad, k_st), // VTG eq. 9
        k_mn: nut_contact_stiffness(
            d.nut_reference_stiffness_n_m,
            d.preload_n,
            d.dynamic_load_rating_n,
        ),
        k_mw: d.hinge_stiffness_n_m,
        c_mn: d.nut_damping_ns_m,
        c_mw: d.hinge_damping_ns_m,
        i_s: d.lead_m / (2.0 * pi),
    }
}

/// Coefficients of a belt drive with the carriage `l1` from the motor pulley (m).
pub fn belt(b: &Belt, l1: f64) -> Coefficients {
    let span = b.span_length_m;
    let l1 = l1.clamp(0.02 * span, 0.98 * span);
    let l2 = span - l1;
    Coefficients {
        m: [
            b.motor_mount_mass_kg,
            b.idler_mass_kg,
            b.carriage_mass_kg,
            b.payload_mass_kg,
        ],
        j_m: b.motor_inertia_kg_m2,
        j_s: b.pulley_inertia_kg_m2,
        k_n: b.mount_stiffness_n_m,
        k_t: b.shaft_stiffness_nm_rad,
        k_mn: b.belt_ea_n * (1.0 / l1 + 1.0 / l2),
        k_mw: b.mount_hinge_stiffness_n_m,
        c_mn: b.carriage_damping_ns_m,
        c_mw: b.payload_damping_ns_m,
        i_s: b.pulley_radius_m,
    }
}

impl Drive {
    /// Coefficients with the axis at `position_m` (machine coordinate, m).
    pub fn coefficients(&self, position_m: f64) -> Coefficients {
        match self {
            Drive::BallScrew(d) => ball_screw(d, d.nut_offset_m + position_m),
            Drive::Belt(b) => belt(b, b.span_offset_m + position_m),
        }
    }

    /// The drive's position loop.
    pub fn servo(&self) -> &ServoLoop {
        match self {
            Drive::BallScrew(d) => &d.servo,
            Drive::Belt(b) => &b.servo,
        }
    }

    /// Travel over which the stiffness varies, m (the screw or belt span).
    pub fn travel_m(&self) -> f64 {
        match self {
            Drive::BallScrew(d) => d.screw_length_m,
            Drive::Belt(b) => b.span_length_m,
        }
    }
}

impl Coefficients {
    /// `M`, `C`, `K` of the mechanism alone (VTG eq. 14); `K` is singular: the rigid-body motion of
    /// the axis (every part moving together) stores no energy.
    pub fn matrices(&self) -> Matrices {
        use dof::*;
        let mut m = Mat6::zeros();
        for (i, &mi) in self.m.iter().enumerate() {
            m[(i, i)] = mi;
        }
        m[(THETA_M, THETA_M)] = self.j_m;
        m[(THETA_S, THETA_S)] = self.j_s;

        let mut c = Mat6::zeros();
        c[(X3, X3)] = self.c_mn;
        c[(X4, X4)] = 2.0 * self.c_mw;

        let mut k = Mat6::zeros();
        let mut spring = |g: Vec6, s: f64| k += g * g.transpose() * s;
        let e = |i: usize| {
            let mut v = Vec6::zeros();
            v[i] = 1.0;
            v
        };
        spring(e(X1), self.k_n);
        spring(e(X2), self.k_n);
        spring(e(THETA_S) - e(THETA_M), self.k_t);
        let mut nut = e(X3) - e(X1) * 0.5 - e(X2) * 0.5;
        nut[THETA_S] = -self.i_s;
        spring(nut, self.k_mn);
        spring(e(X4) - e(X3), 2.0 * self.k_mw);
        Matrices { m, c, k }
    }

    /// The machine as it runs: the mechanism with the position loop acting on `θM` as a
    /// torsional spring `K_p` and damper `K_d` to the commanded angle.
    pub fn closed_loop(&self, servo: &ServoLoop) -> Matrices {
        let mut mats = self.matrices();
        mats.k[(dof::THETA_M, dof::THETA_M)] += servo.stiffness_nm_per_rad;
        mats.c[(dof::THETA_M, dof::THETA_M)] += servo.damping_nms_per_rad;
        mats
    }

    /// Displacement of every coordinate per unit rigid motion of the axis (1 m of table travel).
    pub fn rigid_mode(&self) -> Vec6 {
        Vec6::new(0.0, 0.0, 1.0, 1.0, 1.0 / self.i_s, 1.0 / self.i_s)
    }

    /// Load on `q` per unit commanded velocity and per unit commanded acceleration, when `q` is
    /// measured from the commanded motion (`x3`, `x4` minus the commanded position, angles minus
    /// it over `i_s`): inertia `−M ρ a`, absolute dampers `−C ρ v`, and the feed-forward torque
    /// `i_s (k_a m_eq a + k_v c_eq v)` on the motor, with `m_eq = ρᵀMρ`, `c_eq = ρᵀCρ`.
    pub fn command_loads(&self, servo: &ServoLoop) -> (Vec6, Vec6) {
        let mech = self.matrices();
        let rho = self.rigid_mode();
        let m_rho = mech.m * rho;
        let c_rho = mech.c * rho;
        let m_eq = rho.dot(&m_rho);
        let c_eq = rho.dot(&c_rho);
        let mut f_v = -c_rho;
        let mut f_a = -m_rho;
        f_v[dof::THETA_M] += self.i_s * servo.velocity_feedforward * c_eq;
        f_a[dof::THETA_M] += self.i_s * servo.acceleration_feedforward * m_eq;
        (f_v, f_a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::parameters::MachineDynamics;

    #[test]
    fn rigid_motion_stores_no_energy_and_matrices_are_symmetric() {
        for name in crate::dynamics::parameters::PRESETS {
            let p = MachineDynamics::preset(name).unwrap();
            let c = p.x.coefficients(0.1);
            let mats = c.matrices();
            let rho = c.rigid_mode();
            assert!((mats.k * rho).norm() < 1e-6 * mats.k.norm());
            assert!((mats.k - mats.k.transpose()).norm() == 0.0);
            // With full feed-forward the command loads do no work along the rigid mode.
            let mut servo = *p.x.servo();
            servo.velocity_feedforward = 1.0;
            servo.acceleration_feedforward = 1.0;
            let (fv, fa) = c.command_loads(&servo);
            assert!(rho.dot(&fv).abs() < 1e-9 * fv.norm().max(1.0));
            assert!(rho.dot(&fa).abs() < 1e-9 * fa.norm().max(1.0));
        }
    }

    #[test]
    fn screw_softens_as_the_nut_moves_away() {
        let p = MachineDynamics::preset("ldam-ball-screw").unwrap();
        let near = p.x.coefficients(0.0);
        let far = p.x.coefficients(0.9);
        assert!(far.k_n < near.k_n && far.k_t < near.k_t);
        // VTG eq. 7 with preload 5 % of C_a: 0.8 · 0.5^⅓ of the reference stiffness.
        let k = nut_contact_stiffness(300e6, 500.0, 10e3);
        assert!((k - 0.8 * 300e6 * 0.5f64.powf(1.0 / 3.0)).abs() < 1.0);
    }
}
