//! Small 3-vector helpers on `[f64; 3]` (portable: every transcendental call goes through
//! [`crate::math`] or `libm`, so native and wasm results are bit-identical).
//!
//! One module for every user: the tool-orientation smoother ([`crate::orient`]) passes vectors
//! by value, the toolpath rewriter ([`crate::vtg`]) by reference to the points it keeps; the
//! arithmetic helpers take either (`impl Borrow<V3>`).

use std::borrow::Borrow;

use crate::math;

/// A 3-vector (position, mm, or direction, unitless).
pub type V3 = [f64; 3];

/// `a + b`.
#[inline]
pub fn add(a: impl Borrow<V3>, b: impl Borrow<V3>) -> V3 {
    let (a, b) = (a.borrow(), b.borrow());
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

/// `a - b`.
#[inline]
pub fn sub(a: impl Borrow<V3>, b: impl Borrow<V3>) -> V3 {
    let (a, b) = (a.borrow(), b.borrow());
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

/// `k a`.
#[inline]
pub fn scale(a: impl Borrow<V3>, k: f64) -> V3 {
    let a = a.borrow();
    [a[0] * k, a[1] * k, a[2] * k]
}

/// Dot product.
#[inline]
pub fn dot(a: impl Borrow<V3>, b: impl Borrow<V3>) -> f64 {
    let (a, b) = (a.borrow(), b.borrow());
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// Cross product `a × b`.
#[inline]
pub fn cross(a: impl Borrow<V3>, b: impl Borrow<V3>) -> V3 {
    let (a, b) = (a.borrow(), b.borrow());
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

/// Euclidean norm.
#[inline]
pub fn norm(a: impl Borrow<V3>) -> f64 {
    let a = a.borrow();
    dot(a, a).sqrt()
}

/// `a / |a|`, or `None` for a zero, tiny or non-finite vector.
#[inline]
pub fn normalize(a: V3) -> Option<V3> {
    let n = norm(a);
    if n.is_finite() && n > 1e-12 {
        Some(scale(a, 1.0 / n))
    } else {
        None
    }
}

/// Angle between two vectors, radians, in `[0, π]`.
///
/// CIRP eq. 4 writes it as `arccos(a·b / |a||b|)`; `atan2(|a×b|, a·b)` is the same
/// angle but keeps full precision near 0 and π, where the cone test must be exact.
#[inline]
pub fn angle(a: impl Borrow<V3>, b: impl Borrow<V3>) -> f64 {
    let (a, b) = (a.borrow(), b.borrow());
    math::atan2(norm(cross(a, b)), dot(a, b))
}

/// The point at fraction `t` of the way from `a` to `b`.
#[inline]
pub fn lerp(a: impl Borrow<V3>, b: impl Borrow<V3>, t: f64) -> V3 {
    let (a, b) = (a.borrow(), b.borrow());
    [
        a[0] + (b[0] - a[0]) * t,
        a[1] + (b[1] - a[1]) * t,
        a[2] + (b[2] - a[2]) * t,
    ]
}

/// Whether all three components are finite.
#[inline]
pub fn is_finite(a: V3) -> bool {
    a.iter().all(|c| c.is_finite())
}

/// Rodrigues rotation of `v` about the unit axis `h` by `theta` radians (the matrix of CIRP eq. 6
/// applied to `v`).
pub fn rotate(v: V3, h: V3, theta: f64) -> V3 {
    let c = math::cos(theta);
    let s = math::sin(theta);
    let [hx, hy, hz] = h;
    let r = [
        [
            c + hx * hx * (1.0 - c),
            hx * hy * (1.0 - c) - hz * s,
            hx * hz * (1.0 - c) + hy * s,
        ],
        [
            hy * hx * (1.0 - c) + hz * s,
            c + hy * hy * (1.0 - c),
            hy * hz * (1.0 - c) - hx * s,
        ],
        [
            hz * hx * (1.0 - c) - hy * s,
            hz * hy * (1.0 - c) + hx * s,
            c + hz * hz * (1.0 - c),
        ],
    ];
    [dot(r[0], v), dot(r[1], v), dot(r[2], v)]
}

/// Any unit vector perpendicular to the unit vector `a`.
pub fn any_perpendicular(a: V3) -> V3 {
    let helper = if a[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    normalize(cross(a, helper)).unwrap_or([0.0, 0.0, 1.0])
}

/// Degrees to radians.
#[inline]
pub fn rad(deg: f64) -> f64 {
    deg * (std::f64::consts::PI / 180.0)
}

/// Radians to degrees.
#[inline]
pub fn deg(rad: f64) -> f64 {
    rad * (180.0 / std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rodrigues_quarter_turn_about_z() {
        let r = rotate(
            [1.0, 0.0, 0.0],
            [0.0, 0.0, 1.0],
            std::f64::consts::FRAC_PI_2,
        );
        assert!(norm(sub(r, [0.0, 1.0, 0.0])) < 1e-15);
    }

    #[test]
    fn angle_is_precise_near_zero() {
        let a = [1.0, 0.0, 0.0];
        let b = [1.0, 1e-10, 0.0];
        assert!((angle(a, b) - 1e-10).abs() < 1e-20);
        assert!((angle(a, [-1.0, 0.0, 0.0]) - std::f64::consts::PI).abs() < 1e-15);
    }
}
