//! Least-squares cubic B-spline fit of a polyline within a tolerance (Piegl & Tiller A9.7 with
//! data-placed knots, banded normal equations, knot insertion where the error is too large).
//!
//! The data are the path with its corners blended ([`crate::vtg::blend::samples`]): densely sampled
//! over each corner transition, sparsely along straight runs. Because A9.7 puts the same number
//! of data points in every knot span, the knots crowd at corners and thin out on straights, so
//! a long straight stays straight while a corner follows its transition. The first and last
//! points are interpolated (the path keeps its end points).

use crate::vec3::{norm, sub};
use crate::vtg::bspline::{basis_by_degree, find_span, find_span_from, reciprocals, Curve, DEGREE};
use crate::vtg::tuning::TUNING;

/// A fitted curve with the data it was fitted to.
#[derive(Debug, Clone)]
pub(crate) struct Fit {
    /// The curve, parametrised by the arc length of the original polyline.
    pub(crate) curve: Curve,
    /// Largest distance from a data point to the curve at its parameter, mm.
    #[cfg_attr(not(test), allow(dead_code))] // checked by the tests only
    pub(crate) max_residual_mm: f64,
}

/// Fits a clamped cubic B-spline to `data` at parameters `params` (non-decreasing, distinct
/// ends) so that every data point lies within `tol_mm` of the curve at its parameter. `None`
/// when the data are degenerate or the tolerance cannot be met.
pub(crate) fn fit(data: &[[f64; 3]], params: &[f64], tol_mm: f64) -> Option<Fit> {
    let m = data.len().checked_sub(1)?;
    if params.len() != data.len() || m < DEGREE || !tol_mm.is_finite() || tol_mm <= 0.0 {
        return None;
    }
    let (u0, u1) = (*params.first()?, *params.last()?);
    if u1 - u0 <= 1e-9 {
        return None;
    }
    // A9.7 (NURBS Book eq. 9.68–9.69): n + 1 control points, interior knots averaging the
    // parameters.
    let n = (((m + 1) as f64 / TUNING.points_per_span) as usize).clamp(DEGREE, m);
    let d = (m + 1) as f64 / (n - DEGREE + 1) as f64;
    let mut knots = vec![u0; DEGREE + 1];
    for j in 1..=(n - DEGREE) {
        let jd = j as f64 * d;
        let i = (jd.floor() as usize).clamp(1, m);
        let alpha = jd - jd.floor();
        let k = (1.0 - alpha) * params[i - 1] + alpha * params[i];
        let prev = knots.last().copied().unwrap_or(u0);
        knots.push(k.max(prev));
    }
    knots.extend([u1; DEGREE + 1]);
    for _ in 0..TUNING.fit_rounds {
        let (curve, bases) = solve(data, params, &knots)?;
        let (worst, bad_spans) = residuals(data, params, (&curve, &bases), tol_mm);
        if !worst.is_finite() {
            return None;
        }
        if bad_spans.is_empty() {
            return Some(Fit {
                curve,
                max_residual_mm: worst,
            });
        }
        // Insert a knot in the middle of every span that misses the tolerance.
        let mut next = Vec::with_capacity(knots.len() + bad_spans.len());
        for (i, &k) in knots.iter().enumerate() {
            next.push(k);
            if bad_spans.contains(&i) {
                if let Some(&k1) = knots.get(i + 1) {
                    if k1 - k > 1e-6 {
                        next.push(0.5 * (k + k1));
                    }
                }
            }
        }
        if next.len() == knots.len() {
            return None;
        }
        knots = next;
    }
    None
}

