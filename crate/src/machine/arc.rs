//! Circular and helical arcs (`G2`/`G3`) in the selected plane.
//!
//! Geometry follows RS274/NGC and Marlin: `I`/`J`/`K` are offsets of the centre from the start,
//! `R` gives the radius (negative for the long way round), the non-plane axis moves linearly
//! (helix), and a full circle is an arc that ends where it starts.

use serde::Serialize;

use crate::math::{atan2, cos, hypot, sin};

/// The plane arcs are drawn in (`G17`, `G18`, `G19`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Plane {
    /// `G17`: X-Y, helix along Z, offsets I and J.
    #[default]
    Xy,
    /// `G18`: Z-X, helix along Y, offsets K and I.
    Zx,
    /// `G19`: Y-Z, helix along X, offsets J and K.
    Yz,
}

impl Plane {
    /// Indices (into X, Y, Z) of the plane's first and second axis and of the helix axis.
    pub fn axes(self) -> (usize, usize, usize) {
        match self {
            Plane::Xy => (0, 1, 2),
            Plane::Zx => (2, 0, 1),
            Plane::Yz => (1, 2, 0),
        }
    }

    /// Offset word letters for the plane's first and second axis.
    pub fn offset_letters(self) -> (u8, u8) {
        match self {
            Plane::Xy => (b'I', b'J'),
            Plane::Zx => (b'K', b'I'),
            Plane::Yz => (b'J', b'K'),
        }
    }
}

/// A resolved arc: centre, radius and signed sweep in the plane.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Arc {
    /// Plane of the arc.
    pub plane: Plane,
    /// Centre in the plane's (first, second) coordinates, mm.
    pub center: [f64; 2],
    /// Radius, mm (from the start point).
    pub radius: f64,
    /// Signed sweep angle, radians: negative clockwise (`G2`), positive counter-clockwise (`G3`).
    pub sweep: f64,
    /// Angle of the start point seen from the centre, radians.
    pub start_angle: f64,
}

/// How an arc was specified.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ArcSpec {
    /// Centre offsets from the start point.
    Offsets(f64, f64),
    /// Radius; negative asks for the arc longer than a half turn.
    Radius(f64),
}

/// Relative tolerance on start and end radius before an arc is reported as inconsistent.
pub const RADIUS_MISMATCH_TOLERANCE: f64 = 0.01;

/// Why an arc could not be built.
pub type ArcError = &'static str;

impl Arc {
    /// Builds the arc from `start` to `end` (plane coordinates), `clockwise` for `G2`, with
    /// `turns` full turns in total for an arc that ends where it starts (RS274/NGC `P`; extra
    /// turns beyond the first are added to partial arcs too).
    ///
    /// Returns the arc and whether start and end radius disagree by more than
    /// [`RADIUS_MISMATCH_TOLERANCE`] (the arc is still built from the start radius, as Marlin and
    /// Klipper do).
    pub fn new(
        plane: Plane,
        start: [f64; 2],
        end: [f64; 2],
        spec: ArcSpec,
        clockwise: bool,
        turns: u32,
    ) -> Result<(Arc, bool), ArcError> {
        let (di, dj) = match spec {
            ArcSpec::Offsets(i, j) => (i, j),
            ArcSpec::Radius(r) => radius_to_offsets(start, end, r, clockwise)?,
        };
        let center = [start[0] + di, start[1] + dj];
        let radius = hypot(di, dj);
        if radius.is_nan() || radius <= 1e-9 || !radius.is_finite() {
            return Err("zero radius");
        }
        let end_radius = hypot(end[0] - center[0], end[1] - center[1]);
        let mismatch = (end_radius - radius).abs() > RADIUS_MISMATCH_TOLERANCE * radius.max(1.0);
        let a0 = atan2(start[1] - center[1], start[0] - center[0]);
        let a1 = atan2(end[1] - center[1], end[0] - center[0]);
        let tau = std::f64::consts::TAU;
        let mut sweep = if clockwise { a0 - a1 } else { a1 - a0 };
        sweep = sweep.rem_euclid(tau);
        // A closed arc is a full turn (the chord is zero to within rounding).
        let closed = hypot(end[0] - start[0], end[1] - start[1]) <= 1e-9 * radius.max(1.0);
        if closed || sweep < 1e-12 {
            sweep = tau;
        }
        sweep += tau * f64::from(turns.saturating_sub(1));
        let signed = if clockwise { -sweep } else { sweep };
        Ok((
            Arc {
                plane,
                center,
                radius,
                sweep: signed,
                start_angle: a0,
            },
            mismatch,
        ))
    }

