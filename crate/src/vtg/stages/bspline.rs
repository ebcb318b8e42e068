//! Cubic NURBS curves in 3-D (VTG eq. 21–22).
//!
//! Most fits keep every weight 1, and VTG eq. 21 reduces to a B-spline; [`Curve::rational`] takes
//! weights where the fit finds they help ([`crate::vtg::fit`]). Basis functions follow Piegl &
//! Tiller's A2.2 (the Cox–de Boor recursion of VTG eq. 22), derivatives the derivative curves'
//! control points (P&T eq. 3.8); a rational curve is evaluated in homogeneous coordinates and
//! projected with the quotient rule (P&T eq. 4.8). The tests check both against A2.3.

use crate::vec3::{cross, norm, sub};

/// Degree of the curves.
pub(crate) const DEGREE: usize = 3;

/// A clamped cubic B-spline: `knots.len() == ctrl.len() + 4`, first and last knots repeated
/// four times. The control points of its first and second derivative curves are kept beside
/// it (P&T eq. 3.8), so a point and both derivatives cost one pass of the basis recursion.
#[derive(Debug, Clone)]
pub(crate) struct Curve {
    knots: Vec<f64>,
    /// Each span's [`span_reciprocals`].
    inv: Vec<[f64; 6]>,
    /// The control points (of a rational curve: the weighted points `w_i P_i`).
    ctrl: Net<3>,
    /// A rational curve's weights `w_i`, as a net of their own (`None`: all 1).
    weights: Option<Net<1>>,
    /// The span of the last evaluation: the walk evaluates near it again and again, so the
    /// span search starts there (a curve is used by one thread).
    last_span: std::cell::Cell<usize>,
}

/// Control points with `D` coordinates and those of the first and second derivative curves.
#[derive(Debug, Clone, PartialEq)]
struct Net<const D: usize> {
    /// `P_i`.
    p: Vec<[f64; D]>,
    /// `Q_i = 3 (P_{i+1} − P_i) / (u_{i+4} − u_{i+1})`, for `C' = Σ N_{i+1,2} Q_i`.
    q: Vec<[f64; D]>,
    /// `R_i = 2 (Q_{i+1} − Q_i) / (u_{i+4} − u_{i+2})`, for `C'' = Σ N_{i+2,1} R_i`.
    r: Vec<[f64; D]>,
}

impl<const D: usize> Net<D> {
    fn new(knots: &[f64], p: Vec<[f64; D]>) -> Self {
        let q = diff(knots, &p, 1, 4, 3.0);
        let r = diff(knots, &q, 2, 4, 2.0);
        Self { p, q, r }
    }

    /// The point and both derivatives in `span` from the basis functions of degrees 1–3.
    #[inline]
    fn at(&self, span: usize, [n1, n2, n3]: &[[f64; 4]; 3]) -> Option<[[f64; D]; 3]> {
        Some([
            self.point(span, n3)?,
            weigh(&n2[..3], self.q.get(span - DEGREE..span)?),
            weigh(&n1[..2], self.r.get(span - DEGREE..span - 1)?),
        ])
    }

    /// The point in `span` from the degree-3 basis functions.
    #[inline]
    fn point(&self, span: usize, n3: &[f64; 4]) -> Option<[f64; D]> {
        Some(weigh(n3, self.p.get(span.checked_sub(DEGREE)?..=span)?))
    }
}

/// `Σ w_i · pts_i`, summed in order from zero.
#[inline]
fn weigh<const D: usize>(w: &[f64], pts: &[[f64; D]]) -> [f64; D] {
    let mut out = [0.0; D];
    for (wi, pt) in w.iter().zip(pts) {
        for k in 0..D {
            out[k] += wi * pt[k];
        }
    }
    out
}

/// A point of the curve with its first and second derivatives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Eval {
    /// `C(u)`.
    pub(crate) p: [f64; 3],
    /// `C'(u)`.
    pub(crate) d1: [f64; 3],
    /// `C''(u)`.
    pub(crate) d2: [f64; 3],
}

