//! Kinematic models: machine axes (X, Y, Z and two rotary axes) ⇄ tool-tip position and tool
//! vector in the workpiece frame.
//!
//! # Table-tilting B then rotary C (`table-bc`)
//!
//! The convention of the corpus file `multiaxis-xyzbc_zhang-ral2021_model1.gcode`, read from the
//! generator that wrote it (Zhang et al., RA-L 2021, `MultiAxis_3DP_MotionPlanning`,
//! `GcodeGeneration::getXYZ` and `verifyPosNor`): the nozzle is fixed and points down (−Z);
//! the workpiece sits on a C turntable carried by a B tilting cradle. A workpiece point `p`
//! reaches the machine position
//!
//! `M = R_y(B) · R_z(C) · p`
//!
//! with `R_y(B) = [[cos B, 0, sin B], [0, 1, 0], [−sin B, 0, cos B]]` and
//! `R_z(C) = [[cos C, −sin C, 0], [sin C, cos C, 0], [0, 0, 1]]`, both axes through the origin.
//! The tool vector (from the tip up the nozzle) in the workpiece frame is therefore
//! `n = R_z(−C) · R_y(−B) · ẑ = (−cos C sin B, sin C sin B, cos B)`; its inverse has two
//! solutions, `B = −acos(n_z), C = −atan2(n_y, n_x)` and `B' = −B, C' = C + 180°`.
//!
//! Real cradles rarely have both axes through the machine origin, so the points the axes pass
//! through are settings ([`Kinematics::b_axis_point_mm`], [`Kinematics::c_axis_point_mm`]):
//! `M = R_y(B) · (R_z(C) · (p − c) + c − b) + b`. Zero offsets give Zhang's machine.
//!
//! # Head-tilting A then B (`head-ab`)
//!
//! The workpiece frame is the machine frame; the head turns about X (A, the outer axis) and,
//! inside it, about Y (B): `n = R_x(A) · R_y(B) · ẑ = (sin B, −sin A cos B, cos A cos B)`. The
//! programmed XYZ is the pivot point, a distance [`Kinematics::pivot_length_mm`] up the tool from
//! the tip (`M = p + L n`; 0 for a controller with RTCP / TCPM active).

use serde::{Deserialize, Serialize};

use crate::math;
use crate::vec3::{self, V3};

/// Which machine layout the rotary axes have.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(rename_all = "kebab-case")]
pub enum KinematicModel {
    /// Table tilting about Y (B) carrying a turntable about Z (C).
    #[default]
    TableBc,
    /// Head tilting about X (A, outer) and Y (B, inner).
    HeadAb,
}

impl KinematicModel {
    /// Machine-axis indexes (see [`crate::machine::axis`]) of the two rotary axes: the tilt
    /// axis first, then the second one.
    pub fn rotary_axes(self) -> [usize; 2] {
        use crate::machine::axis;
        match self {
            KinematicModel::TableBc => [axis::B, axis::C],
            KinematicModel::HeadAb => [axis::A, axis::B],
        }
    }

    /// Letters of the two rotary axes.
    pub fn rotary_letters(self) -> [char; 2] {
        match self {
            KinematicModel::TableBc => ['B', 'C'],
            KinematicModel::HeadAb => ['A', 'B'],
        }
    }
}

/// A kinematic model with its geometry.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(default, deny_unknown_fields)]
pub struct Kinematics {
    /// Machine layout (default `table-bc`).
    pub model: KinematicModel,
    /// `table-bc`: a point on the B axis (direction +Y), machine coordinates, mm.
    pub b_axis_point_mm: [f64; 3],
    /// `table-bc`: a point on the C axis (direction +Z) when B = 0, machine coordinates, mm.
    pub c_axis_point_mm: [f64; 3],
    /// `head-ab`: distance from the nozzle tip up to the pivot point the controller programs, mm.
    pub pivot_length_mm: f64,
}

impl Default for Kinematics {
    fn default() -> Self {
        Kinematics {
            model: KinematicModel::TableBc,
            b_axis_point_mm: [0.0; 3],
            c_axis_point_mm: [0.0; 3],
            pivot_length_mm: 0.0,
        }
    }
}