    /// Length of the arc in its plane.
    pub fn planar_length(&self) -> f64 {
        self.radius * self.sweep.abs()
    }

    /// Length of the helix with `rise` along the helix axis.
    pub fn length(&self, rise: f64) -> f64 {
        hypot(self.planar_length(), rise)
    }

    /// Point in the plane at fraction `t` (0..=1) of the sweep.
    pub fn point_at(&self, t: f64) -> [f64; 2] {
        let a = self.start_angle + self.sweep * t;
        [
            self.center[0] + self.radius * cos(a),
            self.center[1] + self.radius * sin(a),
        ]
    }

    /// How many equal chords the arc takes for each to stay within `sagitta` of it (a chord
    /// spanning δ lies `r (1 − cos(δ/2))` from its arc); at least 1, at most 100 000.
    pub fn chords_within(&self, sagitta: f64) -> usize {
        let sagitta = sagitta.max(1e-9);
        let span = 2.0 * crate::math::acos((1.0 - sagitta / self.radius.max(sagitta)).max(-1.0));
        (self.sweep.abs() / span.max(1e-6)).ceil().clamp(1.0, 1e5) as usize
    }

    /// Direction of travel at fraction `t` of the sweep with `rise` along the helix axis, as
    /// (X, Y, Z) (not normalised: its length is the helix length per radian).
    pub fn tangent_at(&self, t: f64, rise: f64) -> [f64; 3] {
        let a = self.start_angle + self.sweep * t;
        let s = self.sweep.signum();
        let (i, j, k) = self.plane.axes();
        let mut d = [0.0; 3];
        d[i] = -s * self.radius * sin(a);
        d[j] = s * self.radius * cos(a);
        d[k] = if self.sweep != 0.0 {
            rise / self.sweep.abs()
        } else {
            0.0
        };
        d
    }

    /// Displacement in the plane from the start point to fraction `t` of the sweep (free of
    /// the absolute coordinates, so it holds after `G92` shifts too).
    pub fn offset_at(&self, t: f64) -> [f64; 2] {
        let a0 = self.start_angle;
        let a = a0 + self.sweep * t;
        [
            self.radius * (cos(a) - cos(a0)),
            self.radius * (sin(a) - sin(a0)),
        ]
    }
}

/// The signed sweep Klipper's `[gcode_arcs]` gives an arc from `start` to `end` with centre
/// offsets `(i, j)`, rad, computed in its order of operations: the angle between the start
/// and end radii, wrapped to (0, 2π) counter-clockwise or (−2π, 0) clockwise, and a full turn
/// only when that angle is exactly 0 and the end is the start. A closed arc whose centre does
/// not round-trip exactly (`(x + i) − x ≠ i`) comes out as a sliver of an angle, not a turn:
/// Creality Print's spiral lifts (`G3 Z… I… J…` back to the start) run on Klipper as a
/// straight Z move, and so they are timed here.
pub fn klipper_sweep(start: [f64; 2], end: [f64; 2], (i, j): (f64, f64), clockwise: bool) -> f64 {
    let (r_p, r_q) = (-i, -j);
    let (center_p, center_q) = (start[0] - r_p, start[1] - r_q);
    let (rt_alpha, rt_beta) = (end[0] - center_p, end[1] - center_q);
    let mut angle = atan2(
        r_p * rt_beta - r_q * rt_alpha,
        r_p * rt_alpha + r_q * rt_beta,
    );
    let tau = std::f64::consts::TAU;
    if angle < 0.0 {
        angle += tau;
    }
    if clockwise {
        angle -= tau;
    }
    if angle == 0.0 && start == end {
        angle = tau;
    }
    angle
}

