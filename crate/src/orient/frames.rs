//! The local frame `(t, n, b)` of section 2.1: `t` the path tangent, `b` the build direction
//! (normal to the path, tangent to the surface for thin walls), `n = b × t` the surface normal,
//! so that `(t, n, b)` is right-handed and orthonormal.

use serde::Serialize;

use crate::vec3::{self, V3};

/// Local basis at one path point.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Frame {
    /// Unit path tangent.
    pub t: V3,
    /// Unit surface normal (`b × t`).
    pub n: V3,
    /// Unit build direction, made orthogonal to `t`.
    pub b: V3,
}

/// Unit tangents of a polyline by central differences (one-sided at the ends); a point with
/// no length on either side takes its neighbour's tangent, or `x̂` for a single point.
pub fn tangents(p: &[V3]) -> Vec<V3> {
    let n = p.len();
    let mut out: Vec<Option<V3>> = (0..n)
        .map(|i| {
            let a = p.get(i.saturating_sub(1)).copied()?;
            let c = p.get((i + 1).min(n - 1)).copied()?;
            vec3::normalize(vec3::sub(c, a))
        })
        .collect();
    // Fill gaps from the nearest defined neighbour (forward, then backward).
    let mut last = None;
    for t in out.iter_mut() {
        if t.is_none() {
            *t = last;
        }
        last = *t;
    }
    let mut next = None;
    for t in out.iter_mut().rev() {
        if t.is_none() {
            *t = next;
        }
        next = *t;
    }
    out.into_iter()
        .map(|t| t.unwrap_or([1.0, 0.0, 0.0]))
        .collect()
}

/// The frames of a path with build directions `b` (one per point).
pub fn frames(p: &[V3], b: &[V3]) -> Vec<Frame> {
    tangents(p)
        .into_iter()
        .zip(b)
        .map(|(t, &b)| {
            let b_perp = vec3::normalize(vec3::sub(b, vec3::scale(t, vec3::dot(b, t))))
                .unwrap_or_else(|| vec3::any_perpendicular(t));
            Frame {
                t,
                n: vec3::cross(b_perp, t),
                b: b_perp,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        let p = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.5, 0.0]];
        let b = [[0.1, 0.0, 1.0]; 3];
        for f in frames(&p, &b) {
            assert!((vec3::norm(f.t) - 1.0).abs() < 1e-12);
            assert!(vec3::dot(f.t, f.b).abs() < 1e-12);
            assert!(vec3::dot(f.n, f.b).abs() < 1e-12);
            assert!(vec3::norm(vec3::sub(vec3::cross(f.t, f.n), f.b)) < 1e-12);
        }
    }
}