/// A machine pose: linear axes (mm) and the two rotary axes (degrees, in
/// [`KinematicModel::rotary_axes`] order).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// X, Y, Z, mm.
    pub xyz: V3,
    /// The two rotary axes, degrees.
    pub rot: [f64; 2],
}

fn rot_y(v: V3, a: f64) -> V3 {
    let (s, c) = (math::sin(a), math::cos(a));
    [c * v[0] + s * v[2], v[1], -s * v[0] + c * v[2]]
}

fn rot_z(v: V3, a: f64) -> V3 {
    let (s, c) = (math::sin(a), math::cos(a));
    [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]
}

fn rot_x(v: V3, a: f64) -> V3 {
    let (s, c) = (math::sin(a), math::cos(a));
    [v[0], c * v[1] - s * v[2], s * v[1] + c * v[2]]
}

/// Wraps an angle difference into `(−180, 180]` degrees.
pub fn wrap180(d: f64) -> f64 {
    let r = d - 360.0 * libm::floor((d + 180.0) / 360.0);
    if r <= -180.0 {
        r + 360.0
    } else {
        r
    }
}

impl Kinematics {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), &'static str> {
        let ok = self
            .b_axis_point_mm
            .iter()
            .chain(&self.c_axis_point_mm)
            .all(|v| v.is_finite() && v.abs() < 1e6);
        if !ok {
            return Err("kinematics: axis points must be finite and within ±1e6 mm");
        }
        if !(self.pivot_length_mm.is_finite() && self.pivot_length_mm.abs() < 1e6) {
            return Err("kinematics: pivot_length_mm must be finite and within ±1e6 mm");
        }
        Ok(())
    }

    /// Tool vector (unit, tip → nozzle) in the workpiece frame for rotary angles in degrees.
    pub fn tool_vector(&self, rot: [f64; 2]) -> V3 {
        let (a, b) = (vec3::rad(rot[0]), vec3::rad(rot[1]));
        match self.model {
            // R_z(−C) R_y(−B) ẑ
            KinematicModel::TableBc => rot_z(rot_y([0.0, 0.0, 1.0], -a), -b),
            // R_x(A) R_y(B) ẑ
            KinematicModel::HeadAb => rot_x(rot_y([0.0, 0.0, 1.0], b), a),
        }
    }

    /// The workpiece-frame direction along which the tool vector is singular (the second
    /// rotary angle is then undefined and near it the axis must spin fast): the C axis (`ẑ`) for
    /// `table-bc`, `x̂` (B = ±90°) for `head-ab`.
    pub fn singular_direction(&self) -> V3 {
        match self.model {
            KinematicModel::TableBc => [0.0, 0.0, 1.0],
            KinematicModel::HeadAb => [1.0, 0.0, 0.0],
        }
    }

    /// Forward kinematics: the tool-tip position in the workpiece frame for a machine pose.
    pub fn tip(&self, pose: &Pose) -> V3 {
        match self.model {
            KinematicModel::TableBc => {
                let (b, c) = (vec3::rad(pose.rot[0]), vec3::rad(pose.rot[1]));
                let bp = self.b_axis_point_mm;
                let cp = self.c_axis_point_mm;
                // p = R_z(−C) (R_y(−B)(M − b) + b − c) + c
                let q = vec3::add(vec3::sub(rot_y(vec3::sub(pose.xyz, bp), -b), cp), bp);
                vec3::add(rot_z(q, -c), cp)
            }
            KinematicModel::HeadAb => {
                let n = self.tool_vector(pose.rot);
                vec3::sub(pose.xyz, vec3::scale(n, self.pivot_length_mm))
            }
        }
    }

    /// Machine XYZ that puts the tool tip on workpiece point `p` with rotary angles `rot`.
    pub fn machine_xyz(&self, p: V3, rot: [f64; 2]) -> V3 {
        match self.model {
            KinematicModel::TableBc => {
                let (b, c) = (vec3::rad(rot[0]), vec3::rad(rot[1]));
                let bp = self.b_axis_point_mm;
                let cp = self.c_axis_point_mm;
                // M = R_y(B) (R_z(C)(p − c) + c − b) + b
                let q = vec3::sub(vec3::add(rot_z(vec3::sub(p, cp), c), cp), bp);
                vec3::add(rot_y(q, b), bp)
            }
            KinematicModel::HeadAb => {
                let n = self.tool_vector(rot);
                vec3::add(p, vec3::scale(n, self.pivot_length_mm))
            }
        }
    }

    /// The two inverse-kinematics solutions for unit tool vector `n`, degrees, principal
    /// values; `None` in the second slot when the axis is singular (the rotary angle is free).
    fn solutions(&self, n: V3) -> ([f64; 2], [f64; 2], bool) {
        match self.model {
            KinematicModel::TableBc => {
                let b1 = -vec3::deg(math::atan2(math::hypot(n[0], n[1]), n[2]));
                let singular = math::hypot(n[0], n[1]) < 1e-12;
                let c1 = -vec3::deg(math::atan2(n[1], n[0]));
                ([b1, c1], [-b1, wrap180(c1 + 180.0)], singular)
            }
            KinematicModel::HeadAb => {
                let b1 = vec3::deg(math::atan2(n[0], math::hypot(n[1], n[2])));
                let singular = math::hypot(n[1], n[2]) < 1e-12;
                let a1 = vec3::deg(math::atan2(-n[1], n[2]));
                (
                    [a1, b1],
                    [wrap180(a1 + 180.0), wrap180(180.0 - b1)],
                    singular,
                )
            }
        }
    }

    /// Inverse kinematics for the orientation: rotary angles (degrees) giving tool vector `n`,
    /// picking of the two solutions the one closest to `prev` (sum of axis moves, as Zhang's
    /// generator does) and unwrapping the turntable (table C) so it never jumps by 360°.
    /// At the singularity (tool along the rotary axis) the free angle keeps its previous value.
    pub fn rotary_for(&self, n: V3, prev: [f64; 2]) -> [f64; 2] {
        let (s1, s2, singular) = self.solutions(n);
        let place = |s: [f64; 2]| -> [f64; 2] {
            match self.model {
                KinematicModel::TableBc => {
                    let c = if singular {
                        prev[1]
                    } else {
                        prev[1] + wrap180(s[1] - prev[1])
                    };
                    [s[0], c]
                }
                KinematicModel::HeadAb => {
                    let a = if singular { prev[0] } else { s[0] };
                    [a, s[1]]
                }
            }
        };
        let (p1, p2) = (place(s1), place(s2));
        let cost = |p: [f64; 2]| {
            let d0 = match self.model {
                KinematicModel::TableBc => (p[0] - prev[0]).abs(),
                KinematicModel::HeadAb => wrap180(p[0] - prev[0]).abs(),
            };
            d0 + (p[1] - prev[1]).abs()
        };
        // Head B beyond ±90° turns the nozzle upside down: only use it when it is the nearer.
        if cost(p2) < cost(p1) {
            p2
        } else {
            p1
        }
    }
}

