//! Correction of the smoothed orientation back into the tolerance cone (CIRP eq. 4–7).
//!
//! For each point `m` the angle `α_m` between the smoothed vector `T_S,m` and the build
//! direction `b_m` is CIRP eq. 4. When `α_m > γ/2` the tool vector becomes `b_m` rotated by `γ/2`
//! (Rodrigues, CIRP eq. 6) about the auxiliary axis `h_m` (CIRP eq. 5), so it lands on the
//! cone's edge in the plane of `b_m` and `T_S,m` (CIRP eq. 7).
//!
//! Two details the paper leaves implicit: `h_m` must be a unit vector, and the sign. Rotating
//! `b` by `+γ/2` about `T_S × b` (CIRP eq. 5 literally) turns it *away* from `T_S`, onto the
//! opposite side of the cone; the intended vector is the cone edge nearest `T_S`, which is the
//! rotation by `+γ/2` about `b × T_S` (the same axis as CIRP eq. 5 with the opposite sign). When
//! `T_S` is exactly opposite `b` any perpendicular axis is used.

use crate::vec3::{self, V3};

/// Result of correcting one vector.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corrected {
    /// The tool vector (unit).
    pub vector: V3,
    /// Whether CIRP eq. 7's second branch was taken.
    pub corrected: bool,
}

/// CIRP eq. 4–7: keeps the unit vector `smoothed` if it lies within `half_angle` (radians) of the
/// unit build direction `b`, else puts it on the cone's edge toward `smoothed`. The returned
/// vector is never more than `half_angle` from `b`, as measured by [`vec3::angle`] (a last
/// guard pulls it in by a few ulps if rounding would put it a hair outside).
pub fn correct(b: V3, smoothed: V3, half_angle: f64) -> Corrected {
    let alpha = vec3::angle(smoothed, b); // CIRP eq. 4
    if alpha <= half_angle {
        return Corrected {
            vector: smoothed,
            corrected: false,
        };
    }
    // CIRP eq. 5 (sign and normalisation: see the module documentation).
    let h = vec3::normalize(vec3::cross(b, smoothed)).unwrap_or_else(|| vec3::any_perpendicular(b));
    // Aim a hair (1e-12 rad) inside the edge so that a caller re-normalising the vector, or
    // measuring the angle another way, still finds it inside.
    let half_angle = (half_angle - 1e-12 * half_angle.max(1.0)).max(0.0);
    let mut theta = half_angle;
    let mut t = b;
    for _ in 0..64 {
        // CIRP eq. 6 and 7.
        t = vec3::normalize(vec3::rotate(b, h, theta)).unwrap_or(b);
        if vec3::angle(t, b) <= half_angle {
            break;
        }
        theta -= half_angle * 1e-12 + 1e-15;
        if theta <= 0.0 {
            t = b;
            break;
        }
    }
    Corrected {
        vector: t,
        corrected: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inside_is_kept_outside_goes_to_the_nearest_edge() {
        let b = [0.0, 0.0, 1.0];
        let half = vec3::rad(30.0);
        let inside = [vec3::rad(20.0).sin(), 0.0, vec3::rad(20.0).cos()];
        let r = correct(b, inside, half);
        assert!(!r.corrected && r.vector == inside);
        let outside = [vec3::rad(50.0).sin(), 0.0, vec3::rad(50.0).cos()];
        let r = correct(b, outside, half);
        assert!(r.corrected);
        // On the edge, in the plane of b and T_S, on T_S's side.
        assert!((vec3::angle(r.vector, b) - half).abs() < 1e-11);
        assert!(r.vector[1].abs() < 1e-15 && r.vector[0] > 0.0);
        assert!(vec3::angle(r.vector, b) <= half);
    }

    #[test]
    fn opposite_vector_still_lands_on_the_cone() {
        let b = [0.0, 0.0, 1.0];
        let half = vec3::rad(45.0);
        let r = correct(b, [0.0, 0.0, -1.0], half);
        assert!(r.corrected && vec3::angle(r.vector, b) <= half);
    }
}
