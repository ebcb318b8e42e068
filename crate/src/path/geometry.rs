//! Drawing data of a layer: flat arrays of segments with what a viewer colours them by.
//!
//! The playground's layer viewer draws thousands of segments per frame; it gets them as flat
//! `f32` arrays (typed arrays in JS) rather than objects. Arcs are split into chords no more
//! than [`ARC_CHORD_DEG`] apart, enough for a screen.

use serde::Serialize;

use super::{PathMove, PrintPath, NO_FEATURE};
use crate::machine::{axis, MoveKind, Plane, Pos};

/// Largest angle an arc's drawing chord spans, degrees.
pub const ARC_CHORD_DEG: f64 = 10.0;

/// What a segment is, for colouring. The numbers are part of the JS API.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[repr(u8)]
pub enum SegmentKind {
    /// A travel (no extrusion).
    Travel = 0,
    /// Outer wall.
    OuterWall = 1,
    /// Inner walls.
    InnerWall = 2,
    /// Sparse infill.
    SparseInfill = 3,
    /// Solid infill, skins.
    SolidInfill = 4,
    /// Bridges.
    Bridge = 5,
    /// Gap fill.
    GapFill = 6,
    /// Support.
    Support = 7,
    /// Skirt, brim, raft.
    Adhesion = 8,
    /// Any other extrusion (unnamed features, custom blocks).
    Other = 9,
}

/// Segments of one layer, as parallel flat arrays (segment `i` is
/// `xy[4i..4i+4] = [x0, y0, x1, y1]`).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct LayerGeometry {
    /// Layer height, mm, if known.
    pub z: Option<f64>,
    /// Segment end points, mm.
    pub xy: Vec<f32>,
    /// [`SegmentKind`] of each segment.
    pub kind: Vec<u8>,
    /// Peak planned speed of the move each segment belongs to, mm/s (its requested feed rate
    /// when the path was extracted without planning).
    pub speed: Vec<f32>,
    /// Curvature at the segment's start: turning angle to the previous printing segment over
    /// the mean of their lengths, 1/mm (0 after a travel and on travels).
    pub curvature: Vec<f32>,
    /// For a multi-axis file, segment end points in 3-D, six numbers each, parallel to `xy`
    /// (segment `i` is `xyz[6i..6i+6] = [x0, y0, z0, x1, y1, z1]`): the tool tip in the
    /// workpiece frame, where the part is built, while `xy` holds the machine axes. Filled only
    /// through a mapping ([`PrintPath::layer_geometry_in`]), which `orient` supplies with its
    /// kinematic model (`orient::layer_geometries`). Empty for a three-axis file, whose
    /// machine X, Y, Z are the workpiece's.
    pub xyz: Vec<f32>,
    /// Tool vectors of a multi-axis file, [`TOOL_FLOATS`] numbers each (vector `i` is
    /// `tool[6i..6i+6] = [x, y, z, i, j, k]`): the tool tip (mm) and the unit tool vector (tip
    /// towards the nozzle), both in the workpiece frame. Always empty here: reading rotary axes
    /// takes a kinematic model, which lives in `orient`, above this module; `orient` fills it
    /// (`orient::layer_geometries`). Empty for a three-axis file.
    pub tool: Vec<f32>,
}

/// Numbers per tool vector in [`LayerGeometry::tool`]: tip x, y, z, then the unit vector.
pub const TOOL_FLOATS: usize = 6;

fn segment_kind(path: &PrintPath, m: &PathMove) -> SegmentKind {
    use crate::gcode::FeatureKind as F;
    if !m.is_extruding() {
        return SegmentKind::Travel;
    }
    if m.feature == NO_FEATURE {
        return SegmentKind::Other;
    }
    match path.feature_kind(m) {
        Some(F::OuterWall) => SegmentKind::OuterWall,
        Some(F::InnerWall) => SegmentKind::InnerWall,
        Some(F::SparseInfill) => SegmentKind::SparseInfill,
        Some(F::SolidInfill) => SegmentKind::SolidInfill,
        Some(F::Bridge) => SegmentKind::Bridge,
        Some(F::GapFill) => SegmentKind::GapFill,
        Some(F::Support) => SegmentKind::Support,
        Some(F::Adhesion) => SegmentKind::Adhesion,
        Some(F::Other) | None => SegmentKind::Other,
    }
}

