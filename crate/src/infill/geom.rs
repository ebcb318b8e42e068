//! Small plane-geometry helpers: points, polygons (even-odd), rotation.

/// A point in the plane, mm.
pub type P2 = [f64; 2];
/// A polyline or a closed contour.
pub type Path = Vec<P2>;
/// A region: contours with the even-odd rule (outer contours and holes alike).
pub type Region = Vec<Path>;

/// Distance between two points.
#[inline]
pub fn dist(a: P2, b: P2) -> f64 {
    crate::math::hypot(a[0] - b[0], a[1] - b[1])
}

/// Rotates `p` by (cos, sin) about `c`.
#[inline]
pub fn rotate(p: P2, c: P2, cs: (f64, f64)) -> P2 {
    let (dx, dy) = (p[0] - c[0], p[1] - c[1]);
    [c[0] + cs.0 * dx - cs.1 * dy, c[1] + cs.1 * dx + cs.0 * dy]
}

/// (cos, sin) of an angle in degrees.
pub fn cos_sin_deg(deg: f64) -> (f64, f64) {
    let r = deg.to_radians();
    (crate::math::cos(r), crate::math::sin(r))
}

/// Signed area of a closed contour (positive counter-clockwise).
pub fn signed_area(c: &[P2]) -> f64 {
    let n = c.len();
    let mut a = 0.0;
    for i in 0..n {
        let (p, q) = (c[i], c[(i + 1) % n]);
        a += p[0] * q[1] - q[0] * p[1];
    }
    0.5 * a
}

/// Area of a region under the even-odd rule (holes subtract: they are nested inside an odd
/// number of contours; slicer regions from the polygon library come with holes reversed).
pub fn region_area(r: &Region) -> f64 {
    r.iter().map(|c| signed_area(c)).sum::<f64>().abs()
}

/// Whether `p` is inside the region (even-odd).
pub fn inside(r: &Region, p: P2) -> bool {
    let mut odd = false;
    for c in r {
        let n = c.len();
        for i in 0..n {
            let (a, b) = (c[i], c[(i + 1) % n]);
            if (a[1] > p[1]) != (b[1] > p[1]) {
                let x = a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]);
                if x > p[0] {
                    odd = !odd;
                }
            }
        }
    }
    odd
}

/// Distance from `p` to segment `ab`.
pub fn seg_dist(p: P2, a: P2, b: P2) -> f64 {
    dist(p, foot(p, a, b))
}

/// The point of segment `ab` nearest `p`.
fn foot(p: P2, a: P2, b: P2) -> P2 {
    let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
    let l2 = dx * dx + dy * dy;
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    [a[0] + t * dx, a[1] + t * dy]
}

/// Whether `p` is inside the region or within `tol` of its boundary. Squared distances, and
/// the first boundary segment near enough ends the search: this test runs for every link and
/// chain the search considers.
pub fn inside_tol(r: &Region, p: P2, tol: f64) -> bool {
    if inside(r, p) {
        return true;
    }
    let tol2 = tol * tol;
    r.iter().any(|c| {
        let n = c.len();
        (0..n).any(|i| seg_dist_sq(p, c[i], c[(i + 1) % n]) <= tol2)
    })
}

/// Squared distance from `p` to segment `ab`.
pub(crate) fn seg_dist_sq(p: P2, a: P2, b: P2) -> f64 {
    let f = foot(p, a, b);
    let (ex, ey) = (p[0] - f[0], p[1] - f[1]);
    ex * ex + ey * ey
}

/// Bounding box `[x0, y0, x1, y1]` of some points (None when empty or not finite).
pub fn bbox<'a>(points: impl IntoIterator<Item = &'a P2>) -> Option<[f64; 4]> {
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for p in points {
        b = [
            b[0].min(p[0]),
            b[1].min(p[1]),
            b[2].max(p[0]),
            b[3].max(p[1]),
        ];
    }
    (b.iter().all(|v| v.is_finite()) && b[2] >= b[0] && b[3] >= b[1]).then_some(b)
}

/// Length of a polyline.
pub fn path_len(p: &[P2]) -> f64 {
    p.windows(2).map(|w| dist(w[0], w[1])).sum()
}

/// Douglas–Peucker simplification of a closed contour to within `tol` (keeps at least 3
/// points). Regions rebuilt from strokes carry many near-collinear points; fewer points make
/// every later offset and clip cheaper.
pub fn simplify_closed(c: &[P2], tol: f64) -> Path {
    if c.len() <= 4 {
        return c.to_vec();
    }
    let mut keep = vec![false; c.len()];
    keep[0] = true;
    // Split at the point farthest from the first, so the closed contour is two open chains.
    let far = (1..c.len())
        .max_by(|&a, &b| dist(c[a], c[0]).total_cmp(&dist(c[b], c[0])))
        .unwrap_or(c.len() / 2);
    keep[far] = true;
    let mut stack = vec![(0usize, far), (far, c.len())];
    while let Some((a, b)) = stack.pop() {
        let pb = c[b % c.len()];
        let mut best = (0.0, 0usize);
        for (i, &p) in c.iter().enumerate().take(b).skip(a + 1) {
            let d = seg_dist(p, c[a], pb);
            if d > best.0 {
                best = (d, i);
            }
        }
        if best.0 > tol {
            keep[best.1] = true;
            stack.push((a, best.1));
            stack.push((best.1, b));
        }
    }
    let out: Path = c
        .iter()
        .zip(&keep)
        .filter(|(_, k)| **k)
        .map(|(p, _)| *p)
        .collect();
    if out.len() >= 3 {
        out
    } else {
        c.to_vec()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn square_with_hole() {
        let r: Region = vec![
            vec![[0.0, 0.0], [10.0, 0.0], [10.0, 10.0], [0.0, 10.0]],
            vec![[4.0, 4.0], [4.0, 6.0], [6.0, 6.0], [6.0, 4.0]],
        ];
        assert!((region_area(&r) - 96.0).abs() < 1e-12);
        assert!(inside(&r, [1.0, 1.0]));
        assert!(!inside(&r, [5.0, 5.0]));
        assert!(!inside(&r, [11.0, 5.0]));
        assert!(inside_tol(&r, [10.01, 5.0], 0.02));
        let dense: Path = (0..=100)
            .map(|i| [0.1 * i as f64, 0.0])
            .chain([[10.0, 10.0], [0.0, 10.0]])
            .collect();
        assert_eq!(simplify_closed(&dense, 0.01).len(), 4);
        let q = rotate([1.0, 0.0], [0.0, 0.0], cos_sin_deg(90.0));
        assert!(q[0].abs() < 1e-12 && (q[1] - 1.0).abs() < 1e-12);
    }
}
