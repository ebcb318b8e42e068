//! Curve patterns: concentric loops, the Hilbert curve, Archimedean chords and the octagram
//! spiral (the PrusaSlicer patterns of the thesis, Table 4). Curves are built over the region's
//! bounding box and clipped to the region with `i_overlay`.

use std::cell::RefCell;
use std::rc::Rc;

use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::OutlineStyle;

use super::super::geom::{bbox, region_area, signed_area, simplify_closed, Path, Region, P2};
use super::super::grid::EdgeGrid;
use super::super::region::flatten;

/// Most points of one generated curve (hostile-input bound).
const MAX_POINTS: usize = 1 << 20;
/// Most concentric loops.
const MAX_LOOPS: usize = 2000;
/// How far a concentric loop may move when its points are thinned, mm: the region's own
/// simplification tolerance, far below a line width.
const LOOP_SIMPLIFY_MM: f64 = 0.01;

/// Clips open polylines to the region (even-odd), keeping the pieces in curve order.
/// The region's edges are bucketed in a grid ([`EdgeGrid`]), so each segment of a curve
/// meets only the few edges near it: linear in the curve's length for any region, where a
/// general clipper sweeps the whole curve against every edge again for every candidate.
pub(crate) fn clip(paths: &[Path], region: &Region) -> Vec<Path> {
    let Some(grid) = EdgeGrid::new(region) else {
        return Vec::new();
    };
    let mut out = Vec::new();
    let mut ts: Vec<f64> = Vec::new();
    for path in paths {
        let mut piece: Path = Vec::new();
        // Whether the last piece of segment looked at was inside: a segment that crosses no
        // edge (not even at its ends) keeps it, so the ray test runs only near crossings.
        let mut state: Option<bool> = None;
        for w in path.windows(2) {
            let (a, b) = (w[0], w[1]);
            if grid.beside(a, b) {
                // Wholly beyond one side of the region's box: outside, and no edge to test
                // (space-filling curves and spirals cover the box's square or circle).
                state = Some(false);
                if piece.len() >= 2 {
                    out.push(std::mem::take(&mut piece));
                } else {
                    piece.clear();
                }
                continue;
            }
            ts.clear();
            ts.push(0.0);
            grid.crossings(a, b, &mut ts);
            ts.push(1.0);
            let crossed = ts.len() > 2;
            ts.sort_by(f64::total_cmp);
            let at = |t: f64| [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])];
            for k in ts.windows(2) {
                if k[1] - k[0] < 1e-12 {
                    continue;
                }
                let (p, q) = (at(k[0]), at(k[1]));
                let inside = match state {
                    Some(v) if !crossed => v,
                    _ => grid.inside(at(0.5 * (k[0] + k[1]))),
                };
                state = Some(inside);
                if inside {
                    if piece.last() != Some(&p) {
                        if piece.len() >= 2 {
                            out.push(std::mem::take(&mut piece));
                        }
                        piece.clear();
                        piece.push(p);
                    }
                    piece.push(q);
                } else if piece.len() >= 2 {
                    out.push(std::mem::take(&mut piece));
                } else {
                    piece.clear();
                }
            }
        }
        if piece.len() >= 2 {
            out.push(piece);
        }
    }
    out
}

/// Concentric loops `spacing` apart, outermost first, each closed (last point = first).
///
/// Every offset is thinned before the next: `i_overlay` bevels each convex vertex into two
/// points, so without it a finely tessellated bore doubled its points at every loop (2,265 →
/// 445,000 points in ten loops on a 16-bore block, minutes per layer).
pub(crate) fn concentric(region: &Region, spacing: f64) -> Vec<Path> {
    let mut out = Vec::new();
    let mut current = region.clone();
    // Stop when what is left is smaller than a line's footprint (offsets of slivers can leave
    // specks that never vanish).
    let min_area = 0.25 * spacing * spacing;
    while region_area(&current) > min_area && out.len() < MAX_LOOPS {
        for c in &current {
            if signed_area(c).abs() < min_area {
                continue;
            }
            let mut p = c.clone();
            if let Some(&f) = p.first() {
                p.push(f);
            }
            out.push(p);
        }
        current = flatten(current.outline(&OutlineStyle::new(-spacing)))
            .iter()
            .map(|c| simplify_closed(c, LOOP_SIMPLIFY_MM))
            .collect();
    }
    out
}

