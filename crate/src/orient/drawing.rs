//! Tool vectors for drawing: where the tool points along a multi-axis file, for the
//! playground's 3-D view.
//!
//! A layer's drawing data ([`LayerGeometry`]) comes from [`crate::path`], which sits below this
//! module and knows no kinematic model, so it cannot read rotary words. This module adds the
//! tool vectors ([`LayerGeometry::tool`]) the way the smoothing reads its path points
//! (`program::samples`): the machine pose at the end of each extruding move, the tool tip in the
//! workpiece frame through `Frame::tip` and the unit tool vector through
//! [`Kinematics::tool_vector`] (table-BC: `n = R_z(−C) · R_y(−B) · ẑ =
//! (−cos C sin B, sin C sin B, cos B)`, see [`super::kinematics`]). The view thus shows the very
//! vectors the smoothing filters and the CIRP tolerance cone (eq. 4–7) is measured around.

use super::kinematics::Kinematics;
use super::program::{self, Frame};
use super::Coordinates;
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
        let tip = frame.tip(&pose);
        let n = kinematics.tool_vector(pose.rot);
        out.extend(tip.iter().chain(&n).map(|&v| v as f32));
    }
    out
}

/// Every layer's drawing data ([`PrintPath::layer_geometry`]) with, for a file whose rotary axes
/// move, its tool vectors ([`tool_vectors`]). A file whose rotary axes never leave zero (a
/// three-axis print) gets none: its tool vector is the constant `ẑ`, and a viewer that finds no
/// vectors knows the file is not multi-axis.
pub fn layer_geometries(
    path: &PrintPath,
    kinematics: &Kinematics,
    coordinates: Coordinates,
) -> Vec<LayerGeometry> {
    let rotary = program::has_rotary_motion(kinematics, &path.moves);
    (0..path.layers.len())
        .map(|i| {
            let mut g = path.layer_geometry(i);
            if rotary {
                g.tool = tool_vectors(path, i, kinematics, coordinates);
            }
            g
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analyze::AnalyzeOptions;
    use crate::path;

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
}
