//! A multi-axis file drawn on its workpiece, for the playground's 3-D view: where the tool tip
//! runs on the part and where the tool points.
//!
//! A layer's drawing data ([`LayerGeometry`]) comes from [`crate::path`], which sits below this
//! module and knows no kinematic model, so it cannot read rotary words. This module adds the
//! tool vectors ([`LayerGeometry::tool`]) the way the smoothing reads its path points
//! (`program::samples`): the machine pose at the end of each extruding move, the tool tip in the
//! workpiece frame through `Frame::tip` and the unit tool vector through
//! [`Kinematics::tool_vector`] (table-BC: `n = R_z(−C) · R_y(−B) · ẑ =
//! (−cos C sin B, sin C sin B, cos B)`, see [`super::kinematics`]). The view thus shows the very
//! vectors the smoothing filters and the CIRP tolerance cone (eq. 4–7) is measured around.
//!
//! The path itself is drawn through the same tips ([`LayerGeometry::xyz`]): the machine X, Y,
//! Z of a table-BC file are where the nozzle is relative to a turning table, not where the
//! material goes on the part, so the vectors would float beside a machine-axis drawing.

use super::kinematics::Kinematics;
use super::program::{self, Frame};
use super::Coordinates;
use crate::machine::Pos;
use crate::path::{LayerGeometry, PrintPath, TOOL_FLOATS};

/// The tool vectors of layer `layer` of `path` ([`LayerGeometry::tool`] layout): one at the end
/// of every extruding move, as the smoothing samples the path. Empty past the last layer.
///
/// Every extruding move gets one, whatever its kind (an arc's end pose is as well defined as a
/// line's); which ones to draw (every n-th) is the viewer's choice, as it depends on how many
/// layers it shows.
pub fn tool_vectors(
    path: &PrintPath,
    layer: usize,
    kinematics: &Kinematics,
    coordinates: Coordinates,
) -> Vec<f32> {
    let frame = Frame {
        kin: kinematics,
        coordinates,
    };
    let moves = path.layer_moves(layer);
    let mut out = Vec::with_capacity(TOOL_FLOATS * moves.len());
    for m in moves.iter().filter(|m| m.is_extruding()) {
        let pose = program::pose(kinematics, &m.to);
        let tip = workpiece_point(&frame, &m.to);
        let n = kinematics.tool_vector(pose.rot);
        out.extend(tip.iter().chain(&n).map(|&v| v as f32));
    }
    out
}

/// Every layer's drawing data ([`PrintPath::layer_geometry`]) with, for a file whose rotary axes
/// move, its tool vectors ([`tool_vectors`]) and its segments in the workpiece frame
/// ([`LayerGeometry::xyz`]: the tool tip each machine position puts on the workpiece). A file
/// whose rotary axes never leave zero (a three-axis print) gets neither: its tool vector is the
/// constant `ẑ` and its machine X, Y, Z are the workpiece's, and a viewer that finds no vectors
/// knows it is not multi-axis.
///
/// The segments go through the same tips as the vectors, so that a viewer drawing both shows
/// each vector starting on the path: the machine X, Y of a table-BC file lie tens of mm away
/// from where the tip is on the part.
pub fn layer_geometries(
    path: &PrintPath,
    kinematics: &Kinematics,
    coordinates: Coordinates,
) -> Vec<LayerGeometry> {
    let rotary = program::has_rotary_motion(kinematics, &path.moves);
    let frame = Frame {
        kin: kinematics,
        coordinates,
    };
    let map = |pos: &Pos| workpiece_point(&frame, pos);
    (0..path.layers.len())
        .map(|i| {
            if !rotary {
                return path.layer_geometry(i);
            }
            let mut g = path.layer_geometry_in(i, Some(&map));
            g.tool = tool_vectors(path, i, kinematics, coordinates);
            g
        })
        .collect()
}

