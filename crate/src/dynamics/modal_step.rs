//! The simulation step in an axis's real modal coordinates.
//!
//! The exact discretisation ([`integrate`](super::integrate)) gives a dense `Φ` (12 × 12), and
//! the step `x ← Φ x + Γ u` costs 144 products per axis and period: the largest share of a
//! simulation. `Φ = e^{A T_s}` has `A`'s eigenvectors, so in the real modal basis `T` (for each
//! conjugate pair `λ = σ ± iω` with eigenvector `a ± ib`, the columns `a` and `b`), `T⁻¹ Φ T` is
//! block-diagonal with one 2 × 2 block `e^{σT_s}[[cos ωT_s, sin ωT_s], [−sin ωT_s, cos ωT_s]]`
//! per mode. The step then costs 24 products, plus 12 for the table's deviation `eᵀ T z` each
//! period; the physical state is only rebuilt where it is needed (at rests, and when the axis
//! crosses into another nut-position bucket, whose basis differs).
//!
//! The basis is found by inverse iteration on the Schur eigenvalues and then *checked*: `T⁻¹ΦT`
//! must be block-diagonal to 1e-10 of its largest entry and `T` well conditioned, or the bucket
//! keeps the dense step (repeated or nearly repeated eigenvalues, which no preset has, would
//! fail the check). The blocks are taken from that product, not from `e^{λT_s}`, so what is
//! simulated is the same exact `Φ`, rounded differently (tested against the dense step).

use nalgebra::{Complex, DMatrix, DVector, Schur};

/// States of one axis.
const N: usize = 12;
/// Largest `‖T‖ ‖T⁻¹‖` (Frobenius) accepted: beyond it rounding in the change of basis could
/// reach the nanometres the simulation resolves.
const MAX_CONDITION: f64 = 1e6;
/// Largest entry outside the 2 × 2 blocks of `T⁻¹ΦT`, relative to its largest entry.
const MAX_OFF_BLOCK: f64 = 1e-10;

/// `Φ`, `Γ` in modal coordinates, with the change of basis both ways.
#[derive(Debug, Clone)]
pub struct ModalStepper {
    /// The 2 × 2 diagonal blocks of `T⁻¹ΦT`, row-major.
    blocks: [[f64; 4]; N / 2],
    /// `T⁻¹Γ`: response to the commanded velocity and to the acceleration.
    gamma: [[f64; N]; 2],
    /// `T`, column-major: modal coordinates to physical state.
    to_physical: [[f64; N]; N],
    /// `T⁻¹`, column-major.
    to_modal: [[f64; N]; N],
    /// Rows of `T` for the table's deviation and its velocity.
    table: [[f64; N]; 2],
}

impl ModalStepper {
    /// The modal form of the step `Φ`, `Γ` of the continuous model `a`, or `None` when its
    /// basis fails the checks (see the module documentation).
    pub fn new(
        a: &DMatrix<f64>,
        phi: &DMatrix<f64>,
        gamma: &DMatrix<f64>,
        rows: [usize; 2],
    ) -> Option<Self> {
        if a.shape() != (N, N) || phi.shape() != (N, N) || gamma.shape() != (N, 2) {
            return None;
        }
        let t = real_modal_basis(a)?;
        let t_inv = t.clone().try_inverse()?;
        if t.norm() * t_inv.norm() > MAX_CONDITION {
            return None;
        }
        let d = &t_inv * phi * &t;
        let g = &t_inv * gamma;
        let largest = d.amax();
        let off_block = (0..N)
            .flat_map(|r| (0..N).map(move |c| (r, c)))
            .filter(|&(r, c)| r / 2 != c / 2)
            .map(|(r, c)| d[(r, c)].abs())
            .fold(0.0, f64::max);
        if !(largest.is_finite() && off_block <= MAX_OFF_BLOCK * largest) {
            return None;
        }
        Some(Self {
            blocks: core::array::from_fn(|j| {
                let i = 2 * j;
                [d[(i, i)], d[(i, i + 1)], d[(i + 1, i)], d[(i + 1, i + 1)]]
            }),
            gamma: core::array::from_fn(|c| core::array::from_fn(|r| g[(r, c)])),
            to_physical: core::array::from_fn(|c| core::array::from_fn(|r| t[(r, c)])),
            to_modal: core::array::from_fn(|c| core::array::from_fn(|r| t_inv[(r, c)])),
            table: rows.map(|row| core::array::from_fn(|c| t[(row, c)])),
        })
    }