/// The largest residual of `curve` (fitted with `bases`) at the data and halfway between
/// consecutive data (consecutive samples lie on one segment of the polyline, so the midpoint
/// is on it too: ringing between data points is caught as well), and the knot spans where it
/// exceeds `tol_mm`, in parameter order. At the data the basis is the one the solve weighed
/// them with: the same point as evaluating there, to the bit, without computing the basis
/// again.
fn residuals(
    data: &[[f64; 3]],
    params: &[f64],
    (curve, bases): (&Curve, &[Basis]),
    tol_mm: f64,
) -> (f64, Vec<usize>) {
    let mut worst = 0.0f64;
    let mut bad_spans: Vec<usize> = Vec::new();
    let last = curve.ctrl().len() - 1;
    let mut check = |q: &[f64; 3], u: f64, basis: Option<&Basis>| {
        let at = basis.and_then(|(span, n3)| curve.point_in_span(*span, n3));
        let r = norm(sub(at.unwrap_or_else(|| curve.point(u)), q));
        worst = worst.max(r);
        if r > tol_mm {
            let s = find_span(curve.knots(), last, u);
            if bad_spans.last() != Some(&s) {
                bad_spans.push(s);
            }
        }
    };
    if let (Some(q), Some(&u)) = (data.first(), params.first()) {
        check(q, u, bases.first());
    }
    for ((q, u), basis) in data
        .windows(2)
        .zip(params.windows(2))
        .zip(bases.iter().skip(1))
    {
        let mid = [
            0.5 * (q[0][0] + q[1][0]),
            0.5 * (q[0][1] + q[1][1]),
            0.5 * (q[0][2] + q[1][2]),
        ];
        check(&mid, 0.5 * (u[0] + u[1]), None);
        check(&q[1], u[1], Some(basis));
    }
    (worst, bad_spans)
}

/// The least-squares control points for fixed knots (A9.7's normal equations `NᵀN P = NᵀR`,
/// band width 3, end points fixed), with a tiny penalty on the control polygon's second
/// differences so spans without data stay determined.
fn solve(data: &[[f64; 3]], params: &[f64], knots: &[f64]) -> Option<(Curve, Vec<Basis>)> {
    let count = knots.len().checked_sub(DEGREE + 1)?;
    if count < DEGREE + 1 {
        return None;
    }
    let n = count - 1;
    let (q0, qm) = (*data.first()?, *data.last()?);
    let unknowns = n - 1;
    let mut eq = Normal {
        band: vec![[0.0f64; DEGREE + 1]; unknowns],
        rhs: vec![[0.0f64; 3]; unknowns],
        n,
        ends: [q0, qm],
    };
    let inv = reciprocals(knots);
    let mut bases = Vec::with_capacity(data.len());
    let mut span = DEGREE;
    for (q, &u) in data.iter().zip(params) {
        span = find_span_from(knots, n, u, span);
        let b = basis_by_degree(knots, inv.get(span)?, span, u)[2];
        bases.push((span, b));
        eq.add_row(span - 3, b, *q);
    }
    // The penalty acts on the control points of C'' (P&T eq. 3.8 applied twice), each scaled
    // by its knot span squared so a row is a length, like a residual. A plain second difference
    // of the control polygon would not do: with knots crowded at the corners even a straight
    // line's control points are unevenly spaced, and where the spans are tiny that penalty
    // outweighs the data and bends the curve into a hook. C'' of a straight line parametrised
    // by its length is zero whatever the knots, so this penalty leaves straights alone.
    let w = TUNING.fit_penalty.sqrt();
    for i in 0..n - 1 {
        let span = |a: usize, b: usize| knots[b] - knots[a];
        let (s1, s2, s12) = (span(i + 1, i + 4), span(i + 2, i + 5), span(i + 2, i + 4));
        if s1 <= 1e-12 || s2 <= 1e-12 || s12 <= 1e-12 {
            continue;
        }
        let (a, b, c) = (3.0 / s1, 3.0 / s2, 2.0 / s12);
        let scale = w * s12 * s12;
        let coef = [scale * c * a, -scale * c * (a + b), scale * c * b];
        eq.add_row(i, coef, [0.0; 3]);
    }
    let x = cholesky_band_solve(&mut eq.band, &mut eq.rhs)?;
    let mut ctrl = Vec::with_capacity(n + 1);
    ctrl.push(q0);
    ctrl.extend(x);
    ctrl.push(qm);
    Some((Curve::with_reciprocals(knots.to_vec(), ctrl, inv), bases))
}