/// `(x, y)` of step `d` along the Hilbert curve of order `n` (the classic d2xy).
fn hilbert_xy(n: u32, mut d: u64) -> (u64, u64) {
    let (mut x, mut y) = (0u64, 0u64);
    let mut s = 1u64;
    while s < (1u64 << n) {
        let rx = 1 & (d / 2);
        let ry = 1 & (d ^ rx);
        if ry == 0 {
            if rx == 1 {
                x = s - 1 - x;
                y = s - 1 - y;
            }
            std::mem::swap(&mut x, &mut y);
        }
        x += s * rx;
        y += s * ry;
        d /= 4;
        s *= 2;
    }
    (x, y)
}

/// The Hilbert curve with cells `spacing` wide, anchored on the bed grid, over the region.
pub(crate) fn hilbert(region: &Region, spacing: f64) -> Vec<Path> {
    let Some(b) = bbox(region.iter().flatten()) else {
        return Vec::new();
    };
    let x0 = (b[0] / spacing).floor() * spacing;
    let y0 = (b[1] / spacing).floor() * spacing;
    let cells = ((b[2] - x0).max(b[3] - y0) / spacing).ceil().max(1.0);
    let mut n = 0u32;
    while ((1u64 << n) as f64) < cells && n < 10 {
        n += 1;
    }
    let count = 1u64 << (2 * n);
    if count as usize > MAX_POINTS {
        return Vec::new();
    }
    let path = HILBERT.with(|last| {
        let mut last = last.borrow_mut();
        let key = (n, x0.to_bits(), y0.to_bits(), spacing.to_bits());
        match last.as_ref() {
            Some((k, path)) if *k == key => path.clone(),
            _ => {
                let path = Rc::new(hilbert_path(n, [x0, y0], spacing));
                *last = Some((key, path.clone()));
                path
            }
        }
    });
    clip(std::slice::from_ref(&*path), region)
}

/// A generated curve's order, anchor (x, y bits) and spacing (bits).
type CurveKey = (u32, u64, u64, u64);

thread_local! {
    /// The last Hilbert curve a thread generated, by (order, anchor, spacing): a search runs
    /// one angle a thread over every layer, and layers with the same extent (a prism's) get
    /// the same curve, so it is made once and clipped to each.
    static HILBERT: RefCell<Option<(CurveKey, Rc<Path>)>> = const { RefCell::new(None) };
}

/// Drops this thread's cached curve when it goes out of scope: the search's own thread (the
/// only one in wasm, where the worker lives on) does not keep a megabyte-sized curve after it.
#[derive(Debug)]
pub(crate) struct CurveCacheScope;

impl Drop for CurveCacheScope {
    fn drop(&mut self) {
        HILBERT.with(|last| last.borrow_mut().take());
    }
}

/// The Hilbert curve of order `n` with cells `spacing` wide from `origin`, cell centres joined.
fn hilbert_path(n: u32, origin: P2, spacing: f64) -> Path {
    let count = 1u64 << (2 * n);
    // Cells in a straight run are one segment: the curve is the same, and the firmware and the
    // cost replay see a third fewer points (a straight step is not a vertex to plan).
    let mut cells: Vec<(u64, u64)> = Vec::with_capacity(count as usize);
    for d in 0..count {
        let c = hilbert_xy(n, d);
        // Steps are one cell along x or y, so a run keeps the signs of its step.
        let dir = |p: (u64, u64), q: (u64, u64)| (q.0.cmp(&p.0), q.1.cmp(&p.1));
        if let [.., a, b] = cells[..] {
            if dir(a, b) == dir(b, c) {
                cells.pop();
            }
        }
        cells.push(c);
    }
    cells
        .into_iter()
        .map(|(x, y)| {
            [
                origin[0] + (x as f64 + 0.5) * spacing,
                origin[1] + (y as f64 + 0.5) * spacing,
            ]
        })
        .collect()
}