    /// One period: `z ← D z + T⁻¹Γ [v, a]`.
    #[inline]
    pub fn step(&self, z: &mut [f64; N], v: f64, a: f64) {
        for (j, b) in self.blocks.iter().enumerate() {
            let (i, k) = (2 * j, 2 * j + 1);
            let (zi, zk) = (z[i], z[k]);
            z[i] = b[0] * zi + b[1] * zk + self.gamma[0][i] * v + self.gamma[1][i] * a;
            z[k] = b[2] * zi + b[3] * zk + self.gamma[0][k] * v + self.gamma[1][k] * a;
        }
    }

    /// Row `which` of the rows given to [`ModalStepper::new`] (the table's deviation, its
    /// velocity) of the physical state `T z`.
    #[inline]
    pub fn physical_row(&self, z: &[f64; N], which: usize) -> f64 {
        // Four running sums, not one: a chain of twelve dependent additions was a tenth of a
        // simulation's time.
        let t = &self.table[which];
        let mut acc = [0.0f64; 4];
        for (tc, zc) in t.chunks_exact(4).zip(z.chunks_exact(4)) {
            for ((a, t), z) in acc.iter_mut().zip(tc).zip(zc) {
                *a += t * z;
            }
        }
        (acc[0] + acc[1]) + (acc[2] + acc[3])
    }

    /// The physical state `T z`.
    pub fn to_physical(&self, z: &[f64; N]) -> [f64; N] {
        product(&self.to_physical, z)
    }

    /// The modal coordinates `T⁻¹ x` of the physical state `x`.
    pub fn to_modal(&self, x: &[f64; N]) -> [f64; N] {
        product(&self.to_modal, x)
    }
}

/// Both axes' modal steps side by side: `z[r][l]` is row `r` of axis `l`'s modal state, and
/// each coefficient is laid out the same way, so that a step is a run of two-lane products
/// (SSE2 natively, SIMD128 in the browser) instead of two runs of single ones with shuffles
/// between them. Each lane's arithmetic is [`ModalStepper::step`]'s and
/// [`ModalStepper::physical_row`]'s, operation for operation: the results are the same bits.
#[derive(Debug, Clone, Default)]
pub struct ModalPair {
    blocks: [[[f64; 2]; 4]; N / 2],
    gamma: [[[f64; 2]; N]; 2],
    table: [[[f64; 2]; N]; 2],
}

impl ModalPair {
    /// Lane `lane` takes `m`'s coefficients.
    pub fn set_lane(&mut self, lane: usize, m: &ModalStepper) {
        into_lane(
            self.blocks.as_flattened_mut(),
            m.blocks.as_flattened(),
            lane,
        );
        into_lane(self.gamma.as_flattened_mut(), m.gamma.as_flattened(), lane);
        into_lane(self.table.as_flattened_mut(), m.table.as_flattened(), lane);
    }

    /// One period of both axes: [`ModalStepper::step`] lane by lane.
    #[inline]
    pub fn step(&self, z: &mut [[f64; 2]; N], v: [f64; 2], a: [f64; 2]) {
        for (j, b) in self.blocks.iter().enumerate() {
            let (i, k) = (2 * j, 2 * j + 1);
            let (zi, zk) = (z[i], z[k]);
            let (gi, gk) = (
                (self.gamma[0][i], self.gamma[1][i]),
                (self.gamma[0][k], self.gamma[1][k]),
            );
            for l in 0..2 {
                z[i][l] = b[0][l] * zi[l] + b[1][l] * zk[l] + gi.0[l] * v[l] + gi.1[l] * a[l];
                z[k][l] = b[2][l] * zi[l] + b[3][l] * zk[l] + gk.0[l] * v[l] + gk.1[l] * a[l];
            }
        }
    }

    /// Row `which` of both physical states: [`ModalStepper::physical_row`] lane by lane.
    #[inline]
    pub fn physical_rows(&self, z: &[[f64; 2]; N], which: usize) -> [f64; 2] {
        let t = &self.table[which];
        let mut acc = [[0.0f64; 2]; 4];
        for (tc, zc) in t.chunks_exact(4).zip(z.chunks_exact(4)) {
            for ((a, t), z) in acc.iter_mut().zip(tc).zip(zc) {
                for l in 0..2 {
                    a[l] += t[l] * z[l];
                }
            }
        }
        core::array::from_fn(|l| (acc[0][l] + acc[1][l]) + (acc[2][l] + acc[3][l]))
    }
}

/// `values` into lane `lane` of `pairs`, in order.
fn into_lane(pairs: &mut [[f64; 2]], values: &[f64], lane: usize) {
    for (p, &v) in pairs.iter_mut().zip(values) {
        p[lane] = v;
    }
}