impl Eval {
    /// The cubic `τ` past this point, its third derivative `jerk` (one knot span of the
    /// curve, [`Curve::third_derivative`]): its Taylor polynomial, which is the cubic itself.
    pub(crate) fn ahead(&self, jerk: &[f64; 3], tau: f64) -> Eval {
        let (t2, t3) = (tau * tau / 2.0, tau * tau * tau / 6.0);
        Eval {
            p: std::array::from_fn(|k| {
                self.p[k] + self.d1[k] * tau + self.d2[k] * t2 + jerk[k] * t3
            }),
            d1: std::array::from_fn(|k| self.d1[k] + self.d2[k] * tau + jerk[k] * t2),
            d2: std::array::from_fn(|k| self.d2[k] + jerk[k] * tau),
        }
    }

    /// Curvature `|C' × C''| / |C'|³`.
    pub(crate) fn curvature(&self) -> f64 {
        let c = cross(self.d1, self.d2);
        let s = norm(self.d1);
        if s < 1e-12 {
            return 0.0;
        }
        norm(c) / (s * s * s)
    }
}

impl PartialEq for Curve {
    fn eq(&self, other: &Self) -> bool {
        self.knots == other.knots && self.ctrl.p == other.ctrl.p && self.weights == other.weights
    }
}

/// Control points of the derivative of a cubic's `lo`/`hi` knot offsets and `degree` (P&T eq.
/// 3.8; a zero-length knot interval gives a zero difference, P&T's 0/0 = 0), for points with
/// `D` coordinates.
fn diff<const D: usize>(
    knots: &[f64],
    pts: &[[f64; D]],
    lo: usize,
    hi: usize,
    degree: f64,
) -> Vec<[f64; D]> {
    pts.windows(2)
        .enumerate()
        .map(|(i, w)| {
            let den = knots
                .get(i + hi)
                .zip(knots.get(i + lo))
                .map_or(0.0, |(b, a)| b - a);
            let f = if den > 0.0 { degree / den } else { 0.0 };
            std::array::from_fn(|k| (w[1][k] - w[0][k]) * f)
        })
        .collect()
}

impl Curve {
    /// The curve with these knots and control points (derivative control points computed here;
    /// a zero-length knot interval gives a zero difference, P&T's 0/0 = 0).
    #[cfg(test)]
    pub(crate) fn new(knots: Vec<f64>, ctrl: Vec<[f64; 3]>) -> Self {
        let inv = reciprocals(&knots);
        Self::with_reciprocals(knots, ctrl, inv)
    }

    /// [`Curve::new`] with the knots' [`reciprocals`] already worked out (the fit's).
    pub(crate) fn with_reciprocals(
        knots: Vec<f64>,
        ctrl: Vec<[f64; 3]>,
        inv: Vec<[f64; 6]>,
    ) -> Self {
        Self {
            ctrl: Net::new(&knots, ctrl),
            inv,
            knots,
            weights: None,
            last_span: std::cell::Cell::new(DEGREE),
        }
    }

    /// The rational curve (VTG eq. 21) with these knots, control points and positive weights (one
    /// per control point; all 1 gives [`Curve::new`]'s curve).
    #[cfg(test)]
    pub(crate) fn rational(knots: Vec<f64>, ctrl: Vec<[f64; 3]>, weights: Vec<f64>) -> Self {
        if weights.len() != ctrl.len() || weights.iter().all(|&w| w == 1.0) {
            return Self::new(knots, ctrl);
        }
        let weighted: Vec<[f64; 3]> = ctrl
            .iter()
            .zip(&weights)
            .map(|(p, &w)| [p[0] * w, p[1] * w, p[2] * w])
            .collect();
        let w = Net::new(&knots, weights.iter().map(|&w| [w]).collect());
        Self {
            weights: Some(w),
            ..Self::new(knots, weighted)
        }
    }

    /// Whether the curve has weights other than 1.
    #[cfg(test)]
    pub(crate) fn is_rational(&self) -> bool {
        self.weights.is_some()
    }

    /// The knot span holding `u`, from the last one if it (or the next) still does.
    #[inline]
    fn span(&self, u: f64) -> usize {
        let n = self.ctrl.p.len() - 1;
        let k = &self.knots;
        let last = self.last_span.get();
        let holds = |s: usize| s <= n && k[s] <= u && (u < k[s + 1] || s == n);
        let span = if holds(last) {
            last
        } else if holds(last + 1) {
            last + 1
        } else {
            find_span(k, n, u)
        };
        self.last_span.set(span);
        span
    }