/// The Sierpiński curve over the region's bounding square, anchored on the bed grid: the
/// closed space-filling curve Cura's "cross" infill is built on. Right isosceles triangles are
/// halved recursively through the midpoint of their hypotenuse; the curve joins the centroids
/// of the leaves in order. Leaves are about `spacing` apart.
pub(crate) fn sierpinski(region: &Region, spacing: f64) -> Vec<Path> {
    let Some(b) = bbox(region.iter().flatten()) else {
        return Vec::new();
    };
    let side0 = 2.0 * spacing;
    let x0 = (b[0] / side0).floor() * side0;
    let y0 = (b[1] / side0).floor() * side0;
    let mut side = side0;
    let mut depth = 2u32;
    while side < (b[2] - x0).max(b[3] - y0) && depth < 36 {
        side *= 2.0;
        depth += 2;
    }
    if (1usize << depth.min(40)) > MAX_POINTS {
        return Vec::new();
    }
    fn tri(a: P2, b: P2, c: P2, depth: u32, out: &mut Path) {
        if depth == 0 {
            out.push([(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0]);
            return;
        }
        let m = [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])];
        tri(a, c, m, depth - 1, out);
        tri(c, b, m, depth - 1, out);
    }
    let (p0, p1, p2, p3) = (
        [x0, y0],
        [x0 + side, y0],
        [x0 + side, y0 + side],
        [x0, y0 + side],
    );
    let mut path = Path::new();
    tri(p0, p2, p1, depth - 1, &mut path);
    tri(p2, p0, p3, depth - 1, &mut path);
    if let Some(&f) = path.first() {
        path.push(f);
    }
    clip(&[path], region)
}

/// A spiral about the region's centre growing by `spacing` per turn; `star` > 0 makes each
/// turn an eight-pointed star (inner vertices at `1 − star` of the radius).
fn spiral(region: &Region, spacing: f64, per_turn: usize, star: f64) -> Vec<Path> {
    let Some(b) = bbox(region.iter().flatten()) else {
        return Vec::new();
    };
    let c: P2 = [0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3])];
    let r_max = 0.5 * crate::math::hypot(b[2] - b[0], b[3] - b[1]) / (1.0 - star).max(0.2);
    let turns = (r_max / spacing).ceil();
    let total = (turns * per_turn as f64) as usize;
    if total > MAX_POINTS || total == 0 {
        return Vec::new();
    }
    let path: Path = (0..=total)
        .map(|i| {
            let t = i as f64 / per_turn as f64;
            let a = t * std::f64::consts::TAU;
            let k = if star > 0.0 && i % 2 == 1 {
                1.0 - star
            } else {
                1.0
            };
            let r = spacing * t * k;
            [
                c[0] + r * crate::math::cos(a),
                c[1] + r * crate::math::sin(a),
            ]
        })
        .collect();
    clip(&[path], region)
}

/// Largest gap between the Archimedean spiral and its chords, mm (a fortieth of a line width:
/// the chords are the curve as far as the print can tell).
const SPIRAL_CHORD_ERROR_MM: f64 = 0.0125;