/// The tool tip in the workpiece frame at machine position `pos`: the point both the drawn
/// path ([`LayerGeometry::xyz`]) and the tool vectors ([`tool_vectors`]) use.
fn workpiece_point(frame: &Frame<'_>, pos: &Pos) -> [f64; 3] {
    frame.tip(&program::pose(frame.kin, pos))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyze::AnalyzeOptions;
    use crate::path::{self, SegmentKind};

    /// One layer, table-BC words: a travel to the start, then four extruding moves ending at
    /// known machine poses.
    const FIVE_AXIS: &[u8] = b"G90\nM83\n;LAYER_CHANGE\n;Z:1\nG0 X10 Y0 Z1 B0 C0 F3000\n\
G1 X10 Y1 Z1 B90 C0 E0.1 F600\nG1 X10 Y2 Z1 B90 C90 E0.1\nG1 X10 Y3 Z1 B-30 C45 E0.1\n\
G1 X10 Y4 Z1 B0 C0 E0.1\n";

    /// The analytic table-BC tool vector, written out rather than computed by the code under
    /// test: `(−cos C sin B, sin C sin B, cos B)`.
    fn analytic(b_deg: f64, c_deg: f64) -> [f64; 3] {
        let (b, c) = (b_deg.to_radians(), c_deg.to_radians());
        [-c.cos() * b.sin(), c.sin() * b.sin(), b.cos()]
    }

    fn rows(v: &[f32]) -> Vec<[f64; 6]> {
        v.chunks_exact(TOOL_FLOATS)
            .map(|c| std::array::from_fn(|k| f64::from(c[k])))
            .collect()
    }

    #[test]
    fn vectors_are_the_analytic_tool_direction() {
        let p = path::extract(FIVE_AXIS, &AnalyzeOptions::default(), false).unwrap();
        let g = layer_geometries(&p, &Kinematics::default(), Coordinates::Machine);
        assert_eq!(g.len(), 1);
        let tools = rows(&g[0].tool);
        // One per extruding move, none for the travel.
        assert_eq!(tools.len(), 4);
        // B = 90°, C = 0 tilts the tool onto −x; B = 90°, C = 90° onto +y.
        let known = [[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        for (t, want) in tools.iter().zip(known) {
            for k in 0..3 {
                assert!((t[3 + k] - want[k]).abs() < 1e-6, "{t:?} vs {want:?}");
            }
        }
        let angles = [(90.0, 0.0), (90.0, 90.0), (-30.0, 45.0), (0.0, 0.0)];
        for (t, (b, c)) in tools.iter().zip(angles) {
            let want = analytic(b, c);
            for k in 0..3 {
                assert!((t[3 + k] - want[k]).abs() < 1e-6, "B{b} C{c}: {t:?}");
            }
        }
        // Machine coordinates: the tip is R_z(−C) R_y(−B) M. B = 90°, C = 0 at M = (10, 1, 1):
        // R_y(−90°) (x, y, z) = (−z, y, x) = (−1, 1, 10).
        let tip = &tools[0][..3];
        for (a, b) in tip.iter().zip([-1.0, 1.0, 10.0]) {
            assert!((a - b).abs() < 1e-5, "{tip:?}");
        }
        // B = 0, C = 0: the workpiece frame is the machine frame.
        let last = &tools[3][..3];
        for (a, b) in last.iter().zip([10.0, 4.0, 1.0]) {
            assert!((a - b).abs() < 1e-5, "{last:?}");
        }
    }

    #[test]
    fn workpiece_coordinates_keep_the_tip_and_three_axis_files_have_none() {
        let p = path::extract(FIVE_AXIS, &AnalyzeOptions::default(), false).unwrap();
        let g = layer_geometries(&p, &Kinematics::default(), Coordinates::Workpiece);
        let tools = rows(&g[0].tool);
        assert_eq!(tools.len(), 4);
        for (t, y) in tools.iter().zip([1.0, 2.0, 3.0, 4.0]) {
            assert!(
                (t[0] - 10.0).abs() < 1e-6 && (t[1] - y).abs() < 1e-6 && (t[2] - 1.0).abs() < 1e-6
            );
        }
        let flat = b"M83\n;LAYER_CHANGE\n;Z:0.2\nG1 X10 Y0 Z0.2 E1 F600\nG1 X10 Y10 E1\n";
        let p = path::extract(flat, &AnalyzeOptions::default(), false).unwrap();
        let g = layer_geometries(&p, &Kinematics::default(), Coordinates::Machine);
        assert_eq!(g.len(), 1);
        assert_eq!(g[0].kind.len(), 2);
        assert!(g[0].tool.is_empty());
        // The path's own drawing data is unchanged by the tool vectors.
        assert_eq!(g[0], p.layer_geometry(0));
    }

    /// Table-BC words with a move in Z alone (nothing in machine X, Y; a 2 mm step along the
    /// part while B = 90°) and a travel between two extrusions.
    const PATH_5X: &[u8] = b"G90\nM83\n;LAYER_CHANGE\n;Z:1\nG0 X10 Y0 Z1 B0 C0 F3000\n\
G1 X10 Y1 Z1 B90 C0 E0.1 F600\nG1 X10 Y2 Z1 B90 C90 E0.1\nG1 X10 Y2 Z3 B90 C90 E0.1\n\
G0 X20 Y2 Z3 B90 C90\nG1 X20 Y3 Z3 B-30 C45 E0.1\nG1 X20 Y4 Z3 B0 C0 E0.1\n";

    /// The analytic table-BC tip of machine point `m` (axes through the origin), written out
    /// rather than computed by the code under test: `R_z(−C) · R_y(−B) · m`.
    fn analytic_tip(m: [f64; 3], b_deg: f64, c_deg: f64) -> [f64; 3] {
        let (b, c) = (b_deg.to_radians(), c_deg.to_radians());
        let q = [
            b.cos() * m[0] - b.sin() * m[2],
            m[1],
            b.sin() * m[0] + b.cos() * m[2],
        ];
        [
            c.cos() * q[0] + c.sin() * q[1],
            -c.sin() * q[0] + c.cos() * q[1],
            q[2],
        ]
    }

    fn near(a: &[f64], b: &[f64], tol: f64) -> bool {
        a.iter().zip(b).all(|(x, y)| (x - y).abs() < tol)
    }

    #[test]
    fn the_drawn_path_runs_through_the_tips_in_the_workpiece_frame() {
        let p = path::extract(PATH_5X, &AnalyzeOptions::default(), false).unwrap();
        let g = layer_geometries(&p, &Kinematics::default(), Coordinates::Machine);
        assert_eq!(g.len(), 1);
        let g = &g[0];
        // One segment per move, the Z-only move included, parallel to the 2-D arrays.
        assert_eq!(g.kind.len(), 7);
        assert_eq!(g.xyz.len(), 6 * g.kind.len());
        let segs = rows(&g.xyz);
        // Each segment ends at the analytic tip of its move's end, starts where the previous
        // ended (from the origin, where the machine starts).
        let ends = [
            ([10.0, 0.0, 1.0], 0.0, 0.0),
            ([10.0, 1.0, 1.0], 90.0, 0.0),
            ([10.0, 2.0, 1.0], 90.0, 90.0),
            ([10.0, 2.0, 3.0], 90.0, 90.0),
            ([20.0, 2.0, 3.0], 90.0, 90.0),
            ([20.0, 3.0, 3.0], -30.0, 45.0),
            ([20.0, 4.0, 3.0], 0.0, 0.0),
        ];
        let mut start = [0.0; 3];
        for (s, (m, b, c)) in segs.iter().zip(ends) {
            let tip = analytic_tip(m, b, c);
            assert!(near(&s[..3], &start, 1e-5), "{s:?} starts at {start:?}");
            assert!(near(&s[3..], &tip, 1e-5), "{s:?} ends at {tip:?}");
            start = tip;
        }
        // Written out: B = 90°, C = 90° turns (x, y, z) into (y, z, x); the Z-only move steps
        // 2 mm along y on the part, though it is a point in machine X, Y.
        assert!(near(&segs[2][3..], &[2.0, 1.0, 10.0], 1e-5));
        assert!(near(&segs[3][3..], &[2.0, 3.0, 10.0], 1e-5));
        assert_eq!(&g.xy[12..14], &g.xy[14..16]);
        assert_ne!(g.kind[3], SegmentKind::Travel as u8);
        assert_eq!(g.kind[4], SegmentKind::Travel as u8);
        // Every tool vector starts where an extruding segment ends, to the bit.
        let tools = rows(&g.tool);
        let extruding_ends: Vec<&[f64]> = segs
            .iter()
            .zip(&g.kind)
            .filter(|(_, &k)| k != SegmentKind::Travel as u8)
            .map(|(s, _)| &s[3..])
            .collect();
        assert_eq!(tools.len(), 5);
        assert_eq!(extruding_ends.len(), tools.len());
        for (t, e) in tools.iter().zip(extruding_ends) {
            assert_eq!(&t[..3], e);
        }
    }

    #[test]
    fn a_three_axis_file_gets_no_workpiece_path() {
        let flat = b"M83\n;LAYER_CHANGE\n;Z:0.2\nG1 X10 Y0 Z0.2 E1 F600\nG1 X10 Y10 E1\n";
        let p = path::extract(flat, &AnalyzeOptions::default(), false).unwrap();
        let g = layer_geometries(&p, &Kinematics::default(), Coordinates::Machine);
        assert!(g[0].xyz.is_empty() && !g[0].kind.is_empty());
    }
}