/// Where a viewer draws a machine position in 3-D, when that is not the position's own X, Y, Z:
/// for a multi-axis file, the tool tip in the workpiece frame. This module cannot read rotary
/// words (that takes the kinematic model, which lives in `orient`, above it), so the caller
/// supplies the mapping ([`PrintPath::layer_geometry_in`]).
pub type DrawPoint<'a> = &'a dyn Fn(&Pos) -> [f64; 3];

/// Machine positions along move `m` at drawing resolution, its start excluded: the end of a
/// line, the chord ends of an arc in the XY plane. Along an arc, the axes outside the plane
/// (Z of a helix, rotary axes) go linearly with the swept fraction, as they are interpolated.
fn draw_positions(m: &PathMove) -> Vec<Pos> {
    match m.kind {
        MoveKind::Arc(a) if a.plane == Plane::Xy && a.radius.is_finite() => {
            let n = (a.sweep.abs().to_degrees() / ARC_CHORD_DEG)
                .ceil()
                .clamp(1.0, 720.0) as usize;
            (1..=n)
                .map(|i| {
                    let t = i as f64 / n as f64;
                    let o = a.offset_at(t);
                    let mut p: Pos = std::array::from_fn(|k| m.from[k] + t * (m.to[k] - m.from[k]));
                    p[axis::X] = m.from[axis::X] + o[0];
                    p[axis::Y] = m.from[axis::Y] + o[1];
                    p
                })
                .collect()
        }
        _ => vec![m.to],
    }
}

fn distance3(a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt()
}

/// Turning angle from the previous printing segment (direction `pd`, length `plen`) to `d` of
/// length `len`, over the mean of the lengths, 1/mm.
fn turn_curvature(pd: [f64; 2], plen: f64, d: [f64; 2], len: f64) -> f64 {
    let cross = pd[0] * d[1] - pd[1] * d[0];
    let dot = pd[0] * d[0] + pd[1] * d[1];
    crate::math::atan2(cross, dot).abs() / (0.5 * (len + plen))
}

impl PrintPath {
    /// The drawing data of layer `layer` (empty past the last layer), without 3-D points
    /// ([`LayerGeometry::xyz`] empty): a viewer stacks `xy` at the layer's height.
    pub fn layer_geometry(&self, layer: usize) -> LayerGeometry {
        self.layer_geometry_in(layer, None)
    }

