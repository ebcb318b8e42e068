//! Where the sparse infill of a layer may go, recovered from the G-code alone.
//!
//! The choice (a slicer's own construction, run backwards):
//! 1. The part's cross-section `P` is the area inside the **closed outer-wall loops** of the
//!    layer under the even-odd rule, so holes come out as holes and islands in holes as
//!    islands. Files that mark walls but not which is outermost (or print open walls) fall
//!    back to all closed wall loops under the non-zero rule: every slicer prints outer
//!    contours and holes in opposite directions, so a hole's loops cancel its contour's.
//! 2. Everything else the layer extrudes (walls, solid infill, bridges, gap fill) is stroked
//!    with half-width `d` and taken away: `R = P ∖ stroke(others, d)`. `d` is **measured**: the
//!    median distance from the ends of the file's own sparse-infill lines to the nearest wall,
//!    which is the slicer's "half extrusion width minus infill overlap" without knowing either.
//! 3. Slivers thinner than about `d` (between solid-infill lines) are removed by an opening
//!    (offset in by `d/2`, out by `d/2`).
//!
//! A loop is a run of consecutive extruding wall moves that returns within 1 mm of its start
//! (a seam gap) after at least 4 mm. Works for every dialect whose feature markers say what a
//! wall and what sparse infill is; layers without closed loops get no region (left as they are).

use i_overlay::core::fill_rule::FillRule;
use i_overlay::core::overlay_rule::OverlayRule;
use i_overlay::float::single::SingleFloatOverlay;
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::stroke::offset::StrokeOffset;
use i_overlay::mesh::float::style::{LineCap, OutlineStyle, StrokeStyle};

use super::geom::{dist, path_len, region_area, seg_dist, simplify_closed, Path, Region, P2};
use super::program::{Mv, Program};
use crate::gcode::FeatureKind;
use crate::machine::{axis, MoveKind, Plane};

/// Largest seam gap of a closed loop, mm.
const SEAM_GAP_MM: f64 = 1.0;
/// Most points a layer's region may have (hostile input bound).
const MAX_POINTS: usize = 200_000;

/// The region of one layer.
#[derive(Debug, Clone)]
pub(crate) struct LayerRegion {
    /// Where new sparse infill goes (even-odd contours).
    pub region: Region,
    /// Area of `region`, mm².
    pub area_mm2: f64,
}

fn is_wall(k: Option<FeatureKind>) -> bool {
    matches!(k, Some(FeatureKind::OuterWall | FeatureKind::InnerWall))
}

/// Extruding runs of a layer: (points, feature kind of the run).
fn runs(moves: &[Mv]) -> Vec<(Path, Option<FeatureKind>)> {
    let mut out: Vec<(Path, Option<FeatureKind>)> = Vec::new();
    let mut cur: Option<(Path, Option<FeatureKind>)> = None;
    for mv in moves {
        let from = [mv.m.from[axis::X], mv.m.from[axis::Y]];
        let to = [mv.m.to[axis::X], mv.m.to[axis::Y]];
        if !mv.m.is_extruding() {
            if mv.m.length_mm > 1e-9 {
                out.extend(cur.take());
            }
            continue;
        }
        // Arcs (G2/G3 in the XY plane) as chords of at most 5°, so arc-fitted walls bound the
        // region as the nozzle draws them.
        let mut pts_of_move: Vec<P2> = Vec::new();
        if let MoveKind::Arc(a) = mv.m.kind {
            if a.plane == Plane::Xy && a.radius.is_finite() && a.sweep.is_finite() {
                let n = ((a.sweep.abs() / 5f64.to_radians()).ceil() as usize).clamp(1, 720);
                for k in 1..n {
                    let t = a.start_angle + a.sweep * k as f64 / n as f64;
                    pts_of_move.push([
                        a.center[0] + a.radius * crate::math::cos(t),
                        a.center[1] + a.radius * crate::math::sin(t),
                    ]);
                }
            }
        }
        pts_of_move.push(to);
        match cur.as_mut() {
            Some((pts, k))
                if *k == mv.kind && pts.last().is_some_and(|&l| dist(l, from) < 1e-6) =>
            {
                pts.extend(pts_of_move)
            }
            _ => {
                out.extend(cur.take());
                let mut pts = vec![from];
                pts.extend(pts_of_move);
                cur = Some((pts, mv.kind));
            }
        }
    }
    out.extend(cur);
    out
}

fn is_closed(p: &[P2]) -> bool {
    match (p.first(), p.last()) {
        (Some(&a), Some(&b)) => dist(a, b) <= SEAM_GAP_MM && path_len(p) >= 4.0 * SEAM_GAP_MM,
        _ => false,
    }
}