/// A datum's knot span and degree-3 basis functions, as [`solve`] weighed it.
type Basis = (usize, [f64; 4]);

/// The normal equations of [`solve`] being built: the band of `NᵀN` and `NᵀR` over the inner
/// control points (the end points, fixed, are moved to the right-hand side).
struct Normal {
    band: Vec<[f64; DEGREE + 1]>,
    rhs: Vec<[f64; 3]>,
    /// Index of the last control point.
    n: usize,
    /// The fixed first and last control points.
    ends: [[f64; 3]; 2],
}

impl Normal {
    /// Adds one least-squares row Σ c_j P_j ≈ target over the consecutive control points
    /// `first..first + N` (indices 0..=n; those outside are ignored). A fixed stride of
    /// `N`, not a list of indices: the loops unroll (a list was 7 % of `vtg`'s instructions
    /// on the first 4 MB of the 34 MB corpus file; this is 2 %), summing in the same order.
    #[allow(clippy::needless_range_loop)] // per axis, as the rows below are indexed
    fn add_row<const N: usize>(&mut self, first: usize, coef: [f64; N], target: [f64; 3]) {
        let n = self.n;
        let mut t = target;
        for (a, &c) in coef.iter().enumerate() {
            let fixed = match first + a {
                0 => self.ends[0],
                j if j == n => self.ends[1],
                _ => continue,
            };
            for k in 0..3 {
                t[k] -= c * fixed[k];
            }
        }
        for a in 0..N {
            let j = first + a;
            if j == 0 || j >= n {
                continue;
            }
            let (row, cj) = (j - 1, coef[a]);
            for k in 0..3 {
                self.rhs[row][k] += cj * t[k];
            }
            for b in a..N {
                if first + b < n && b - a <= DEGREE {
                    self.band[row][b - a] += cj * coef[b];
                }
            }
        }
    }
}