    /// The point in knot span `span` whose degree-3 basis functions are `n3` (as
    /// [`basis_by_degree`] gives them): [`Curve::eval`]'s point, to the bit, for a caller that
    /// already has the basis (the fit, at its data). Non-rational curves only.
    pub(crate) fn point_in_span(&self, span: usize, n3: &[f64; 4]) -> Option<[f64; 3]> {
        if self.weights.is_some() || !self.knots_fit() {
            return None;
        }
        self.ctrl.point(span, n3)
    }

    /// Whether there are as many knots as the control points of a cubic need (`n + 5` for
    /// `n + 1` points).
    fn knots_fit(&self) -> bool {
        self.knots.len() == self.ctrl.p.len() + DEGREE + 1
    }

    /// Knot vector.
    pub(crate) fn knots(&self) -> &[f64] {
        &self.knots
    }

    /// Control points (of a rational curve: weighted, `w_i P_i`).
    pub(crate) fn ctrl(&self) -> &[[f64; 3]] {
        &self.ctrl.p
    }

    /// First parameter.
    pub(crate) fn start(&self) -> f64 {
        self.knots.first().copied().unwrap_or(0.0)
    }

    /// Last parameter.
    pub(crate) fn end(&self) -> f64 {
        self.knots.last().copied().unwrap_or(0.0)
    }

    /// [`Curve::eval`]'s point alone, to the bit: without the derivatives' sums (the fit's
    /// residuals between its data, nearly a million evaluations on the first 4 MB of the
    /// 34 MB corpus file).
    pub(crate) fn point(&self, u: f64) -> [f64; 3] {
        if self.weights.is_some() {
            return self.eval(u).p;
        }
        // Where evaluation finds nothing, its point is zero.
        self.basis_at(u)
            .and_then(|(span, basis)| self.ctrl.point(span, &basis[2]))
            .unwrap_or([0.0; 3])
    }

    /// The span of `u` (clamped to the curve's range) and its basis functions of degrees 1–3,
    /// what [`Curve::eval`] and [`Curve::point`] weigh; `None` where the knots do not fit the
    /// control points.
    fn basis_at(&self, u: f64) -> Option<(usize, [[f64; 4]; 3])> {
        let n = self.ctrl.p.len();
        if n < DEGREE + 1 || !self.knots_fit() {
            return None;
        }
        let u = u.clamp(self.start(), self.end());
        let span = self.span(u);
        let inv = self.inv.get(span)?;
        Some((span, basis_by_degree(&self.knots, inv, span, u)))
    }

    /// The third derivative of the cubic in the knot span that starts at `u0` (a break of the
    /// knot vector), constant across it: the span's `C''` runs linearly from `R_{s−3}` to
    /// `R_{s−2}`. `None` on a rational curve or outside the knots.
    pub(crate) fn third_derivative(&self, u0: f64) -> Option<[f64; 3]> {
        if self.weights.is_some() || !self.knots_fit() {
            return None;
        }
        let s = self.span(u0.clamp(self.start(), self.end()));
        let h = self.knots.get(s + 1)? - self.knots.get(s)?;
        let (r0, r1) = (self.ctrl.r.get(s.checked_sub(3)?)?, self.ctrl.r.get(s - 2)?);
        (h > 0.0).then(|| std::array::from_fn(|k| (r1[k] - r0[k]) / h))
    }