/// The measured clearance `d` between walls and infill ends (see the module docs), from up to
/// `MAX_SAMPLES` sparse-infill line ends; `None` when the file gives no evidence.
pub(crate) fn clearance(prog: &Program, layers: &[Vec<usize>]) -> Option<f64> {
    const MAX_SAMPLES: usize = 400;
    let mut samples = Vec::new();
    for idx in layers {
        let moves: Vec<Mv> = idx
            .iter()
            .filter_map(|&i| prog.moves.get(i).copied())
            .collect();
        let walls: Vec<Path> = runs(&moves)
            .into_iter()
            .filter(|(_, k)| is_wall(*k))
            .map(|(p, _)| p)
            .collect();
        if walls.is_empty() {
            continue;
        }
        for mv in moves
            .iter()
            .filter(|m| m.kind == Some(FeatureKind::SparseInfill) && m.m.is_extruding())
        {
            let p = [mv.m.to[axis::X], mv.m.to[axis::Y]];
            let d = walls
                .iter()
                .flat_map(|w| w.windows(2).map(move |s| seg_dist(p, s[0], s[1])))
                .fold(f64::INFINITY, f64::min);
            if d < 1.5 {
                samples.push(d);
            }
            if samples.len() >= MAX_SAMPLES {
                break;
            }
        }
        if samples.len() >= MAX_SAMPLES {
            break;
        }
    }
    if samples.len() < 4 {
        return None;
    }
    samples.sort_by(f64::total_cmp);
    samples
        .get(samples.len() / 2)
        .copied()
        .map(|d| d.clamp(0.05, 1.5))
}

/// The region of the layer made of `moves`, with clearance `d`.
pub(crate) fn extract(moves: &[Mv], d: f64) -> Option<LayerRegion> {
    let runs = runs(moves);
    let points: usize = runs.iter().map(|r| r.0.len()).sum();
    if points > MAX_POINTS {
        return None;
    }
    let closed = |want: &dyn Fn(Option<FeatureKind>) -> bool| -> Vec<Path> {
        runs.iter()
            .filter(|(p, k)| want(*k) && is_closed(p))
            .map(|(p, _)| p.clone())
            .collect()
    };
    let outer = closed(&|k| k == Some(FeatureKind::OuterWall));
    let part: Region = if !outer.is_empty() {
        let empty: Vec<Path> = Vec::new();
        flatten(outer.overlay(&empty, OverlayRule::Subject, FillRule::EvenOdd))
    } else {
        let all = closed(&is_wall);
        if all.is_empty() {
            return None;
        }
        let empty: Vec<Path> = Vec::new();
        flatten(all.overlay(&empty, OverlayRule::Subject, FillRule::NonZero))
    };
    if part.is_empty() {
        return None;
    }
    let others: Vec<Path> = runs
        .iter()
        .filter(|(_, k)| *k != Some(FeatureKind::SparseInfill))
        .map(|(p, _)| p.clone())
        .collect();
    let style = StrokeStyle::new(2.0 * d)
        .start_cap(LineCap::Square)
        .end_cap(LineCap::Square);
    let taken = flatten(others.stroke(style, false));
    let r = flatten(part.overlay(&taken, OverlayRule::Difference, FillRule::EvenOdd));
    // Opening: drop slivers narrower than about d.
    let r = flatten(r.outline(&OutlineStyle::new(-0.5 * d)));
    let region: Region = flatten(r.outline(&OutlineStyle::new(0.5 * d)))
        .iter()
        .map(|c| simplify_closed(c, 0.01))
        .collect();
    let area_mm2 = region_area(&region);
    (area_mm2 > 1e-6).then_some(LayerRegion { region, area_mm2 })
}

/// Shapes (outer + holes) to a flat even-odd contour list, dropping degenerate contours.
pub(crate) fn flatten(shapes: Vec<Vec<Path>>) -> Region {
    shapes
        .into_iter()
        .flatten()
        .filter(|c| c.len() >= 3 && c.iter().all(|p| p[0].is_finite() && p[1].is_finite()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::machine::{Move, MoveKind};

    fn mv(a: P2, b: P2, e: f64, kind: FeatureKind) -> Mv {
        let mut from = [0.0; crate::machine::AXES];
        let mut to = [0.0; crate::machine::AXES];
        from[0] = a[0];
        from[1] = a[1];
        to[0] = b[0];
        to[1] = b[1];
        to[3] = e;
        Mv {
            m: Move {
                line: 1,
                kind: MoveKind::Linear,
                from,
                to,
                feed_mm_s: 50.0,
                length_mm: dist(a, b),
            },
            kind: Some(kind),
            names: [true, true],
            layer: 0,
        }
    }

    fn square(c: f64, h: f64, kind: FeatureKind, clockwise: bool) -> Vec<Mv> {
        let mut p = [
            [c - h, c - h],
            [c + h, c - h],
            [c + h, c + h],
            [c - h, c + h],
            [c - h, c - h],
        ];
        if clockwise {
            p.reverse();
        }
        p.windows(2).map(|w| mv(w[0], w[1], 1.0, kind)).collect()
    }

    #[test]
    fn square_part_with_square_hole() {
        let mut moves = square(10.0, 10.0, FeatureKind::OuterWall, false);
        moves.extend(square(10.0, 9.5, FeatureKind::InnerWall, false));
        // A hole: loops the other way round.
        moves.extend(square(10.0, 2.0, FeatureKind::OuterWall, true));
        moves.extend(square(10.0, 2.5, FeatureKind::InnerWall, true));
        let r = extract(&moves, 0.25).expect("region");
        // The inner wall (half-width 9.5) less d = 0.25: an 18.5 mm square; the hole's inner
        // wall (half-width 2.5) plus d: a 5.5 mm square.
        let want = 18.5 * 18.5 - 5.5 * 5.5;
        assert!((r.area_mm2 - want).abs() < 0.5, "{} vs {want}", r.area_mm2);
        assert!(super::super::geom::inside(&r.region, [2.0, 2.0]));
        assert!(!super::super::geom::inside(&r.region, [10.0, 10.0]));
    }
}
