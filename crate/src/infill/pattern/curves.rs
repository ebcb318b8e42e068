//! Curve patterns: concentric loops, the Hilbert curve, Archimedean chords and the octagram
//! spiral (the PrusaSlicer patterns of the thesis, Table 4). Curves are built over the region's
//! bounding box and clipped to the region with `i_overlay`.

use i_overlay::core::fill_rule::FillRule;
use i_overlay::float::clip::FloatClip;
use i_overlay::mesh::float::outline::offset::OutlineOffset;
use i_overlay::mesh::float::style::OutlineStyle;
use i_overlay::string::clip::ClipRule;

use super::super::geom::{bbox, region_area, signed_area, Path, Region, P2};
use super::super::region::flatten;

/// Most points of one generated curve (hostile-input bound).
const MAX_POINTS: usize = 1 << 20;
/// Most concentric loops.
const MAX_LOOPS: usize = 2000;

/// Clips open polylines to the region (even-odd), keeping the pieces in curve order.
pub(crate) fn clip(paths: &[Path], region: &Region) -> Vec<Path> {
    let rule = ClipRule {
        invert: false,
        boundary_included: true,
    };
    paths.clip_by(region, FillRule::EvenOdd, rule)
}

/// Concentric loops `spacing` apart, outermost first, each closed (last point = first).
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
        current = flatten(current.outline(&OutlineStyle::new(-spacing)));
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
    let path: Path = (0..count)
        .map(|d| {
            let (x, y) = hilbert_xy(n, d);
            [
                x0 + (x as f64 + 0.5) * spacing,
                y0 + (y as f64 + 0.5) * spacing,
            ]
        })
        .collect();
    clip(&[path], region)
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

/// Archimedean chords: the spiral `r = S·θ/2π` drawn with chords of about `S` (PrusaSlicer
/// draws it with short chords too).
pub(crate) fn archimedean(region: &Region, spacing: f64) -> Vec<Path> {
    let Some(b) = bbox(region.iter().flatten()) else {
        return Vec::new();
    };
    let r_max = 0.5 * crate::math::hypot(b[2] - b[0], b[3] - b[1]);
    // Chords of about one spacing at the outer turns, at least 12 per turn.
    let per_turn = ((std::f64::consts::TAU * r_max / spacing).ceil() as usize).clamp(12, 4096);
    spiral(region, spacing, per_turn, 0.0)
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
