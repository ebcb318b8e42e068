//! The paper's two test parts (section 3.1) as point-vector toolpaths: a quarter torus (CIRP eq. 1)
//! and a square-shaped tube (CIRP eq. 2).
//!
//! Each part is a tube surface `S(t, v)` around a guide curve (`t` along it, `v` the polar
//! angle around it). Layers are generated at a constant inter-layer distance measured along the
//! surface, as in the paper's CAM chain: layer `k` meets each meridian `v` where the meridian's
//! length from the base is `k·h`. Where a meridian is shorter than `k·h` the layer stops at the
//! top edge (`t = t_max`); on the torus the inner meridians (length `(R − ρ)·π/2`) run out
//! first, which creates the tangency discontinuities "starting from a certain layer" the paper
//! describes. The build direction `b` of every point is tangent to the surface and normal to the
//! path (`b = n̂ × τ`, oriented toward growing `t`), section 2.1.

use std::f64::consts::{FRAC_PI_2, PI};

use serde::{Deserialize, Serialize};

use super::points::PointVector;
use crate::math;
use crate::vec3::{self, V3};

/// Size of a generated part.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PartOptions {
    /// Distance between layers along the surface, mm.
    pub layer_height_mm: f64,
    /// Distance between points along a layer, mm (about).
    pub point_spacing_mm: f64,
    /// Square tube only: height of the tube, mm.
    pub height_mm: f64,
}

impl Default for PartOptions {
    fn default() -> Self {
        PartOptions {
            layer_height_mm: 1.0,
            point_spacing_mm: 0.5,
            height_mm: 30.0,
        }
    }
}

/// CIRP eq. 1: guide curve `(R cos t − R, 0, R sin t)`, `t ∈ [0, π/2]`, tube radius `ρ`.
pub fn torus_surface(t: f64, v: f64) -> V3 {
    const R: f64 = 50.0;
    const RHO: f64 = 15.0;
    let (st, ct) = (math::sin(t), math::cos(t));
    let (sv, cv) = (math::sin(v), math::cos(v));
    // G(t) + ρ (cos v e₁ + sin v e₂), e₁ = (cos t, 0, sin t) (away from the torus axis), e₂ = ŷ.
    [R * ct - R + RHO * cv * ct, RHO * sv, R * st + RHO * cv * st]
}

/// CIRP eq. 2: guide curve the Z axis,
/// `ρ(t, v) = 15 (1 + t²/400) / (√(1 + sin 2v) + √(1 − sin 2v))` (a square whose half-side grows
/// from 7.5 mm).
pub fn square_tube_surface(t: f64, v: f64) -> V3 {
    let s2 = math::sin(2.0 * v);
    let den = (1.0 + s2).max(0.0).sqrt() + (1.0 - s2).max(0.0).sqrt();
    let rho = 15.0 * (1.0 + t * t / 400.0) / den;
    [rho * math::cos(v), rho * math::sin(v), t]
}

/// The quarter torus of CIRP eq. 1 (R = 50 mm, ρ = 15 mm).
pub fn quarter_torus(options: &PartOptions) -> Vec<PointVector> {
    generate(&torus_surface, FRAC_PI_2, options)
}

/// The square-shaped tube of CIRP eq. 2, `options.height_mm` tall.
pub fn square_tube(options: &PartOptions) -> Vec<PointVector> {
    generate(&square_tube_surface, options.height_mm, options)
}

/// Most points a generated part may have.
const MAX_GENERATED: usize = 2_000_000;

