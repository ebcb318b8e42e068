//! Runs of nearly collinear lines joined into one, to pay in lines for the corners rounded
//! elsewhere where arcs do not (a firmware without `G2`/`G3`, or chains that lie on no
//! circle).
//!
//! Slicers write a wall from the mesh's facets and their own offsetting, and many chains of
//! short lines turn by a hair at each vertex: what Cura's "maximum resolution" and
//! PrusaSlicer's `gcode_resolution` exist to thin. Joined within a quarter of the tolerance
//! (the compacting's share, as for arcs), such a chain is one line the firmware plans as one
//! block. Only lines of one feed and one flow are joined (filament per millimetre within
//! [`FLOW_SHARE`] of the first line's): the joined line lays the chain's filament evenly, so the
//! wall gets the same plastic where it was even already, and no less where it was not.

use crate::vtg::arcs::Piece;
use crate::vtg::deviation::point_segment;

/// Largest relative difference in filament per millimetre between lines joined: a hundredth,
/// well under what a printer's own extrusion varies by, and above the rounding of five-decimal
/// E words on lines of a few tenths of a millimetre (which a stricter bound would refuse).
pub(crate) const FLOW_SHARE: f64 = 0.01;

/// Most lines joined into one: the check of a run costs its length squared.
const MOST_JOINED: usize = 64;

/// `pieces` of the polyline `pts` (filament `e` from the start at each point) with each run of
/// consecutive lines of one feed and flow whose inner points all lie within `tol` of the line
/// from the run's start to its end written as that line; arcs as they are. With them, the
/// largest distance of an inner point from its joined line: the path moves no farther from the
/// original than that, either way (each original segment lies within it of the joined line,
/// distance to a segment being convex along a line, and every point of the joined line has an
/// original point projecting onto it within it).
pub(crate) fn joined(pts: &[[f64; 3]], e: &[f64], pieces: &[Piece], tol: f64) -> (Vec<Piece>, f64) {
    let mut out: Vec<Piece> = Vec::with_capacity(pieces.len());
    let mut worst = 0.0f64;
    // The run being joined: where it starts (a point index) and its first line's flow.
    let mut run: Option<(usize, f64)> = None;
    let mut start = 0usize;
    for piece in pieces {
        let (from, to) = (start, piece.end);
        start = piece.end;
        let flow = flow(pts, e, from, to).filter(|_| piece.arc.is_none() && to == from + 1);
        let Some(flow) = flow else {
            run = None;
            out.push(*piece);
            continue;
        };
        let extended = run.and_then(|(s, f0)| {
            let last = out.last()?;
            let fits = last.arc.is_none()
                && last.feed == piece.feed
                && (flow - f0).abs() <= FLOW_SHARE * f0.abs()
                && to - s <= MOST_JOINED;
            fits.then(|| farthest_inside(pts, s, to))
                .flatten()
                .filter(|&far| far <= tol)
        });
        match extended {
            Some(far) => {
                if let Some(last) = out.last_mut() {
                    last.end = to;
                }
                worst = worst.max(far);
            }
            None => {
                run = Some((from, flow));
                out.push(*piece);
            }
        }
    }
    (out, worst)
}

/// Filament per millimetre of the stretch `from..to` of `pts`, `None` where it is too short
/// to say or lays none.
fn flow(pts: &[[f64; 3]], e: &[f64], from: usize, to: usize) -> Option<f64> {
    let (a, b) = (pts.get(from)?, pts.get(to)?);
    let len = crate::vec3::norm(crate::vec3::sub(*b, *a));
    let laid = e.get(to)? - e.get(from)?;
    (len > 1e-6 && laid > 0.0).then(|| laid / len)
}