    /// Point and derivatives at `u` (clamped to the curve's range): one pass of A2.2 gives
    /// the basis functions of degrees 1, 2 and 3, which weigh `R`, `Q` and `P`.
    pub(crate) fn eval(&self, u: f64) -> Eval {
        let zero = Eval {
            p: [0.0; 3],
            d1: [0.0; 3],
            d2: [0.0; 3],
        };
        let Some((span, basis)) = self.basis_at(u) else {
            return zero;
        };
        let Some([a, a1, a2]) = self.ctrl.at(span, &basis) else {
            return zero;
        };
        let Some(weights) = &self.weights else {
            return Eval {
                p: a,
                d1: a1,
                d2: a2,
            };
        };
        // P&T eq. 4.8: C = A/W, C' = (A' − W'C)/W, C'' = (A'' − 2W'C' − W''C)/W.
        let Some([[w], [w1], [w2]]) = weights.at(span, &basis) else {
            return zero;
        };
        if w.abs() < 1e-300 {
            return zero;
        }
        let c: [f64; 3] = std::array::from_fn(|k| a[k] / w);
        let c1: [f64; 3] = std::array::from_fn(|k| (a1[k] - w1 * c[k]) / w);
        let c2: [f64; 3] = std::array::from_fn(|k| (a2[k] - 2.0 * w1 * c1[k] - w2 * c[k]) / w);
        Eval {
            p: c,
            d1: c1,
            d2: c2,
        }
    }
}

/// The reciprocals of the knot differences A2.2 divides by in span `span`, in the order it
/// uses them (`u_{span+1+r} − u_{span+1−j+r}` for degree `j` = 1..=3, `r` < `j`; 0 for an empty
/// interval, P&T's 0/0 = 0). They depend on the knots alone, so a curve keeps them per span
/// and an evaluation multiplies where A2.2 would divide six times (on the 34 MB corpus file the
/// recursion was an eighth of `vtg`'s time, most of it in the divisions).
fn span_reciprocals(knots: &[f64], span: usize) -> [f64; 6] {
    let mut out = [0.0; 6];
    if span < DEGREE || span + DEGREE >= knots.len() {
        return out;
    }
    let mut k = 0;
    for j in 1..=DEGREE {
        for r in 0..j {
            let den = knots[span + 1 + r] - knots[span + 1 + r - j];
            out[k] = if den != 0.0 { 1.0 / den } else { 0.0 };
            k += 1;
        }
    }
    out
}

/// [`span_reciprocals`] of every span of `knots` (indexed by span; the spans outside the
/// curve's range are zeros).
pub(crate) fn reciprocals(knots: &[f64]) -> Vec<[f64; 6]> {
    (0..knots.len())
        .map(|span| span_reciprocals(knots, span))
        .collect()
}