/// Archimedean chords: the spiral `r = S·θ/2π` about the region's centre, drawn with chords
/// whose sagitta stays within [`SPIRAL_CHORD_ERROR_MM`] (`Δθ = 2·acos(1 − ε/r)`, at least 12
/// chords a turn), as PrusaSlicer bounds its discretisation by a resolution. Chords of one
/// angular step at every radius would put thousands of sub-micron chords in the inner turns
/// (a 230 mm part: 390,000 points a layer, against about 40,000 this way).
pub(crate) fn archimedean(region: &Region, spacing: f64) -> Vec<Path> {
    let Some(b) = bbox(region.iter().flatten()) else {
        return Vec::new();
    };
    let c: P2 = [0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3])];
    let r_max = 0.5 * crate::math::hypot(b[2] - b[0], b[3] - b[1]);
    let most_step = std::f64::consts::TAU / 12.0;
    let mut path = Path::new();
    let mut theta = 0.0f64;
    loop {
        let r = spacing * theta / std::f64::consts::TAU;
        path.push([
            c[0] + r * crate::math::cos(theta),
            c[1] + r * crate::math::sin(theta),
        ]);
        if r > r_max || path.len() > MAX_POINTS || !r.is_finite() {
            break;
        }
        let ratio = (SPIRAL_CHORD_ERROR_MM / r.max(1e-9)).min(1.0);
        theta += (2.0 * (1.0 - ratio).acos()).min(most_step);
    }
    if path.len() > MAX_POINTS {
        return Vec::new();
    }
    clip(&[path], region)
}