/// The largest distance of the points strictly between `from` and `to` from the segment
/// joining those two, `None` where the points climb (a vase's steps keep their heights).
fn farthest_inside(pts: &[[f64; 3]], from: usize, to: usize) -> Option<f64> {
    let (a, b) = (*pts.get(from)?, *pts.get(to)?);
    let level = |p: &[f64; 3]| (p[2] - a[2]).abs() <= 1e-9;
    if !level(&b) {
        return None;
    }
    let inner = pts.get(from + 1..to)?;
    inner.iter().try_fold(0.0f64, |far, p| {
        level(p).then(|| far.max(point_segment(p, &a, &b)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vtg::arcs;

    /// A polyline through `xy` at Z 0.2, filament `flow` per millimetre, and its lines.
    fn polyline(xy: &[[f64; 2]], flow: &[f64]) -> (Vec<[f64; 3]>, Vec<f64>, Vec<Piece>) {
        let pts: Vec<[f64; 3]> = xy.iter().map(|p| [p[0], p[1], 0.2]).collect();
        let mut e = vec![0.0];
        for (k, w) in pts.windows(2).enumerate() {
            let len = crate::vec3::norm(crate::vec3::sub(w[1], w[0]));
            e.push(e[k] + len * flow[k]);
        }
        let pieces = arcs::lines(&vec![30.0; pts.len() - 1]);
        (pts, e, pieces)
    }

    #[test]
    fn a_chain_that_bends_by_hundredths_is_one_line_and_a_corner_stays() {
        // Four lines along X bending by 0.01 mm, then a right angle.
        let xy = [
            [0.0, 0.0],
            [1.0, 0.01],
            [2.0, 0.0],
            [3.0, 0.01],
            [4.0, 0.0],
            [4.0, 3.0],
        ];
        let (pts, e, pieces) = polyline(&xy, &[0.03; 5]);
        let (out, far) = joined(&pts, &e, &pieces, 0.025);
        let ends: Vec<usize> = out.iter().map(|p| p.end).collect();
        assert_eq!(ends, [4, 5]);
        assert!((far - 0.01).abs() < 1e-12, "{far}");
        // Bending by more than the tolerance, nothing is joined.
        let (out, far) = joined(&pts, &e, &pieces, 0.005);
        assert_eq!(out.len(), 5);
        assert_eq!(far, 0.0);
    }

    #[test]
    fn lines_of_another_flow_or_feed_or_an_arc_are_not_joined() {
        let xy = [[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0], [4.0, 0.0]];
        // The third line lays 5 % more: the run stops before it and starts again there.
        let (pts, e, pieces) = polyline(&xy, &[0.03, 0.03, 0.0315, 0.0315]);
        let ends: Vec<usize> = joined(&pts, &e, &pieces, 0.025)
            .0
            .iter()
            .map(|p| p.end)
            .collect();
        assert_eq!(ends, [2, 4]);
        // A feed change does the same.
        let (pts, e, mut pieces) = polyline(&xy, &[0.03; 4]);
        pieces[1].feed = 60.0;
        let ends: Vec<usize> = joined(&pts, &e, &pieces, 0.025)
            .0
            .iter()
            .map(|p| p.end)
            .collect();
        assert_eq!(ends, [1, 2, 4]);
        // An arc piece is kept, and the lines on either side of it are not joined across it.
        let (pts, e, _) = polyline(&xy, &[0.03; 4]);
        let arc = arcs::ArcShape {
            center: [1.5, -10.0],
            ccw: true,
        };
        let with_arc = vec![
            Piece {
                end: 1,
                arc: None,
                feed: 30.0,
            },
            Piece {
                end: 2,
                arc: Some(arc),
                feed: 30.0,
            },
            Piece {
                end: 3,
                arc: None,
                feed: 30.0,
            },
            Piece {
                end: 4,
                arc: None,
                feed: 30.0,
            },
        ];
        let out = joined(&pts, &e, &with_arc, 0.025).0;
        let ends: Vec<usize> = out.iter().map(|p| p.end).collect();
        assert_eq!(ends, [1, 2, 4]);
        assert!(out[1].arc.is_some());
    }

    #[test]
    fn a_climbing_chain_keeps_its_steps() {
        let pts = vec![[0.0, 0.0, 0.2], [1.0, 0.0, 0.21], [2.0, 0.0, 0.22]];
        let e = vec![0.0, 0.03, 0.06];
        let pieces = arcs::lines(&[30.0, 30.0]);
        assert_eq!(joined(&pts, &e, &pieces, 0.025).0.len(), 2);
    }
}