/// The non-zero basis functions of degrees 1, 2 and 3 at `u` in span `span` (A2.2, keeping
/// its intermediate rows): `[N_{span−1..=span,1}, N_{span−2..=span,2}, N_{span−3..=span,3}]`,
/// each padded to four entries; `inv` is the span's [`span_reciprocals`].
#[inline]
pub(crate) fn basis_by_degree(knots: &[f64], inv: &[f64; 6], span: usize, u: f64) -> [[f64; 4]; 3] {
    let mut out = [[0.0; 4]; 3];
    if span < DEGREE || span + DEGREE >= knots.len() {
        return out;
    }
    let mut n = [1.0, 0.0, 0.0, 0.0];
    let mut left = [0.0f64; 4];
    let mut right = [0.0f64; 4];
    let mut k = 0;
    for j in 1..=DEGREE {
        left[j] = u - knots[span + 1 - j];
        right[j] = knots[span + j] - u;
        let mut saved = 0.0;
        for r in 0..j {
            let temp = n[r] * inv[k];
            k += 1;
            n[r] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        n[j] = saved;
        out[j - 1] = n;
    }
    out
}

/// [`find_span`] for parameters met in increasing order: from the span `hint` found for the
/// one before, a few knots forward before searching them all (the fit's data lie a span or
/// two apart). The same span either way.
pub(crate) fn find_span_from(knots: &[f64], n: usize, u: f64, hint: usize) -> usize {
    if hint >= DEGREE && hint <= n && knots.get(hint).is_some_and(|&k| k <= u) {
        let mut s = hint;
        for _ in 0..8 {
            match knots.get(s + 1) {
                Some(&next) if s < n && u >= next => s += 1,
                Some(_) => return s,
                None => break,
            }
        }
    }
    find_span(knots, n, u)
}

/// Index of the knot span holding `u` (A2.1), for `n + 1` control points.
pub(crate) fn find_span(knots: &[f64], n: usize, u: f64) -> usize {
    let (Some(&hi), true) = (knots.get(n + 1), knots.len() > n + 1) else {
        return DEGREE;
    };
    if u >= hi {
        return n;
    }
    let (mut low, mut high) = (DEGREE, n + 1);
    let mut mid = (low + high) / 2;
    while mid > low && (u < knots[mid] || u >= knots[mid + 1]) {
        if u < knots[mid] {
            high = mid;
        } else {
            low = mid;
        }
        mid = (low + high) / 2;
    }
    mid.max(DEGREE)
}

/// Arc length of the polyline `pts` at each of its points (from 0).
pub(crate) fn arc_lengths(pts: &[[f64; 3]]) -> Vec<f64> {
    let mut arc = Vec::with_capacity(pts.len());
    let mut s = 0.0;
    arc.push(s);
    for w in pts.windows(2) {
        s += norm(sub(w[1], w[0]));
        arc.push(s);
    }
    arc
}

/// The segment of a polyline of `segments` segments (arc lengths `arc` at its points) that arc
/// length `u` falls in (the first or the last beyond the ends).
pub(crate) fn segment_at(arc: &[f64], u: f64, segments: usize) -> usize {
    arc.partition_point(|&a| a <= u).clamp(1, segments.max(1)) - 1
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference [`Curve::eval`] is checked against: the four non-zero cubic basis
    /// functions at `u` in span `span` and their first and second derivatives (A2.3, computed
    /// independently of the derivative control points): `ders[k][j]` is the k-th derivative of
    /// `N_{span−3+j,3}`.
    #[allow(clippy::needless_range_loop)] // A2.3 as Piegl & Tiller write it
    fn basis_ders(knots: &[f64], span: usize, u: f64) -> [[f64; 4]; 3] {
        const P: usize = DEGREE;
        let mut ders = [[0.0; 4]; 3];
        if span < P || span + P >= knots.len() {
            return ders;
        }
        let mut ndu = [[0.0f64; 4]; 4];
        let mut left = [0.0f64; 4];
        let mut right = [0.0f64; 4];
        ndu[0][0] = 1.0;
        for j in 1..=P {
            left[j] = u - knots[span + 1 - j];
            right[j] = knots[span + j] - u;
            let mut saved = 0.0;
            for r in 0..j {
                ndu[j][r] = right[r + 1] + left[j - r];
                let temp = if ndu[j][r] != 0.0 {
                    ndu[r][j - 1] / ndu[j][r]
                } else {
                    0.0
                };
                ndu[r][j] = saved + right[r + 1] * temp;
                saved = left[j - r] * temp;
            }
            ndu[j][j] = saved;
        }
        for j in 0..=P {
            ders[0][j] = ndu[j][P];
        }
        let mut a = [[0.0f64; 4]; 2];
        for r in 0..=P {
            let (mut s1, mut s2) = (0usize, 1usize);
            a[0][0] = 1.0;
            for k in 1..=2usize {
                let mut d = 0.0;
                let rk = r as isize - k as isize;
                let pk = P - k;
                if r >= k {
                    let den = ndu[pk + 1][rk as usize];
                    a[s2][0] = if den != 0.0 { a[s1][0] / den } else { 0.0 };
                    d = a[s2][0] * ndu[rk as usize][pk];
                }
                let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
                let j2 = if r as isize - 1 <= pk as isize {
                    k - 1
                } else {
                    P - r
                };
                for j in j1..=j2 {
                    let idx = (rk + j as isize) as usize;
                    let den = ndu[pk + 1][idx];
                    a[s2][j] = if den != 0.0 {
                        (a[s1][j] - a[s1][j - 1]) / den
                    } else {
                        0.0
                    };
                    d += a[s2][j] * ndu[idx][pk];
                }
                if r <= pk {
                    let den = ndu[pk + 1][r];
                    a[s2][k] = if den != 0.0 { -a[s1][k - 1] / den } else { 0.0 };
                    d += a[s2][k] * ndu[r][pk];
                }
                ders[k][r] = d;
                std::mem::swap(&mut s1, &mut s2);
            }
        }
        // Multiply by p!/(p−k)!.
        for j in 0..=P {
            ders[1][j] *= P as f64;
            ders[2][j] *= (P * (P - 1)) as f64;
        }
        ders
    }

    /// A single Bézier span: C(u) = Σ B_i(u) P_i with Bernstein polynomials.
    #[test]
    fn bezier_span_matches_bernstein() {
        let c = Curve::new(
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 2.0, 0.0],
                [3.0, 2.0, 0.0],
                [4.0, 0.0, 1.0],
            ],
        );
        for &u in &[0.0, 0.25, 0.5, 0.9, 1.0] {
            let e = c.eval(u);
            let b = [
                (1.0 - u).powi(3),
                3.0 * u * (1.0 - u).powi(2),
                3.0 * u * u * (1.0 - u),
                u.powi(3),
            ];
            let db = [
                -3.0 * (1.0 - u).powi(2),
                3.0 * (1.0 - u).powi(2) - 6.0 * u * (1.0 - u),
                6.0 * u * (1.0 - u) - 3.0 * u * u,
                3.0 * u * u,
            ];
            let ddb = [
                6.0 * (1.0 - u),
                -12.0 * (1.0 - u) + 6.0 * u,
                6.0 * (1.0 - u) - 12.0 * u,
                6.0 * u,
            ];
            for k in 0..3 {
                let p: f64 = (0..4).map(|i| b[i] * c.ctrl()[i][k]).sum();
                let d: f64 = (0..4).map(|i| db[i] * c.ctrl()[i][k]).sum();
                let dd: f64 = (0..4).map(|i| ddb[i] * c.ctrl()[i][k]).sum();
                assert!((e.p[k] - p).abs() < 1e-12);
                assert!((e.d1[k] - d).abs() < 1e-12);
                assert!((e.d2[k] - dd).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn partition_of_unity_with_interior_knots() {
        let knots = [0.0, 0.0, 0.0, 0.0, 0.3, 0.35, 0.9, 2.0, 2.0, 2.0, 2.0];
        for i in 0..=40 {
            let u = i as f64 * 0.05;
            let span = find_span(&knots, 6, u);
            assert!(knots[span] <= u && (u < knots[span + 1] || span == 6));
            let d = basis_ders(&knots, span, u);
            assert!((d[0].iter().sum::<f64>() - 1.0).abs() < 1e-12);
            assert!(d[1].iter().sum::<f64>().abs() < 1e-9);
            assert!(d[2].iter().sum::<f64>().abs() < 1e-8);
        }
    }

    /// The knots (an interior double knot at 0.35) and control points of a wavy test curve.
    fn wavy() -> (Vec<f64>, Vec<[f64; 3]>) {
        let knots = vec![
            0.0, 0.0, 0.0, 0.0, 0.3, 0.35, 0.35, 0.9, 1.4, 2.0, 2.0, 2.0, 2.0,
        ];
        let ctrl = (0..9)
            .map(|i| {
                let t = i as f64;
                [t, (1.3 * t).sin() * 2.0, 0.1 * t * t]
            })
            .collect();
        (knots, ctrl)
    }

    /// The derivative control points agree with A2.3's basis derivatives everywhere, interior
    /// double knot and ends included.
    #[test]
    #[allow(clippy::needless_range_loop)] // three coordinates, indexed in step
    fn evaluation_matches_the_general_derivative_recursion() {
        let (knots, ctrl) = wavy();
        let c = Curve::new(knots.clone(), ctrl.clone());
        for i in 0..=200 {
            let u = i as f64 * 0.01;
            let span = find_span(&knots, ctrl.len() - 1, u);
            let d = basis_ders(&knots, span, u);
            let e = c.eval(u);
            for k in 0..3 {
                let sum = |row: &[f64; 4]| -> f64 {
                    (0..4).map(|j| row[j] * ctrl[span - 3 + j][k]).sum()
                };
                let scale = 1.0 + sum(&d[2]).abs();
                assert!((e.p[k] - sum(&d[0])).abs() < 1e-12, "u {u}");
                assert!((e.d1[k] - sum(&d[1])).abs() < 1e-10 * scale, "u {u}");
                assert!((e.d2[k] - sum(&d[2])).abs() < 1e-9 * scale, "u {u}");
            }
        }
    }

    #[test]
    fn the_span_found_forward_is_the_span_searched() {
        let knots = [
            0.0, 0.0, 0.0, 0.0, 0.3, 0.35, 0.35, 0.9, 1.4, 2.0, 2.0, 2.0, 2.0,
        ];
        let n = knots.len() - DEGREE - 2;
        // Increasing, with repeats, a jump over several spans, the end and past it; then
        // from a hint past `u` and from nonsense hints.
        let us = [0.0, 0.0, 0.1, 0.3, 0.3, 0.34, 0.35, 0.36, 1.9, 2.0, 2.5];
        let mut hint = DEGREE;
        for &u in &us {
            hint = find_span_from(&knots, n, u, hint);
            assert_eq!(hint, find_span(&knots, n, u), "u {u}");
        }
        for hint in [0, 5, 7, n, n + 3] {
            assert_eq!(
                find_span_from(&knots, n, 0.2, hint),
                find_span(&knots, n, 0.2)
            );
        }
        assert_eq!(
            find_span_from(&knots, n, f64::NAN, 4),
            find_span(&knots, n, f64::NAN)
        );
    }

    #[test]
    fn inside_a_span_the_curve_is_the_taylor_cubic_of_its_start() {
        // Knots with a double knot (0.35), where C'' jumps: each span's own jerk is used.
        let (knots, ctrl) = wavy();
        let c = Curve::new(knots, ctrl);
        for w in [0.0, 0.3, 0.35, 0.9, 1.4, 2.0].windows(2) {
            let (u0, u1) = (w[0], w[1]);
            let (start, jerk) = (c.eval(u0), c.third_derivative(u0).expect("inside"));
            for i in 0..=20 {
                let tau = (u1 - u0) * i as f64 / 20.0;
                let (e, t) = (c.eval(u0 + tau), start.ahead(&jerk, tau));
                assert_eq!(c.point(u0 + tau), e.p);
                for k in 0..3 {
                    assert!((e.p[k] - t.p[k]).abs() < 1e-12, "u {}", u0 + tau);
                    assert!((e.d1[k] - t.d1[k]).abs() < 1e-10, "u {}", u0 + tau);
                    // At the span's end C'' may jump (the double knot): inside it may not.
                    if i < 20 {
                        assert!((e.d2[k] - t.d2[k]).abs() < 1e-9, "u {}", u0 + tau);
                    }
                }
            }
        }
    }

    /// The quarter circle of radius 2 as a rational cubic (the rational quadratic arc with
    /// middle weight cos 45°, raised to degree 3): every point on the circle, and
    /// the curvature from the quotient-rule derivatives exactly 1/2.
    #[test]
    fn rational_quarter_circle_is_exact() {
        let h = std::f64::consts::SQRT_2;
        let m = h / (1.0 + h);
        let r = 2.0;
        let ctrl = vec![
            [r, 0.0, 0.0],
            [r, r * m, 0.0],
            [r * m, r, 0.0],
            [0.0, r, 0.0],
        ];
        let w = (1.0 + h) / 3.0;
        let c = Curve::rational(
            vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
            ctrl,
            vec![1.0, w, w, 1.0],
        );
        assert!(c.is_rational());
        for i in 0..=100 {
            let u = i as f64 / 100.0;
            let e = c.eval(u);
            assert!((norm(e.p) - r).abs() < 1e-12, "{u}: {:?}", e.p);
            assert!(
                (e.curvature() - 1.0 / r).abs() < 1e-9,
                "{u}: {}",
                e.curvature()
            );
            // The derivative against a central difference.
            if i > 0 && i < 100 {
                let (a, b) = (c.eval(u - 1e-6).p, c.eval(u + 1e-6).p);
                for k in 0..2 {
                    assert!(((b[k] - a[k]) / 2e-6 - e.d1[k]).abs() < 1e-5);
                }
            }
        }
        // Unit weights are the plain B-spline.
        let ctrl = vec![
            [0.0, 0.0, 0.0],
            [1.0, 2.0, 0.0],
            [3.0, 2.0, 0.0],
            [4.0, 0.0, 0.0],
        ];
        let knots = vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
        let plain = Curve::new(knots.clone(), ctrl.clone());
        assert_eq!(Curve::rational(knots, ctrl, vec![1.0; 4]), plain);
    }
}