/// Octagram spiral: each turn an eight-pointed star (16 vertices), growing by `S` per turn.
pub(crate) fn octagram(region: &Region, spacing: f64) -> Vec<Path> {
    spiral(region, spacing, 16, 0.35)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::infill::geom::path_len;

    fn square() -> Region {
        vec![vec![[0.0, 0.0], [20.0, 0.0], [20.0, 20.0], [0.0, 20.0]]]
    }

    #[test]
    fn the_cached_curve_is_the_one_generated_and_dropped_with_its_scope() {
        let cached = || HILBERT.with(|c| c.borrow().is_some());
        let scope = CurveCacheScope;
        let first = hilbert(&square(), 1.0);
        assert!(cached());
        // A region of the same extent with a hole (the same key, so the cached curve) is
        // clipped afresh: shorter than the square's, and the square's comes back unchanged.
        let mut holed = square();
        holed.push(vec![[5.0, 5.0], [5.0, 15.0], [15.0, 15.0], [15.0, 5.0]]);
        let again: f64 = hilbert(&holed, 1.0).iter().map(|p| path_len(p)).sum();
        let whole: f64 = first.iter().map(|p| path_len(p)).sum();
        assert!(again < whole && again > 0.5 * whole, "{again} of {whole}");
        assert_eq!(hilbert(&square(), 1.0), first);
        drop(scope);
        assert!(!cached());
    }

    /// A 60 mm square with a bore drawn as a 360-gon, as slicers tessellate holes.
    fn bored_square() -> Region {
        let bore: Path = (0..360)
            .rev()
            .map(|k| {
                let t = (k as f64).to_radians();
                [30.0 + 8.0 * t.cos(), 30.0 + 8.0 * t.sin()]
            })
            .collect();
        vec![
            vec![[0.0, 0.0], [60.0, 0.0], [60.0, 60.0], [0.0, 60.0]],
            bore,
        ]
    }

    #[test]
    fn concentric_loops_keep_their_point_count_and_spacing() {
        let loops = concentric(&bored_square(), 0.5);
        // About 22 mm from the bore to the square's edge at 0.5 mm: one loop round the bore
        // per step and one inside the square, until the two meet.
        assert!(loops.len() > 40, "{} loops", loops.len());
        let most = loops.iter().map(Vec::len).max().unwrap_or(0);
        assert!(most <= 2 * 365, "a loop of {most} points");
        // The bore's first loop is a circle of radius 8.5 (half a spacing out would be 8.25).
        let first_bore = loops.iter().find(|l| l.len() > 100).expect("a bore loop");
        for p in first_bore {
            let r = ((p[0] - 30.0).powi(2) + (p[1] - 30.0).powi(2)).sqrt();
            assert!(
                (r - 8.0).abs() < 0.02 || (r - 8.5).abs() < 0.02,
                "radius {r}"
            );
        }
    }

    #[test]
    fn archimedean_chords_stay_within_their_error_and_few() {
        let (s, half) = (0.6, 100.0);
        let region = vec![vec![
            [0.0, 0.0],
            [2.0 * half, 0.0],
            [2.0 * half, 2.0 * half],
            [0.0, 2.0 * half],
        ]];
        let pieces = archimedean(&region, s);
        let points: usize = pieces.iter().map(Vec::len).sum();
        // Sagitta-bounded chords: about 2π/(S·√(8ε))·(2/3)·R^1.5 ≈ 37,000 points over the
        // 141 mm half-diagonal; one step per 1/4096 turn would be 970,000.
        assert!(points > 10_000 && points < 50_000, "{points} points");
        let mut checked = 0;
        for w in pieces.iter().flat_map(|p| p.windows(2)) {
            let r = |p: P2| ((p[0] - half).powi(2) + (p[1] - half).powi(2)).sqrt();
            // Clipped by the square, or in the first turn, where the radius grows by a
            // large part of itself per chord and the circle's sagitta is no measure.
            if r(w[0]) > half - 1.0 || r(w[1]) > half - 1.0 || r(w[0]) < 1.0 {
                continue;
            }
            // r = S·θ/2π fixes each end's angle; the spiral half-way between them is where the
            // chord is farthest from it.
            let th = std::f64::consts::PI * (r(w[0]) + r(w[1])) / s;
            let rm = s * th / std::f64::consts::TAU;
            let on = [half + rm * th.cos(), half + rm * th.sin()];
            let mid = [0.5 * (w[0][0] + w[1][0]), 0.5 * (w[0][1] + w[1][1])];
            let gap = ((on[0] - mid[0]).powi(2) + (on[1] - mid[1]).powi(2)).sqrt();
            assert!(
                gap <= 1.1 * SPIRAL_CHORD_ERROR_MM,
                "chord {w:?} {gap} mm off the spiral"
            );
            checked += 1;
        }
        assert!(checked > 5_000, "{checked} chords");
    }

    #[test]
    fn hilbert_has_no_straight_through_vertex() {
        let pieces = hilbert(&square(), 0.5);
        let len: f64 = pieces.iter().map(|p| path_len(p)).sum();
        // 64 × 64 cells of 0.5 mm (the 20 mm square sits in 32 mm of curve): inside the
        // square about 40 × 40 steps of 0.5 mm.
        assert!((len - 1600.0 * 0.5).abs() < 60.0, "{len} mm");
        for p in &pieces {
            for w in p.windows(3) {
                let (u, v) = (
                    [w[1][0] - w[0][0], w[1][1] - w[0][1]],
                    [w[2][0] - w[1][0], w[2][1] - w[1][1]],
                );
                let cross = u[0] * v[1] - u[1] * v[0];
                let dot = u[0] * v[0] + u[1] * v[1];
                assert!(
                    cross.abs() > 1e-9 || dot < 0.0,
                    "straight vertex at {:?}",
                    w[1]
                );
            }
        }
    }

    #[test]
    fn hilbert_visits_cells_once() {
        let n = 3;
        let mut seen = std::collections::HashSet::new();
        for d in 0..64 {
            assert!(seen.insert(hilbert_xy(n, d)));
        }
        let pieces = hilbert(&square(), 2.0);
        let len: f64 = pieces.iter().map(|p| path_len(p)).sum();
        // 100 cells of 2 mm: about 99 steps of 2 mm inside.
        assert!((len - 198.0).abs() < 10.0, "{len}");
    }

    #[test]
    fn concentric_and_spirals_fill_about_area_over_spacing() {
        for (name, f) in [
            ("concentric", concentric as fn(&Region, f64) -> Vec<Path>),
            ("archimedean", archimedean),
            ("octagram", octagram),
            ("sierpinski", sierpinski),
        ] {
            let len: f64 = f(&square(), 2.0).iter().map(|p| path_len(p)).sum();
            assert!(len > 100.0 && len < 400.0, "{name}: {len}");
        }
    }
}