/// `m x` for a column-major `m` (the dense step's product too; it unrolls and vectorises).
pub(super) fn product(m: &[[f64; N]; N], x: &[f64; N]) -> [f64; N] {
    let mut y = [0.0; N];
    for (col, &xc) in m.iter().zip(x) {
        for (yr, p) in y.iter_mut().zip(col) {
            *yr += p * xc;
        }
    }
    y
}

/// The real modal basis of `a`: for each eigenvalue with positive imaginary part the real and
/// imaginary parts of its eigenvector, then the real eigenvalues' eigenvectors, which pair up
/// into diagonal 2 × 2 blocks. `None` if the eigenvalues do not converge, the real ones are
/// odd in number (a pair split by rounding) or an eigenvector cannot be found.
fn real_modal_basis(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let n = a.nrows();
    let scale = a.amax().max(f64::MIN_POSITIVE);
    let eigenvalues = Schur::try_new(a.clone(), f64::EPSILON, 100_000)?.complex_eigenvalues();
    let tol = 1e-9 * scale;
    let mut complex: Vec<Complex<f64>> =
        eigenvalues.iter().copied().filter(|l| l.im > tol).collect();
    let mut real: Vec<Complex<f64>> = eigenvalues
        .iter()
        .filter(|l| l.im.abs() <= tol)
        .map(|l| Complex::new(l.re, 0.0))
        .collect();
    if 2 * complex.len() + real.len() != n || real.len() % 2 != 0 {
        return None;
    }
    complex.sort_by(|x, y| x.im.total_cmp(&y.im));
    real.sort_by(|x, y| x.re.total_cmp(&y.re));
    let mut columns: Vec<DVector<f64>> = Vec::with_capacity(n);
    for &lambda in &complex {
        let v = orthogonal_phase(eigenvector(a, lambda)?);
        columns.push(v.map(|c| c.re));
        columns.push(v.map(|c| c.im));
    }
    for &lambda in &real {
        let v = eigenvector(a, lambda)?.map(|c| c.re);
        let norm = v.norm();
        if norm.is_nan() || norm <= 0.0 {
            return None;
        }
        columns.push(v / norm);
    }
    Some(DMatrix::from_columns(&columns))
}

/// The eigenvector of `a` for `lambda`, by inverse iteration from a shift just beside it.
fn eigenvector(a: &DMatrix<f64>, lambda: Complex<f64>) -> Option<DVector<Complex<f64>>> {
    let n = a.nrows();
    let shift = lambda + Complex::new(1e-10, 1e-10) * lambda.norm().max(1.0);
    let m = DMatrix::from_fn(n, n, |r, c| {
        Complex::new(a[(r, c)], 0.0)
            - if r == c {
                shift
            } else {
                Complex::new(0.0, 0.0)
            }
    });
    let lu = m.lu();
    let mut v = DVector::from_fn(n, |i, _| Complex::new(1.0 + i as f64 * 0.1, 0.0));
    for _ in 0..3 {
        v = lu.solve(&v)?;
        let norm = v.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return None;
        }
        v /= Complex::new(norm, 0.0);
    }
    Some(v)
}

/// `v` turned by the phase that makes its real and imaginary parts orthogonal, the
/// best-conditioned pair of real columns it gives.
fn orthogonal_phase(v: DVector<Complex<f64>>) -> DVector<Complex<f64>> {
    let re = v.map(|c| c.re);
    let im = v.map(|c| c.im);
    let theta = 0.5 * f64::atan2(-2.0 * re.dot(&im), re.norm_squared() - im.norm_squared());
    v * Complex::new(theta.cos(), theta.sin())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_oscillator_s_block_is_its_rotation_and_decay() {
        // ẍ + 2ζω ẋ + ω² x = 0: one block e^{σT}[[cos, sin], [−sin, cos]] up to the basis.
        let (w, zeta, ts) = (2.0 * core::f64::consts::PI * 50.0, 0.02, 1e-3);
        let a = DMatrix::from_row_slice(2, 2, &[0.0, 1.0, -w * w, -2.0 * zeta * w]);
        let t = real_modal_basis(&a).unwrap();
        let phi = (&a * ts).exp();
        let d = t.clone().try_inverse().unwrap() * phi * t;
        let sigma = -zeta * w;
        let wd = w * (1.0 - zeta * zeta).sqrt();
        let decay = (sigma * ts).exp();
        // Trace and determinant are basis-free: 2 e^{σT} cos(ω_d T) and e^{2σT}.
        assert!((d.trace() - 2.0 * decay * (wd * ts).cos()).abs() < 1e-12);
        assert!((d.determinant() - decay * decay).abs() < 1e-12);
    }
}