impl Kinematics {
    /// Every rotary solution for unit tool vector `n` worth considering near the original
    /// angles `orig`: both inverse-kinematics branches, and for the turntable (table C) the turn
    /// nearest `orig` and one either side. At the singularity the free angle takes its original
    /// value. Used by the path-wide choice in [`super::core`].
    pub fn candidates(&self, n: V3, orig: [f64; 2]) -> Vec<[f64; 2]> {
        let (s1, s2, singular) = self.solutions(n);
        let mut out = Vec::with_capacity(6);
        for s in [s1, s2] {
            match self.model {
                KinematicModel::TableBc => {
                    let c0 = if singular {
                        orig[1]
                    } else {
                        orig[1] + wrap180(s[1] - orig[1])
                    };
                    for turn in [0.0, -360.0, 360.0] {
                        out.push([s[0], c0 + turn]);
                    }
                }
                KinematicModel::HeadAb => {
                    let a = if singular { orig[0] } else { s[0] };
                    out.push([a, s[1]]);
                }
            }
        }
        out
    }

    /// Joint-space distance between two rotary poses (sum of the axis moves, degrees; the head's
    /// A is compared modulo a turn).
    pub fn step(&self, a: [f64; 2], b: [f64; 2]) -> f64 {
        let d0 = match self.model {
            KinematicModel::TableBc => (a[0] - b[0]).abs(),
            KinematicModel::HeadAb => wrap180(a[0] - b[0]).abs(),
        };
        d0 + (a[1] - b[1]).abs()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: V3, b: V3, tol: f64) -> bool {
        vec3::norm(vec3::sub(a, b)) < tol
    }