/// Centre offsets of an `R`-form arc (the construction of RS274/NGC and grbl).
fn radius_to_offsets(
    start: [f64; 2],
    end: [f64; 2],
    r: f64,
    clockwise: bool,
) -> Result<(f64, f64), ArcError> {
    let x = end[0] - start[0];
    let y = end[1] - start[1];
    let d = hypot(x, y);
    if d <= 1e-12 {
        return Err("R form cannot describe a full circle");
    }
    if r.is_nan() || r.abs() <= 1e-12 {
        return Err("zero radius");
    }
    let mut disc = 4.0 * r * r - d * d;
    if disc < 0.0 {
        // Chord longer than the diameter: accept rounding, reject real inconsistencies.
        if d > 2.0 * r.abs() * (1.0 + 1e-3) + 1e-3 {
            return Err("radius smaller than half the chord");
        }
        disc = 0.0;
    }
    let mut h = -disc.sqrt() / d;
    if !clockwise {
        h = -h;
    }
    if r < 0.0 {
        h = -h;
    }
    Ok((0.5 * (x - y * h), 0.5 * (y + x * h)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI, TAU};

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn quarter_circles_both_ways() {
        // From (10,0) to (0,10) around the origin.
        let (a, bad) = Arc::new(
            Plane::Xy,
            [10.0, 0.0],
            [0.0, 10.0],
            ArcSpec::Offsets(-10.0, 0.0),
            false,
            1,
        )
        .unwrap();
        assert!(!bad);
        assert!(close(a.sweep, FRAC_PI_2));
        assert!(close(a.planar_length(), 10.0 * FRAC_PI_2));
        let (a, _) = Arc::new(
            Plane::Xy,
            [10.0, 0.0],
            [0.0, 10.0],
            ArcSpec::Offsets(-10.0, 0.0),
            true,
            1,
        )
        .unwrap();
        assert!(close(a.sweep, -3.0 * FRAC_PI_2));
    }

    #[test]
    fn full_circles_and_turns() {
        let (a, _) = Arc::new(
            Plane::Xy,
            [5.0, 0.0],
            [5.0, 0.0],
            ArcSpec::Offsets(-5.0, 0.0),
            false,
            1,
        )
        .unwrap();
        assert!(close(a.sweep, TAU));
        let (a, _) = Arc::new(
            Plane::Xy,
            [5.0, 0.0],
            [5.0, 0.0],
            ArcSpec::Offsets(-5.0, 0.0),
            true,
            3,
        )
        .unwrap();
        assert!(close(a.sweep, -3.0 * TAU));
        assert!(close(a.length(4.0), (5.0 * 3.0 * TAU).hypot(4.0)));
    }

    #[test]
    fn radius_form_short_and_long_way() {
        // Semicircle-free case: chord of length sqrt(2)*10 with r=10 is a quarter circle.
        let (a, bad) = Arc::new(
            Plane::Xy,
            [10.0, 0.0],
            [0.0, 10.0],
            ArcSpec::Radius(10.0),
            false,
            1,
        )
        .unwrap();
        assert!(!bad);
        assert!(close(a.sweep, FRAC_PI_2), "{a:?}");
        assert!(close(a.center[0], 0.0) && close(a.center[1], 0.0));
        let (a, _) = Arc::new(
            Plane::Xy,
            [10.0, 0.0],
            [0.0, 10.0],
            ArcSpec::Radius(-10.0),
            false,
            1,
        )
        .unwrap();
        assert!(close(a.sweep, 3.0 * FRAC_PI_2), "{a:?}");
        // Chord equal to the diameter, with rounding: a half turn.
        let (a, _) = Arc::new(
            Plane::Xy,
            [0.0, 0.0],
            [20.0, 0.0],
            ArcSpec::Radius(9.99999),
            true,
            1,
        )
        .unwrap();
        assert!((a.sweep.abs() - PI).abs() < 1e-3);
    }

    #[test]
    fn invalid_arcs() {
        assert!(Arc::new(
            Plane::Xy,
            [0.0, 0.0],
            [1.0, 0.0],
            ArcSpec::Offsets(0.0, 0.0),
            true,
            1
        )
        .is_err());
        assert!(Arc::new(
            Plane::Xy,
            [0.0, 0.0],
            [100.0, 0.0],
            ArcSpec::Radius(1.0),
            true,
            1
        )
        .is_err());
        assert!(Arc::new(
            Plane::Xy,
            [0.0, 0.0],
            [0.0, 0.0],
            ArcSpec::Radius(1.0),
            true,
            1
        )
        .is_err());
    }

    #[test]
    fn radius_mismatch_is_flagged() {
        let (_, bad) = Arc::new(
            Plane::Xy,
            [10.0, 0.0],
            [0.0, 12.0],
            ArcSpec::Offsets(-10.0, 0.0),
            false,
            1,
        )
        .unwrap();
        assert!(bad);
    }

    #[test]
    fn points_lie_on_the_circle() {
        let (a, _) = Arc::new(
            Plane::Xy,
            [10.0, 0.0],
            [0.0, 10.0],
            ArcSpec::Offsets(-10.0, 0.0),
            false,
            1,
        )
        .unwrap();
        let p = a.point_at(0.5);
        assert!(close(p[0].hypot(p[1]), 10.0));
        assert!(close(p[0], p[1]));
    }
}