/// Solves `A x = b` for a symmetric positive definite band matrix stored by rows as
/// `a[i][k] = A[i][i+k]` (Cholesky `A = UᵀU`, then two triangular solves). `None` if `A` is
/// not positive definite.
#[allow(clippy::needless_range_loop)] // band indices, as in the textbook algorithm
pub(crate) fn cholesky_band_solve(
    a: &mut [[f64; DEGREE + 1]],
    b: &mut [[f64; 3]],
) -> Option<Vec<[f64; 3]>> {
    let n = a.len();
    if b.len() != n {
        return None;
    }
    for i in 0..n {
        for k in 0..=DEGREE {
            let j = i + k;
            if j >= n {
                break;
            }
            let mut sum = a[i][k];
            let lo = j.saturating_sub(DEGREE);
            for l in lo..i {
                sum -= a[l][i - l] * a[l][j - l];
            }
            if k == 0 {
                if sum.is_nan() || sum <= 1e-300 {
                    return None;
                }
                a[i][0] = sum.sqrt();
            } else {
                a[i][k] = sum / a[i][0];
            }
        }
    }
    // Uᵀ y = b.
    for i in 0..n {
        let lo = i.saturating_sub(DEGREE);
        for l in lo..i {
            let f = a[l][i - l];
            let bl = b[l];
            for k in 0..3 {
                b[i][k] -= f * bl[k];
            }
        }
        for k in 0..3 {
            b[i][k] /= a[i][0];
        }
    }
    // U x = y.
    for i in (0..n).rev() {
        for k in 1..=DEGREE {
            let j = i + k;
            if j >= n {
                break;
            }
            let f = a[i][k];
            let bj = b[j];
            for c in 0..3 {
                b[i][c] -= f * bj[c];
            }
        }
        for c in 0..3 {
            b[i][c] /= a[i][0];
        }
    }
    Some(b.to_vec())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    #[allow(clippy::needless_range_loop)]
    fn band_solver_matches_dense() {
        // A tridiagonal-plus SPD matrix.
        let n = 7;
        let mut a = vec![[0.0; 4]; n];
        for (i, row) in a.iter_mut().enumerate() {
            row[0] = 6.0 + i as f64;
            row[1] = 1.0;
            row[2] = 0.5;
            row[3] = 0.25;
        }
        let x_true: Vec<[f64; 3]> = (0..n).map(|i| [i as f64, 1.0, -(i as f64)]).collect();
        let mut b = vec![[0.0; 3]; n];
        for i in 0..n {
            for j in 0..n {
                let (lo, hi) = (i.min(j), i.max(j));
                let v = if hi - lo <= 3 { a[lo][hi - lo] } else { 0.0 };
                for k in 0..3 {
                    b[i][k] += v * x_true[j][k];
                }
            }
        }
        let x = cholesky_band_solve(&mut a, &mut b).unwrap();
        for (x, t) in x.iter().zip(&x_true) {
            for k in 0..3 {
                assert!((x[k] - t[k]).abs() < 1e-10);
            }
        }
    }

    fn blended(pts: &[[f64; 3]], tol: f64) -> (Vec<[f64; 3]>, Vec<f64>) {
        let b = crate::vtg::blend::plan(pts, tol, 0.0, crate::vtg::blend::Line::Racing);
        crate::vtg::blend::samples(pts, &b, 2.0)
    }

    #[test]
    fn straight_line_is_reproduced() {
        let pts = [[0.0, 0.0, 0.2], [30.0, 0.0, 0.2]];
        let (d, u) = blended(&pts, 0.1);
        let f = fit(&d, &u, 0.01).unwrap();
        assert!(f.max_residual_mm < 1e-2, "{}", f.max_residual_mm);
        for i in 0..=30 {
            let p = f.curve.eval(i as f64).p;
            assert!(p[1].abs() < 1e-6 && (p[0] - i as f64).abs() < 1e-2);
        }
    }

    #[test]
    fn corner_is_rounded_within_tolerance() {
        let pts = [[0.0, 0.0, 0.2], [10.0, 0.0, 0.2], [10.0, 10.0, 0.2]];
        let (d, u) = blended(&pts, 0.04);
        let f = fit(&d, &u, 0.01).unwrap();
        assert!(f.max_residual_mm <= 0.01);
        // The curve passes inside the corner, not through it, about where the blend does
        // (0.04 mm from the vertex), never further than blend and fit allow.
        let c = f.curve.eval(10.0).p;
        let off = norm(sub(c, [10.0, 0.0, 0.2]));
        assert!(off > 0.03 && off <= 0.05, "{off}");
    }

    /// The residual check at the data reads the point off the solve's own basis: the same
    /// bits as evaluating the curve there.
    #[test]
    fn the_point_from_the_solves_basis_is_the_evaluated_point() {
        let pts = [
            [0.0, 0.0, 0.2],
            [10.0, 0.0, 0.2],
            [10.0, 10.0, 0.2],
            [3.0, 12.0, 0.2],
        ];
        let (d, u) = blended(&pts, 0.04);
        let (start, end) = (u[0], *u.last().unwrap());
        let inner = u
            .iter()
            .copied()
            .step_by(3)
            .filter(|&k| k > start && k < end);
        let knots: Vec<f64> = [start; DEGREE + 1]
            .into_iter()
            .chain(inner)
            .chain([end; DEGREE + 1])
            .collect();
        let (curve, bases) = solve(&d, &u, &knots).unwrap();
        assert_eq!(bases.len(), d.len());
        for (&at, (span, n3)) in u.iter().zip(&bases) {
            assert_eq!(
                curve.point_in_span(*span, n3),
                Some(curve.eval(at).p),
                "{at}"
            );
        }
    }
}