    #[test]
    fn zhang_formulas() {
        let k = Kinematics::default();
        let (b, c) = (-26.5f64, 371.0f64);
        let (br, cr) = (vec3::rad(b), vec3::rad(c));
        let n = k.tool_vector([b, c]);
        let expect = [
            -math::cos(cr) * math::sin(br),
            math::sin(br) * math::sin(cr),
            math::cos(br),
        ];
        assert!(close(n, expect, 1e-15));
        let p = [3.0, -7.0, 40.0];
        let m = k.machine_xyz(p, [b, c]);
        let (sb, cb, sc, cc) = (math::sin(br), math::cos(br), math::sin(cr), math::cos(cr));
        let zx = cb * cc * p[0] - cb * sc * p[1] + sb * p[2];
        let zy = sc * p[0] + cc * p[1];
        let zz = -sb * cc * p[0] + sb * sc * p[1] + cb * p[2];
        assert!(close(m, [zx, zy, zz], 1e-12));
    }

    #[test]
    fn round_trip_with_offsets() {
        for model in [KinematicModel::TableBc, KinematicModel::HeadAb] {
            let k = Kinematics {
                model,
                b_axis_point_mm: [10.0, -3.0, 55.0],
                c_axis_point_mm: [1.0, 2.0, 0.0],
                pivot_length_mm: 120.0,
            };
            // Table C is multi-turn; head angles are principal values.
            let last = if model == KinematicModel::TableBc {
                [5.0, 720.5]
            } else {
                [5.0, 80.5]
            };
            for (i, rot) in [[-20.0, 33.0], [45.0, -170.0], last].iter().enumerate() {
                let p = [i as f64 * 3.0 - 4.0, 12.5, 30.0 + i as f64];
                let m = k.machine_xyz(p, *rot);
                let back = k.tip(&Pose { xyz: m, rot: *rot });
                assert!(close(back, p, 1e-9), "{model:?} {rot:?}");
                let n = k.tool_vector(*rot);
                let r = k.rotary_for(n, *rot);
                assert!(
                    close(k.tool_vector(r), n, 1e-12),
                    "{model:?} {rot:?} -> {r:?}"
                );
                assert!(
                    (r[0] - rot[0]).abs() < 1e-9 && (r[1] - rot[1]).abs() < 1e-9,
                    "{model:?} {rot:?} {r:?}"
                );
            }
        }
    }

    #[test]
    fn turntable_is_unwrapped() {
        let k = Kinematics::default();
        let mut prev = [-10.0, 0.0];
        for step in 1..=2000 {
            let c_true = step as f64 * 2.5; // seven turns
            let n = k.tool_vector([-10.0, c_true]);
            let r = k.rotary_for(n, prev);
            assert!((r[1] - prev[1]).abs() < 180.0);
            assert!((r[1] - c_true).abs() < 1e-9);
            prev = r;
        }
    }

    #[test]
    fn wrap_is_in_range() {
        for d in [-540.0, -181.0, -180.0, 0.0, 179.9, 180.0, 181.0, 1e6] {
            let w = wrap180(d);
            assert!(w > -180.0 && w <= 180.0, "{d} -> {w}");
            assert!((libm::remainder(w - d, 360.0)).abs() < 1e-9);
        }
    }
}
