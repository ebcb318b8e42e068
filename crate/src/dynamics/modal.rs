//! Modal analysis: natural frequencies and damping ratios of `M q̈ + C q̇ + K q = 0`.
//!
//! The eigenvalues `λ` of the first-order system `ẋ = A x`, `A = [[0, I], [−M⁻¹K, −M⁻¹C]]`,
//! come in conjugate pairs `λ = −ζ ωₙ ± i ωₙ √(1 − ζ²)` for every underdamped mode, so
//! `ωₙ = |λ|` and `ζ = −Re λ / |λ|`. This holds for any damping matrix (the paper's dampers act on
//! `x3` and `x4` only, which is not proportional damping, so the undamped mode shapes would not
//! decouple it). Real eigenvalues (overdamped or rigid-body motion) are not vibration modes and
//! are left out.

use nalgebra::{DMatrix, Schur};
use serde::Serialize;

/// One vibration mode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
pub struct Mode {
    /// Undamped natural frequency `ωₙ / 2π`, Hz.
    pub frequency_hz: f64,
    /// Damping ratio `ζ`.
    pub damping_ratio: f64,
}

/// `A = [[0, I], [−M⁻¹K, −M⁻¹C]]`, or `None` if `M` is singular or anything is not finite.
pub fn state_matrix(m: &DMatrix<f64>, c: &DMatrix<f64>, k: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = m.nrows();
    if [m, c, k]
        .iter()
        .any(|x| x.nrows() != n || x.ncols() != n || x.iter().any(|v| !v.is_finite()))
    {
        return None;
    }
    let m_inv = m.clone().try_inverse()?;
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    a.view_mut((0, n), (n, n)).fill_with_identity();
    a.view_mut((n, 0), (n, n)).copy_from(&(-(&m_inv * k)));
    a.view_mut((n, n), (n, n)).copy_from(&(-(&m_inv * c)));
    a.iter().all(|v| v.is_finite()).then_some(a)
}

/// The underdamped modes of `(M, C, K)`, by increasing frequency. Empty if the matrices are
/// unusable (singular `M`, non-finite entries) or the eigenvalue iteration does not converge.
pub fn modes(m: &DMatrix<f64>, c: &DMatrix<f64>, k: &DMatrix<f64>) -> Vec<Mode> {
    let Some(a) = state_matrix(m, c, k) else {
        return Vec::new();
    };
    let scale = a.amax().max(f64::MIN_POSITIVE);
    let Some(schur) = Schur::try_new(a, f64::EPSILON, 100_000) else {
        return Vec::new();
    };
    let mut out: Vec<Mode> = schur
        .complex_eigenvalues()
        .iter()
        .filter(|l| l.im > 1e-9 * scale.sqrt())
        .map(|l| {
            let wn = l.norm();
            let zeta = -l.re / wn;
            Mode {
                frequency_hz: wn / (2.0 * core::f64::consts::PI),
                // An undamped mode comes out at ±1e-12 or so: call it 0.
                damping_ratio: if zeta.abs() < 1e-9 { 0.0 } else { zeta },
            }
        })
        .collect();
    out.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
    out
}

/// The slowest decay rate of free motion, `min −Re λ` over every eigenvalue of `A` (1/s,
/// overdamped and rigid-body ones too): a state difference shrinks by at least `e^{-r t}` in
/// `t` seconds, asymptotically. `None` if the matrices are unusable or the iteration does not
/// converge; 0 or less where some motion never decays (an undamped mode).
pub fn slowest_decay(m: &DMatrix<f64>, c: &DMatrix<f64>, k: &DMatrix<f64>) -> Option<f64> {
    let a = state_matrix(m, c, k)?;
    let schur = Schur::try_new(a, f64::EPSILON, 100_000)?;
    schur
        .complex_eigenvalues()
        .iter()
        .map(|l| -l.re)
        .reduce(f64::min)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_oscillator_frequency_and_damping() {
        // m = 2 kg, k = 800 N/m: ωₙ = 20 rad/s; c = 4 N·s/m: ζ = c / (2 m ωₙ) = 0.05.
        let m = DMatrix::from_element(1, 1, 2.0);
        let c = DMatrix::from_element(1, 1, 4.0);
        let k = DMatrix::from_element(1, 1, 800.0);
        let modes = modes(&m, &c, &k);
        assert_eq!(modes.len(), 1);
        assert!((modes[0].frequency_hz - 20.0 / (2.0 * core::f64::consts::PI)).abs() < 1e-12);
        assert!((modes[0].damping_ratio - 0.05).abs() < 1e-12);
    }

    #[test]
    fn two_mass_chain_closed_form() {
        // Wall –k– m –k– m: ω² = (k/m)(3 ∓ √5)/2.
        let (mass, k) = (1.5, 6000.0);
        let m = DMatrix::from_diagonal_element(2, 2, mass);
        let c = DMatrix::zeros(2, 2);
        let kk = DMatrix::from_row_slice(2, 2, &[2.0 * k, -k, -k, k]);
        let modes = modes(&m, &c, &kk);
        assert_eq!(modes.len(), 2);
        let s5 = 5f64.sqrt();
        for (mode, sign) in modes.iter().zip([-1.0, 1.0]) {
            let w = (k / mass * (3.0 + sign * s5) / 2.0).sqrt();
            let f = w / (2.0 * core::f64::consts::PI);
            assert!((mode.frequency_hz - f).abs() < 1e-9 * f, "{mode:?} vs {f}");
            assert!(mode.damping_ratio.abs() < 1e-9);
        }
    }

    #[test]
    fn the_slowest_decay_is_the_least_damped_modes() {
        // Two uncoupled oscillators: −Re λ = ζ ωₙ = c / 2m for each; the slower one counts.
        let m = DMatrix::from_diagonal_element(2, 2, 2.0);
        let c = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![4.0, 0.4]));
        let k = DMatrix::from_diagonal(&nalgebra::DVector::from_vec(vec![800.0, 5000.0]));
        let r = slowest_decay(&m, &c, &k).unwrap();
        assert!((r - 0.1).abs() < 1e-9, "{r}");
        // Undamped: no decay.
        let z = DMatrix::zeros(2, 2);
        assert!(slowest_decay(&m, &z, &k).unwrap().abs() < 1e-9);
    }

    #[test]
    fn unusable_matrices_give_no_modes() {
        let z = DMatrix::zeros(2, 2);
        assert!(modes(&z, &z, &z).is_empty());
        let nan = DMatrix::from_element(1, 1, f64::NAN);
        assert!(modes(&nan, &nan, &nan).is_empty());
    }
}