    /// The drawing data of layer `layer`, with, when `map` is given, every segment's end points
    /// through it in [`LayerGeometry::xyz`] (parallel to `xy`, so the colours apply to both).
    ///
    /// A segment is dropped when it has no length in the drawing: none in XY, and none in 3-D
    /// either when mapped. The second condition keeps, for a multi-axis file, a move that only
    /// turns the table or lifts Z (nothing in machine XY, a real path on the workpiece), so the
    /// 3-D path runs through every move's end; in `xy` it is a point, with no curvature.
    pub fn layer_geometry_in(&self, layer: usize, map: Option<DrawPoint<'_>>) -> LayerGeometry {
        let mut g = LayerGeometry {
            z: self.layers.get(layer).and_then(|l| l.z),
            ..LayerGeometry::default()
        };
        // Previous printing segment's direction and length, for curvature.
        let mut prev: Option<([f64; 2], f64)> = None;
        for m in self.layer_moves(layer) {
            let kind = segment_kind(self, m);
            let speed = m.timing.map_or(m.feed_mm_s, |t| t.profile.peak) as f32;
            let mut start = [m.from[axis::X], m.from[axis::Y]];
            let mut start3 = map.map(|f| f(&m.from));
            for pos in draw_positions(m) {
                let p = [pos[axis::X], pos[axis::Y]];
                let p3 = map.map(|f| f(&pos));
                let d = [p[0] - start[0], p[1] - start[1]];
                let len = crate::math::hypot(d[0], d[1]);
                let len3 = start3.zip(p3).map_or(0.0, |(a, b)| distance3(a, b));
                if len < 1e-9 && len3 < 1e-9 {
                    continue;
                }
                let curvature = match (kind, prev) {
                    _ if len < 1e-9 => 0.0,
                    (SegmentKind::Travel, _) | (_, None) => 0.0,
                    (_, Some((pd, plen))) => turn_curvature(pd, plen, d, len),
                };
                if len >= 1e-9 {
                    prev = (kind != SegmentKind::Travel).then_some((d, len));
                }
                g.xy.extend([start[0] as f32, start[1] as f32, p[0] as f32, p[1] as f32]);
                if let (Some(a), Some(b)) = (start3, p3) {
                    g.xyz.extend(a.iter().chain(&b).map(|&v| v as f32));
                }
                g.kind.push(kind as u8);
                g.speed.push(speed);
                g.curvature.push(curvature as f32);
                start = p;
                start3 = p3;
            }
        }
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyze::AnalyzeOptions;

    #[test]
    fn square_corners_have_curvature_and_arcs_are_split() {
        let gcode =
            b"M83\n;LAYER_CHANGE\n;TYPE:External perimeter\nG1 X10 Y0 E1 F600\nG1 X10 Y10 E1\n\
G0 X20 Y10\nG3 X20 Y30 I0 J10 E1\n";
        let p = super::super::extract(gcode, &AnalyzeOptions::default(), true).unwrap();
        let g = p.layer_geometry(0);
        // 2 lines + 1 travel + a half circle in 18 chords of 10°.
        assert_eq!(g.kind.len(), 2 + 1 + 18);
        assert_eq!(g.xy.len(), 4 * g.kind.len());
        assert_eq!(g.kind[0], SegmentKind::OuterWall as u8);
        assert_eq!(g.kind[2], SegmentKind::Travel as u8);
        // 90° turn between two 10 mm segments: (π/2) / 10.
        assert!((g.curvature[1] as f64 - std::f64::consts::FRAC_PI_2 / 10.0).abs() < 1e-6);
        assert_eq!(g.curvature[3], 0.0, "first segment after a travel");
        // Chords of a radius-10 circle 10° apart: curvature ≈ 1/10.
        assert!(
            (g.curvature[5] as f64 - 0.1).abs() < 1e-3,
            "{}",
            g.curvature[5]
        );
        let end = &g.xy[g.xy.len() - 2..];
        assert!((end[0] - 20.0).abs() < 1e-4 && (end[1] - 30.0).abs() < 1e-4);
        assert!(g.speed.iter().all(|&v| v > 0.0 && v <= 10.0 + 1e-3));
        assert!(p.layer_geometry(5).kind.is_empty());
    }

    #[test]
    fn a_mapping_gives_parallel_3d_points_through_the_arc_chords() {
        let gcode = b"M83\n;LAYER_CHANGE\nG1 X20 Y10 E1 F600\nG1 X20 Y10 Z2 E1\n\
G3 X20 Y30 Z4 I0 J10 E1\n";
        let p = super::super::extract(gcode, &AnalyzeOptions::default(), true).unwrap();
        let map = |q: &Pos| [q[axis::X], q[axis::Y], q[axis::Z]];
        let plain = p.layer_geometry(0);
        let g = p.layer_geometry_in(0, Some(&map));
        assert!(plain.xyz.is_empty());
        // The Z-only lift is a point in XY: dropped unmapped, kept mapped (a real 3-D step).
        assert_eq!(plain.kind.len(), 1 + 18);
        assert_eq!(g.kind.len(), 1 + 1 + 18);
        assert_eq!(g.xyz.len(), 6 * g.kind.len());
        assert_eq!(g.curvature[1], 0.0);
        for (i, s) in g.xyz.chunks_exact(6).enumerate() {
            assert_eq!([s[0], s[1], s[3], s[4]], g.xy[4 * i..4 * i + 4]);
        }
        // Along the helix Z rises linearly with the swept fraction: 2 + 2·i/18 at chord i.
        for (i, s) in g.xyz.chunks_exact(6).skip(2).enumerate() {
            let want = 2.0 + 2.0 * (i + 1) as f32 / 18.0;
            assert!((s[5] - want).abs() < 1e-5, "chord {i}: {s:?}");
        }
        // Unmapped data is untouched by the mapping.
        assert_eq!(
            plain.xy[..],
            g.xy[..4]
                .iter()
                .chain(&g.xy[8..])
                .copied()
                .collect::<Vec<_>>()[..]
        );
    }
}
