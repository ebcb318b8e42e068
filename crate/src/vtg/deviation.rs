//! Measuring how far a rewritten path strays from the original, independently of the
//! optimiser: only the two polylines are used (never the fitted curve or its parameters).
//!
//! Each output segment is sampled every `step` mm and every sample's distance to the original
//! polyline is taken; the largest is the deviation (up to `step/2` optimistic on a segment that
//! crosses a corner, so `step` is a small fraction of the tolerance).

use std::collections::HashMap;

use crate::path::{PathMove, PrintPath};
use crate::vec3::{dot, lerp, norm, sub};

/// Distance from `p` to segment `a`–`b`.
pub(crate) fn point_segment(p: &[f64; 3], a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let ab = sub(b, a);
    let ap = sub(p, a);
    let l2 = dot(ab, ab);
    let t = if l2 > 0.0 {
        (dot(ap, ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm(sub(p, lerp(a, b, t)))
}

/// Distance from `p` to the polyline `poly`.
pub(crate) fn point_polyline(p: &[f64; 3], poly: &[[f64; 3]]) -> f64 {
    match poly {
        [] => f64::INFINITY,
        [a] => norm(sub(p, a)),
        _ => poly
            .windows(2)
            .map(|w| point_segment(p, &w[0], &w[1]))
            .fold(f64::INFINITY, f64::min),
    }
}

/// Calls `each` with points along every segment of `poly`, at most `step` apart.
fn samples(poly: &[[f64; 3]], step: f64, mut each: impl FnMut(&[f64; 3])) {
    if let Some(p) = poly.first() {
        each(p);
    }
    for w in poly.windows(2) {
        let len = norm(sub(w[1], w[0]));
        let k = ((len / step).ceil() as usize).clamp(1, 100_000);
        for i in 1..=k {
            each(&lerp(w[0], w[1], i as f64 / k as f64));
        }
    }
}

/// An upper bound of the largest distance from the polyline `out` to the polyline `orig`
/// (exact to within `step/2`).
///
/// Distance to one segment is convex along a straight line, so an output segment whose two ends
/// are both within `d` of the *same* original segment lies wholly within `d` of it: such
/// segments are certified from their ends alone. Others (those that cut across a corner) are
/// sampled every `step` mm, and `step/2` is added to what the samples show. Certificates up to
/// `accept` mm are taken as they are (they are upper bounds); set it to the tolerance to check
/// against, or to 0 for the tightest figure. With `accept > 0` the measurement stops as soon as
/// it exceeds `accept`.
pub(crate) fn polyline_deviation(
    out: &[[f64; 3]],
    orig: &[[f64; 3]],
    step: f64,
    accept: f64,
) -> f64 {
    let segs = orig.len().saturating_sub(1);
    if segs == 0 {
        return match (out.is_empty(), orig.first()) {
            (true, _) => 0.0,
            (false, Some(o)) => out.iter().map(|p| norm(sub(p, o))).fold(0.0, f64::max),
            (false, None) => f64::INFINITY,
        };
    }
    deviation_from_segments(out, &Segments::new(orig).0, step, accept)
}

/// [`polyline_deviation`] from `out` to an original of at least one segment, prepared once
/// ([`Segments`]): a caller that measures many short pieces against stretches of one
/// original (the thinning's joins) prepares it once and passes a slice of it.
pub(crate) fn deviation_from_segments(
    out: &[[f64; 3]],
    segments: &[Segment],
    step: f64,
    accept: f64,
) -> f64 {
    if segments.is_empty() {
        return f64::INFINITY;
    }
    let o = Original { segments };
    let mut worst = 0.0f64;
    let mut cursor = 0usize;
    let mut prev: Option<([f64; 3], usize, f64)> = None;
    for p in out {
        let (mut j, mut d) = o.nearest(p, cursor);
        if d > worst.max(step).max(accept) {
            (j, d) = o.nearest_anywhere(p);
        }
        cursor = j;
        if let Some((q, jq, dq)) = prev {
            // Certificate: both ends near one segment (either end's nearest).
            let c1 = dq.max(o.seg_dist(p, jq));
            let c2 = o.seg_dist(&q, j).max(d);
            let cert = c1.min(c2);
            let bound = if cert <= worst.max(step).max(accept) {
                cert
            } else {
                cert.min(o.walk(&q, p, jq, step, accept))
            };
            worst = worst.max(bound);
            if accept > 0.0 && worst > accept {
                // Over the line: the caller only needs to know that.
                return worst;
            }
        } else {
            worst = worst.max(d);
        }
        prev = Some((*p, j, d));
    }
    worst
}

/// The original polyline of [`polyline_deviation`] (at least one segment), with the nearest-
/// segment searches its measurement is made of. Each segment's start, direction and inverse
/// squared length are computed once: a measurement asks for the distance to each original
/// segment a dozen times or more, and the searches compare squared distances, taking one
/// square root for the nearest (this was a seventh of `vtg`'s time on the 34 MB corpus file).
struct Original<'s> {
    /// At least one.
    segments: &'s [Segment],
}

/// A polyline's segments, prepared for [`deviation_from_segments`]: segment `j` runs from
/// point `j` to point `j + 1`.
#[derive(Debug, Clone, Default)]
pub(crate) struct Segments(pub(crate) Vec<Segment>);

impl Segments {
    pub(crate) fn new(poly: &[[f64; 3]]) -> Self {
        Segments(
            poly.windows(2)
                .map(|w| {
                    let d = sub(w[1], w[0]);
                    let l2 = dot(d, d);
                    Segment {
                        a: w[0],
                        d,
                        inv: if l2 > 0.0 { 1.0 / l2 } else { 0.0 },
                    }
                })
                .collect(),
        )
    }
}

/// A segment `a`–`a + d`, with `1 / |d|²` (0 for a point).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Segment {
    a: [f64; 3],
    d: [f64; 3],
    inv: f64,
}

impl Segment {
    /// The largest `s` at which the line `q + s·u` (`u` a unit vector) lies within `r` of the
    /// segment, `None` where it never does. The points within `r` form a capsule, which is
    /// convex: the line crosses it in one interval, whose far end is the farthest of the far
    /// ends of its crossings of the two end spheres and of the cylinder between them.
    fn capsule_exit(&self, q: &[f64; 3], u: &[f64; 3], r: f64) -> Option<f64> {
        let r2 = r * r;
        let mut exit: Option<f64> = None;
        let mut farther = |s: f64| exit = Some(exit.map_or(s, |e: f64| e.max(s)));
        let b_end = [
            self.a[0] + self.d[0],
            self.a[1] + self.d[1],
            self.a[2] + self.d[2],
        ];
        for centre in [self.a, b_end] {
            let w = sub(q, centre);
            let (b, c) = (dot(u, w), dot(w, w) - r2);
            let disc = b * b - c;
            if disc >= 0.0 {
                farther(-b + disc.sqrt());
            }
        }
        if self.inv > 0.0 {
            if let Some(s) = self.cylinder_exit(q, u, r2) {
                farther(s);
            }
        }
        exit.filter(|s| s.is_finite())
    }

    /// The far end of the line `q + s·u`'s crossing of the cylinder of squared radius `r2`
    /// round the segment, between the planes through its ends; `None` where it misses it.
    fn cylinder_exit(&self, q: &[f64; 3], u: &[f64; 3], r2: f64) -> Option<f64> {
        let w = sub(q, self.a);
        // The projection onto the segment, τ(s) = τ0 + s τ1 (0 and 1 at its ends), and the
        // part of the line across it, e0 + s e1.
        let (tau0, tau1) = (dot(w, self.d) * self.inv, dot(u, self.d) * self.inv);
        let e0: [f64; 3] = std::array::from_fn(|k| w[k] - tau0 * self.d[k]);
        let e1: [f64; 3] = std::array::from_fn(|k| u[k] - tau1 * self.d[k]);
        let (a, b, c) = (dot(e1, e1), dot(e0, e1), dot(e0, e0) - r2);
        let (mut lo, mut hi) = if a > 1e-18 {
            let disc = b * b - a * c;
            if disc < 0.0 {
                return None;
            }
            let root = disc.sqrt();
            ((-b - root) / a, (-b + root) / a)
        } else if c <= 0.0 {
            // Along the segment, inside the cylinder all the way.
            (f64::NEG_INFINITY, f64::INFINITY)
        } else {
            return None;
        };
        if tau1 != 0.0 {
            let (s0, s1) = (-tau0 / tau1, (1.0 - tau0) / tau1);
            lo = lo.max(s0.min(s1));
            hi = hi.min(s0.max(s1));
        } else if !(0.0..=1.0).contains(&tau0) {
            return None;
        }
        (lo <= hi).then_some(hi)
    }

    /// Squared distance from `p`.
    #[inline]
    fn distance_sq(&self, p: &[f64; 3]) -> f64 {
        let ap = sub(p, self.a);
        let t = (dot(ap, self.d) * self.inv).clamp(0.0, 1.0);
        let q = [
            ap[0] - self.d[0] * t,
            ap[1] - self.d[1] * t,
            ap[2] - self.d[2] * t,
        ];
        dot(q, q)
    }
}

impl Original<'_> {
    /// Distance from `p` to segment `j`.
    fn seg_dist(&self, p: &[f64; 3], j: usize) -> f64 {
        self.segments[j].distance_sq(p).sqrt()
    }

    /// The nearest of segments `range` to `p` (the first of equals) and its distance.
    #[inline]
    fn nearest_in(
        &self,
        p: &[f64; 3],
        range: std::ops::Range<usize>,
        first: usize,
    ) -> (usize, f64) {
        let mut best = (first, f64::INFINITY);
        let start = range.start;
        for (j, s) in self.segments.get(range).unwrap_or(&[]).iter().enumerate() {
            let d = s.distance_sq(p);
            if d < best.1 {
                best = (start + j, d);
            }
        }
        (best.0, best.1.sqrt())
    }

    /// Nearest original segment to `p`, searched around `cursor` first, then everywhere.
    fn nearest(&self, p: &[f64; 3], cursor: usize) -> (usize, f64) {
        const WINDOW: usize = 6;
        let segs = self.segments.len();
        let lo = cursor.saturating_sub(WINDOW);
        let hi = (cursor + WINDOW).min(segs - 1);
        self.nearest_in(p, lo..hi + 1, cursor.min(segs - 1))
    }

    /// Nearest segment over the whole polyline: where the window has lost track (the other
    /// polyline is much denser here, or doubles back), it puts the cursor back.
    fn nearest_anywhere(&self, p: &[f64; 3]) -> (usize, f64) {
        self.nearest_in(p, 0..self.segments.len(), 0)
    }

    /// The largest distance along the output segment `q`–`p` (`q` nearest segment `jq`), by
    /// walking it. Distance is 1-Lipschitz, so from a point at distance d the next
    /// `accept − d` mm cannot exceed `accept`: the walk strides there and steps `step` mm only
    /// where the segment comes close to the limit.
    fn walk(&self, q: &[f64; 3], p: &[f64; 3], jq: usize, step: f64, accept: f64) -> f64 {
        let len = norm(sub(p, q));
        let mut m = 0.0f64;
        let mut t = 0.0f64;
        let mut c = jq;
        let mut guard = 0usize;
        loop {
            let f = if len > 0.0 { (t / len).min(1.0) } else { 1.0 };
            let x = lerp(q, p, f);
            let (mut jj, mut dx) = self.nearest(&x, c);
            if dx > m.max(accept) {
                (jj, dx) = self.nearest_anywhere(&x);
            }
            c = jj;
            m = m.max(dx);
            guard += 1;
            if f >= 1.0 || guard > 1_000_000 {
                break;
            }
            let stride = t + step.max(accept - dx);
            t = if accept > 0.0 && dx <= accept {
                stride.max(self.within_along(q, p, t, jj, accept, step))
            } else {
                stride
            };
        }
        if accept > 0.0 {
            m
        } else {
            m + step / 2.0
        }
    }

    /// How far along the output segment `q`–`p` from `t` (a point within
    /// `accept` of original segment `j`) it provably stays within `accept` of that segment, to
    /// within `step` mm: distance to a segment is convex along a straight line, so two points
    /// within `accept` of it enclose only such points. The walk strides there at once, instead
    /// of `accept` at a time: an original straight of 20 mm beside a densely walked new path
    /// took 200 nearest-segment searches.
    fn within_along(
        &self,
        q: &[f64; 3],
        p: &[f64; 3],
        t: f64,
        j: usize,
        accept: f64,
        step: f64,
    ) -> f64 {
        let len = norm(sub(p, q));
        let at = |s: f64| self.seg_dist(&lerp(q, p, (s / len).min(1.0)), j);
        if len <= 0.0 || at(len) <= accept {
            return len;
        }
        // Where the line leaves the capsule round segment `j`, in closed form; the
        // halvings below only where rounding puts that point a hair outside.
        let dir = sub(p, q).map(|x| x / len);
        let exit = self.segments[j].capsule_exit(q, &dir, accept);
        let (mut lo, mut hi) = (t, len);
        if let Some(s) = exit.filter(|&s| s > t && s < len) {
            // Exactly at the capsule, rounding falls either side: a thousandth of a step back
            // is inside.
            if let Some(inside) = [s, s - 1e-3 * step].into_iter().find(|&x| at(x) <= accept) {
                return inside.max(t);
            }
            hi = s;
        }
        // At most 64 halvings: a step of 0 (or below the numbers' resolution) ends there.
        for _ in 0..64 {
            if hi - lo <= step {
                break;
            }
            let mid = 0.5 * (lo + hi);
            if at(mid) <= accept {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }
}

/// Segments bucketed by 2-D cell (XY) for nearest-segment queries.
struct Grid {
    cell: f64,
    segs: Vec<([f64; 3], [f64; 3])>,
    cells: HashMap<(i64, i64), Vec<u32>>,
}

impl Grid {
    fn new(segs: impl Iterator<Item = ([f64; 3], [f64; 3])>, cell: f64) -> Self {
        let mut g = Grid {
            cell,
            segs: Vec::new(),
            cells: HashMap::new(),
        };
        for (a, b) in segs {
            let i = g.segs.len() as u32;
            g.segs.push((a, b));
            let len = norm(sub(b, a));
            let k = ((len / (0.5 * cell)).ceil() as usize).clamp(1, 1_000_000);
            let mut last = None;
            for j in 0..=k {
                let t = j as f64 / k as f64;
                let key = g.key(&[a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, 0.0]);
                if last != Some(key) {
                    let v = g.cells.entry(key).or_default();
                    if v.last() != Some(&i) {
                        v.push(i);
                    }
                    last = Some(key);
                }
            }
        }
        g
    }

    fn key(&self, p: &[f64; 3]) -> (i64, i64) {
        (
            (p[0] / self.cell).floor() as i64,
            (p[1] / self.cell).floor() as i64,
        )
    }

    /// Distance to the nearest segment if one lies within one cell (exact then), else `None`.
    fn distance(&self, p: &[f64; 3]) -> Option<f64> {
        let (cx, cy) = self.key(p);
        let mut best = f64::INFINITY;
        for dx in -1..=1 {
            for dy in -1..=1 {
                if let Some(v) = self.cells.get(&(cx + dx, cy + dy)) {
                    for &i in v {
                        if let Some((a, b)) = self.segs.get(i as usize) {
                            best = best.min(point_segment(p, a, b));
                        }
                    }
                }
            }
        }
        (best <= self.cell).then_some(best)
    }
}

/// The larger of [`polyline_deviation`] from `a` to `b` and from `b` to `a`: `a` stays near
/// `b`, and `b` is covered by `a` (a path that cuts a corner short fails the second).
pub(crate) fn both_ways(a: &[[f64; 3]], b: &[[f64; 3]], step: f64, accept: f64) -> f64 {
    polyline_deviation(a, b, step, accept).max(polyline_deviation(b, a, step, accept))
}

/// Largest distance from any printing move of `output` to the printing moves of the same layer
/// of `original`, sampled every `step` mm: the whole-file check, reading both files as moves
/// (nothing of the optimiser is used). Moves identical in both are skipped cheaply by the grid
/// (their distance is 0). Layers are matched by index; if the counts differ, `INFINITY`.
pub fn file_deviation(original: &PrintPath, output: &PrintPath, step: f64) -> f64 {
    if original.layers.len() != output.layers.len() {
        return f64::INFINITY;
    }
    let xyz = |p: &crate::machine::Pos| [p[0], p[1], p[2]];
    let mut worst = 0.0f64;
    for li in 0..original.layers.len() {
        let mut orig: Vec<([f64; 3], [f64; 3])> = Vec::new();
        for m in original.layer_moves(li).iter().filter(|m| m.is_extruding()) {
            match arc_points(m, step) {
                Some(pts) => orig.extend(pts.windows(2).map(|w| (w[0], w[1]))),
                None => orig.push((xyz(&m.from), xyz(&m.to))),
            }
        }
        let grid = Grid::new(orig.iter().copied(), 1.0);
        let mut measure = |seg: &[[f64; 3]]| {
            samples(seg, step, |p| {
                let d = grid.distance(p).unwrap_or_else(|| {
                    orig.iter()
                        .map(|(a, b)| point_segment(p, a, b))
                        .fold(f64::INFINITY, f64::min)
                });
                worst = worst.max(d);
            });
        };
        for m in output.layer_moves(li).iter().filter(|m| m.is_extruding()) {
            match arc_points(m, step) {
                Some(pts) => measure(&pts),
                None => measure(&[xyz(&m.from), xyz(&m.to)]),
            }
        }
    }
    worst
}

/// Points along an arc move (`G2`/`G3`) from its start to its end, the chords between them
/// within `step / 10` of the arc; `None` for any other move.
pub(crate) fn arc_points(m: &PathMove, step: f64) -> Option<Vec<[f64; 3]>> {
    let a = m.kind.arc()?;
    let (i, j, k) = a.plane.axes();
    let rise = m.to[k] - m.from[k];
    let n = a.chords_within(0.1 * step);
    Some(
        (0..=n)
            .map(|s| {
                let t = s as f64 / n as f64;
                let o = a.offset_at(t);
                let mut p = [m.from[0], m.from[1], m.from[2]];
                p[i] += o[0];
                p[j] += o[1];
                p[k] += rise * t;
                p
            })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_line_leaves_the_capsule_round_a_segment_where_a_fine_scan_finds_it() {
        // Lines through a segment's capsule at many angles and offsets, the exit checked
        // against a scan in 1e-5 mm steps (the distance is convex along the line).
        let seg = Segments::new(&[[0.0, 0.0, 0.0], [2.0, 0.5, 0.0]]).0[0];
        let r = 0.1;
        let mut checked = 0;
        for i in 0..40 {
            let angle = i as f64 * 0.157;
            let u = [angle.cos(), angle.sin(), 0.0];
            for k in 0..15 {
                // Along the segment and past its ends, either side of it.
                let (tau, off) = (-0.04 + 0.08 * k as f64, 0.09 * (k as f64 * 0.7).sin());
                let q = [
                    2.0 * tau - 0.5 * off / 2.06,
                    0.5 * tau + 2.0 * off / 2.06,
                    0.0,
                ];
                let dist = |s: f64| {
                    seg.distance_sq(&[q[0] + s * u[0], q[1] + s * u[1], 0.0])
                        .sqrt()
                };
                if dist(0.0) > r {
                    continue;
                }
                let mut s = 0.0;
                while dist(s + 1e-5) <= r && s < 10.0 {
                    s += 1e-5;
                }
                let exit = seg.capsule_exit(&q, &u, r).expect("q is inside");
                assert!(
                    (exit - s).abs() < 2e-5,
                    "angle {angle} q {q:?}: {exit} vs {s}"
                );
                checked += 1;
            }
        }
        assert!(checked > 400, "{checked}");
        // A line that passes by misses it.
        assert_eq!(
            seg.capsule_exit(&[0.0, 1.0, 0.0], &[1.0, 0.0, 0.0], r),
            None
        );
    }

    #[test]
    fn chord_across_a_corner_deviates_by_its_depth() {
        let orig = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]];
        let out = [
            [0.0, 0.0, 0.0],
            [0.9, 0.0, 0.0],
            [1.0, 0.1, 0.0],
            [1.0, 1.0, 0.0],
        ];
        let d = polyline_deviation(&out, &orig, 0.001, 0.0);
        // The chord's midpoint is 0.05 from both legs.
        let depth = 0.05;
        assert!((d - depth).abs() < 1e-3, "{d}");
    }

    #[test]
    fn a_long_original_straight_is_judged_as_the_tight_measurement_judges_it() {
        // A 20 mm straight against a new path that follows it in 0.05 mm steps and bulges
        // out by `h` over 1 mm in the middle: the straight's far side, walked from the new
        // path's segments, must be rejected exactly where the tight figure exceeds `accept`.
        let accept = 0.1;
        for h in [0.0, 0.05, 0.09, 0.099, 0.101, 0.11, 0.3] {
            let new: Vec<[f64; 3]> = (0..=400)
                .map(|i| {
                    let x = i as f64 * 0.05;
                    let y = if (9.5..=10.5).contains(&x) { h } else { 0.0 };
                    [x, y, 0.2]
                })
                .collect();
            let straight = [[0.0, 0.0, 0.2], [20.0, 0.0, 0.2]];
            let tight = both_ways(&straight, &new, 1e-4, 0.0);
            let judged = both_ways(&straight, &new, accept / 10.0, accept);
            assert!((tight - h).abs() < 1e-3, "h {h}: tight {tight}");
            assert_eq!(judged > accept, h > accept, "h {h}: judged {judged}");
            assert!(judged <= tight + 1e-9, "h {h}: {judged} > {tight}");
        }
    }

    #[test]
    fn an_arc_is_measured_along_the_arc_not_its_chord() {
        // A half circle of radius 5 (G3 from (0,0) to (10,0), centre (5,0), through (5,-5)) and, in the other
        // file, its chord: 5 mm apart at the middle, where a chord-only reading sees 0.
        let arc = "G1 X0 Y0 Z0.2 F3000\nG3 X10 Y0 I5 J0 E1\n";
        let chord = "G1 X0 Y0 Z0.2 F3000\nG1 X10 Y0 E1\n";
        let options = crate::analyze::AnalyzeOptions::default();
        let read = |g: &str| crate::path::extract(g.as_bytes(), &options, false).unwrap();
        let (a, c) = (read(arc), read(chord));
        let d = file_deviation(&c, &a, 0.01);
        assert!((d - 5.0).abs() < 0.01, "{d}");
        assert!(file_deviation(&a, &a, 0.01) < 1e-9);
        let pts = arc_points(&a.moves[1], 0.01).unwrap();
        for p in &pts {
            let r = ((p[0] - 5.0).powi(2) + p[1].powi(2)).sqrt();
            assert!((r - 5.0).abs() < 1e-9 && p[1] <= 1e-9, "{p:?}");
        }
    }
}