fn generate(surface: &dyn Fn(f64, f64) -> V3, t_max: f64, o: &PartOptions) -> Vec<PointVector> {
    let ok = |x: f64| x.is_finite() && x > 0.0;
    if !(ok(o.layer_height_mm) && ok(o.point_spacing_mm) && ok(t_max)) {
        return Vec::new();
    }
    // Points per layer from the longest cross-section perimeter.
    let perimeter = |t: f64| {
        (0..720)
            .map(|i| {
                let a = surface(t, 2.0 * PI * i as f64 / 720.0);
                let b = surface(t, 2.0 * PI * (i + 1) as f64 / 720.0);
                vec3::norm(vec3::sub(b, a))
            })
            .sum::<f64>()
    };
    let per = perimeter(0.0).max(perimeter(t_max));
    let nv = ((per / o.point_spacing_mm).ceil() as usize).clamp(16, 5_000);
    // Meridian length tables s_j(t).
    const NT: usize = 400;
    let dt = t_max / NT as f64;
    let vs: Vec<f64> = (0..nv).map(|j| 2.0 * PI * j as f64 / nv as f64).collect();
    let tables: Vec<Vec<f64>> = vs
        .iter()
        .map(|&v| {
            let mut s = Vec::with_capacity(NT + 1);
            let mut acc = 0.0;
            let mut prev = surface(0.0, v);
            s.push(0.0);
            for k in 1..=NT {
                let p = surface(k as f64 * dt, v);
                acc += vec3::norm(vec3::sub(p, prev));
                prev = p;
                s.push(acc);
            }
            s
        })
        .collect();
    let longest = tables
        .iter()
        .filter_map(|t| t.last().copied())
        .fold(0.0, f64::max);
    let layers = ((longest / o.layer_height_mm).floor() as usize).min(MAX_GENERATED / nv.max(1));
    let mut out = Vec::new();
    for layer in 1..=layers {
        let target = layer as f64 * o.layer_height_mm;
        let params: Vec<(f64, f64)> = vs
            .iter()
            .zip(&tables)
            .map(|(&v, s)| (t_at(s, target, dt, t_max), v))
            .collect();
        let pts: Vec<V3> = params.iter().map(|&(t, v)| surface(t, v)).collect();
        let n = pts.len();
        // Closed ring: the last point repeats the first.
        for idx in 0..=n {
            let j = idx % n;
            let (t, v) = params.get(j).copied().unwrap_or((0.0, 0.0));
            let p = pts.get(j).copied().unwrap_or([0.0; 3]);
            let prev = pts.get((j + n - 1) % n).copied().unwrap_or(p);
            let next = pts.get((j + 1) % n).copied().unwrap_or(p);
            let tau = vec3::normalize(vec3::sub(next, prev)).unwrap_or([1.0, 0.0, 0.0]);
            let b = build_direction(surface, t, v, tau, t_max);
            out.push(PointVector {
                x: p[0],
                y: p[1],
                z: p[2],
                i: b[0],
                j: b[1],
                k: b[2],
                path: layer as u32,
            });
        }
    }
    out
}

/// `t` where a meridian's length reaches `target` (`t_max` past its end).
fn t_at(s: &[f64], target: f64, dt: f64, t_max: f64) -> f64 {
    let k = s.partition_point(|&x| x < target);
    if k == 0 {
        return 0.0;
    }
    let (Some(&a), Some(&b)) = (s.get(k - 1), s.get(k)) else {
        return t_max;
    };
    let f = if b > a { (target - a) / (b - a) } else { 0.0 };
    ((k - 1) as f64 + f) * dt
}

/// Build direction at `(t, v)` for path tangent `tau`: tangent to the surface, normal to the
/// path, toward growing `t`.
fn build_direction(surface: &dyn Fn(f64, f64) -> V3, t: f64, v: f64, tau: V3, t_max: f64) -> V3 {
    let h = 1e-5 * t_max.max(1.0);
    let (t0, t1) = ((t - h).max(0.0), (t + h).min(t_max));
    let st = vec3::sub(surface(t1, v), surface(t0, v));
    let sv = vec3::sub(surface(t, v + 1e-5), surface(t, v - 1e-5));
    let normal = vec3::normalize(vec3::cross(st, sv)).unwrap_or([1.0, 0.0, 0.0]);
    let b = vec3::normalize(vec3::cross(normal, tau))
        .unwrap_or_else(|| vec3::normalize(st).unwrap_or([0.0, 0.0, 1.0]));
    if vec3::dot(b, st) < 0.0 {
        vec3::scale(b, -1.0)
    } else {
        b
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn torus_points_lie_on_the_torus_and_b_is_normal_to_the_path() {
        let pts = quarter_torus(&PartOptions {
            layer_height_mm: 5.0,
            point_spacing_mm: 2.0,
            ..PartOptions::default()
        });
        assert!(!pts.is_empty());
        for p in &pts {
            // Distance to the guide circle (centre (−50, 0, 0), radius 50, in the XZ plane) is ρ.
            let d = math::hypot(p.x + 50.0, p.z) - 50.0;
            assert!((math::hypot(d, p.y) - 15.0).abs() < 1e-9);
            assert!((math::hypot(math::hypot(p.i, p.j), p.k) - 1.0).abs() < 1e-9);
        }
        // First layer, outer side (v = 0): 5 mm up the 65 mm-radius meridian, b along it.
        let t: f64 = 5.0 / 65.0;
        assert!((pts[0].z - 65.0 * t.sin()).abs() < 1e-3);
        assert!((pts[0].k - t.cos()).abs() < 1e-4 && (pts[0].i + t.sin()).abs() < 1e-4);
    }

    #[test]
    fn square_tube_is_square() {
        let p = square_tube_surface(0.0, 0.0);
        assert!((p[0] - 7.5).abs() < 1e-12);
        let c = square_tube_surface(0.0, PI / 4.0);
        assert!((c[0] - 7.5).abs() < 1e-9 && (c[1] - 7.5).abs() < 1e-9);
        let e = square_tube_surface(20.0, PI / 8.0);
        assert!((e[0] - 7.5 * 2.0).abs() < 1e-9);
    }
}
