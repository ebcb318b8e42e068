//! Arcs (`G2`/`G3`) in place of runs of rewritten points that lie on one circle (the issue's
//! optional step: fewer lines for the same path).
//!
//! A rounded corner is walked in steps that each turn less than δθ, so a 90° fillet becomes four
//! or more `G1` lines, and the rewritten file has several times the original's lines. Where a
//! run of at least [`MIN_SEGMENTS`] steps lies on a circle within a small share of the
//! tolerance, turning one way, in one plane of constant Z and at (nearly) one feed rate, it is
//! written as one arc instead. The firmware cuts the arc back into short segments itself
//! (Marlin's `plan_arc`, Klipper's `[gcode_arcs]`), so the motion is the same; the file and the
//! serial link carry one line where they carried several (a printer fed over USB at 115 200
//! baud can starve its planner on dense `G1` runs).
//!
//! Arcs are off by default: not every firmware has them (Marlin's `ARC_SUPPORT`, Klipper's
//! `[gcode_arcs]` section). The rewriter measures the path with its arcs against the original
//! before it keeps them ([`crate::vtg::deviation::both_ways`]), so the tolerance holds as before.

use crate::gcode::number::rounded;
use crate::machine::{Arc, Plane};
use crate::vec3::{norm, sub};
use crate::vtg::tuning::TUNING;

/// Fewest steps an arc replaces: below that the file gains little.
pub(crate) const MIN_SEGMENTS: usize = 3;
/// Most steps one arc replaces (bounds the search).
const MAX_SEGMENTS: usize = 256;
/// Largest sweep of one arc, rad: a half turn, a hairpin's. `I`/`J` place the centre and
/// `G2`/`G3` the direction, so where rounding moves the centre a little off the chord the
/// firmware (Marlin's and Klipper's `plan_arc` alike) still takes the half turn the way
/// written.
const MAX_SWEEP: f64 = std::f64::consts::PI + 1e-9;
/// Largest relative mismatch between the start and end radius as written.
const RADIUS_MISMATCH: f64 = 0.002;
/// Largest mismatch between them in any case, mm: the 3-decimal rounding of the end point
/// alone moves it up to 0.0007 mm, more than the relative bound on a hairpin's 0.2 mm radius;
/// the firmware runs the last chord to the end point as written, within the room the
/// tolerance keeps for rounding.
const RADIUS_MISMATCH_MM: f64 = 0.001;

/// A circle an arc runs on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct ArcShape {
    /// Centre (X, Y), mm.
    pub(crate) center: [f64; 2],
    /// Counter-clockwise (`G3`); clockwise is `G2`.
    pub(crate) ccw: bool,
}

impl ArcShape {
    /// The machine's arc from `from` to `to` on this circle (the sweep the firmware takes).
    pub(crate) fn resolve(&self, from: &[f64; 3], to: &[f64; 3]) -> Arc {
        let c = self.center;
        let a0 = crate::math::atan2(from[1] - c[1], from[0] - c[0]);
        let mut a1 = crate::math::atan2(to[1] - c[1], to[0] - c[0]);
        if self.ccw && a1 < a0 {
            a1 += std::f64::consts::TAU;
        }
        if !self.ccw && a1 > a0 {
            a1 -= std::f64::consts::TAU;
        }
        Arc {
            plane: Plane::Xy,
            center: c,
            radius: (from[0] - c[0]).hypot(from[1] - c[1]),
            sweep: a1 - a0,
            start_angle: a0,
        }
    }
}

/// One written move: it ends at point `end` of the polyline (0 is the start point), straight or
/// along an arc, at `feed` mm/s.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Piece {
    /// Index of its end point.
    pub(crate) end: usize,
    /// The arc it runs along (`None`: a straight `G1`).
    pub(crate) arc: Option<ArcShape>,
    /// Feed, mm/s.
    pub(crate) feed: f64,
}

/// The circle through three points in the XY plane: centre and radius.
pub(crate) fn circle_through(a: &[f64; 3], b: &[f64; 3], c: &[f64; 3]) -> Option<([f64; 2], f64)> {
    let (bx, by) = (b[0] - a[0], b[1] - a[1]);
    let (cx, cy) = (c[0] - a[0], c[1] - a[1]);
    let d = 2.0 * (bx * cy - by * cx);
    let scale = (bx * bx + by * by).max(cx * cx + cy * cy);
    if d.abs() <= 1e-9 * scale || !d.is_finite() {
        return None;
    }
    let (b2, c2) = (bx * bx + by * by, cx * cx + cy * cy);
    let ux = (cy * b2 - by * c2) / d;
    let uy = (bx * c2 - cx * b2) / d;
    let r = (ux * ux + uy * uy).sqrt();
    r.is_finite().then_some(([a[0] + ux, a[1] + uy], r))
}

/// How the firmware runs an arc: into how many straight segments it cuts an arc of a radius
/// and planar length at a feed (mm, mm, mm/s), and the largest turn one of its segments may
/// make (rad): an arc the firmware would cut more coarsely than the walk cut the curve is not
/// written (a tight fillet as two 40° chords would bring back the sharp corners).
pub(crate) struct Firmware<'a> {
    /// Segments of an arc.
    pub(crate) segments: &'a dyn Fn(f64, f64, f64) -> usize,
    /// Largest turn at a segment's end, rad.
    pub(crate) max_turn_rad: f64,
}

impl std::fmt::Debug for Firmware<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Firmware")
            .field("max_turn_rad", &self.max_turn_rad)
            .finish_non_exhaustive()
    }
}

/// Why a run of points is not written as one arc ([`arc_over`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Unfit {
    /// Its points are not on one circle as an arc asks (nor would a longer run's be).
    Shape,
    /// They are, but the firmware would cut the arc into chords that turn more than the walk's
    /// steps: a longer run on the same circle may be cut finely enough (upstream Marlin 2.1
    /// cuts 45° of a 0.225 mm circle into one chord and 180° into seven).
    Coarse,
}

/// Whether points `pts[i..=j]` (feeds `feed[i..j]` of the segments between them) make one arc
/// within `tol` of the circle through the first, middle and last; its shape if so.
fn arc_over(
    pts: &[[f64; 3]],
    feed: &[f64],
    (i, j): (usize, usize),
    tol: f64,
    firmware: &Firmware<'_>,
) -> Result<ArcShape, Unfit> {
    let run = pts.get(i..=j).ok_or(Unfit::Shape)?;
    let (first, last) = (&run[0], &run[run.len() - 1]);
    let (center, r) = circle_through(first, &run[run.len() / 2], last).ok_or(Unfit::Shape)?;
    if !(TUNING.arc_min_radius_mm..=TUNING.arc_max_radius_mm).contains(&r) {
        return Err(Unfit::Shape);
    }
    if run.iter().any(|p| (p[2] - first[2]).abs() > 1e-9) {
        return Err(Unfit::Shape);
    }
    let speeds = feed.get(i..j).ok_or(Unfit::Shape)?;
    let (lo, hi) = speeds.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &f| {
        (lo.min(f), hi.max(f))
    });
    if !(lo > 0.0 && hi <= lo * TUNING.arc_feed_spread) {
        return Err(Unfit::Shape);
    }
    // Every point on the circle, every step turning the same way by less than a quarter turn.
    // (The arc runs outside the chords between the points by their sagittas: closer to the
    // curve the points were walked on than the chords are. What counts, the distance to the
    // original, is measured by the caller.)
    let rel = |p: &[f64; 3]| [p[0] - center[0], p[1] - center[1]];
    let mut sweep = 0.0;
    let mut sign = 0.0;
    for w in run.windows(2) {
        let (a, b) = (rel(&w[0]), rel(&w[1]));
        let cross = a[0] * b[1] - a[1] * b[0];
        let dot = a[0] * b[0] + a[1] * b[1];
        let step = crate::math::atan2(cross, dot);
        if sign == 0.0 {
            sign = step.signum();
        }
        if step.signum() != sign || step.abs() >= std::f64::consts::FRAC_PI_2 {
            return Err(Unfit::Shape);
        }
        sweep += step.abs();
    }
    if sweep > MAX_SWEEP
        || run
            .iter()
            .any(|p| (norm(sub(p, [center[0], center[1], p[2]])) - r).abs() > tol)
    {
        return Err(Unfit::Shape);
    }
    // As written (the block writer's rounding): the end stays on the circle the start and the
    // offsets define.
    let (sx, sy) = (rounded(first[0], 3), rounded(first[1], 3));
    let (ci, cj) = (rounded(center[0] - sx, 4), rounded(center[1] - sy, 4));
    let (ex, ey) = (rounded(last[0], 3), rounded(last[1], 3));
    let r_start = ci.hypot(cj);
    let r_end = (ex - sx - ci).hypot(ey - sy - cj);
    if (r_end - r_start).abs() > (RADIUS_MISMATCH * r_start).max(RADIUS_MISMATCH_MM) {
        return Err(Unfit::Shape);
    }
    let cuts = (firmware.segments)(r, r * sweep, lo).max(1);
    if sweep / cuts as f64 > firmware.max_turn_rad {
        return Err(Unfit::Coarse);
    }
    Ok(ArcShape {
        center,
        ccw: sign > 0.0,
    })
}

/// A polyline written as it is: one straight piece per segment, `feed[k]` on the one ending at
/// point `k + 1`.
pub(crate) fn lines(feed: &[f64]) -> Vec<Piece> {
    feed.iter()
        .enumerate()
        .map(|(k, &feed)| Piece {
            end: k + 1,
            arc: None,
            feed,
        })
        .collect()
}

/// The polyline `pts` (the start point first) as pieces: the longest runs that make arcs
/// within `tol` (greedily, from the start), lines elsewhere. `feed[k]` is the feed of the segment
/// ending at `pts[k + 1]`.
pub(crate) fn pieces(
    pts: &[[f64; 3]],
    feed: &[f64],
    tol: f64,
    firmware: &Firmware<'_>,
) -> Vec<Piece> {
    let n = pts.len().saturating_sub(1);
    let mut out = Vec::with_capacity(n);
    let mut i = 0;
    while i < n {
        let mut best: Option<(usize, ArcShape)> = None;
        let mut j = i + MIN_SEGMENTS;
        while j <= n && j - i <= MAX_SEGMENTS {
            match arc_over(pts, feed, (i, j), tol, firmware) {
                Ok(shape) => best = Some((j, shape)),
                Err(Unfit::Coarse) => {}
                Err(Unfit::Shape) => break,
            }
            j += 1;
        }
        match best {
            Some((j, shape)) => {
                let slowest = feed[i..j].iter().copied().fold(f64::INFINITY, f64::min);
                out.push(Piece {
                    end: j,
                    arc: Some(shape),
                    feed: slowest,
                });
                i = j;
            }
            None => {
                out.push(Piece {
                    end: i + 1,
                    arc: None,
                    feed: feed.get(i).copied().unwrap_or(0.0),
                });
                i += 1;
            }
        }
    }
    out
}

/// An upper bound of the distance between each arc of `pieces` and the run of `pts` it
/// replaces, both ways, mm (0 without arcs). A run's points lie on its circle's side within
/// the fit, in order of angle (every step turns one way, by less than a quarter turn), so over
/// the angles of each chord both the chord and the arc cross every ray from the centre once:
/// the two are no farther apart than the chord's farthest radius beyond the arc's, or its
/// nearest approach to the centre within it (the exact distance from the centre to the
/// chord). The path with its arcs is then within this of the polyline, whose own distance to
/// the original is measured on far fewer points than the arcs flattened finely would take.
pub(crate) fn offset_bound(pts: &[[f64; 3]], pieces: &[Piece]) -> f64 {
    let mut worst = 0.0f64;
    let mut start = 0usize;
    for piece in pieces {
        let run = pts.get(start..=piece.end).unwrap_or(&[]);
        start = piece.end;
        let (Some(shape), Some(first)) = (piece.arc, run.first()) else {
            continue;
        };
        let c = [shape.center[0], shape.center[1], first[2]];
        let radius = (first[0] - c[0]).hypot(first[1] - c[1]);
        for w in run.windows(2) {
            let outward = norm(sub(w[0], c)).max(norm(sub(w[1], c))) - radius;
            let inward = radius - crate::vtg::deviation::point_segment(&c, &w[0], &w[1]);
            worst = worst.max(outward).max(inward);
        }
    }
    worst
}

/// The pieces as a polyline for measuring: arcs sampled so no chord is more than `sagitta` from
/// its arc.
pub(crate) fn flatten(pts: &[[f64; 3]], pieces: &[Piece], sagitta: f64) -> Vec<[f64; 3]> {
    let mut out = Vec::with_capacity(pts.len());
    let Some(&first) = pts.first() else {
        return out;
    };
    out.push(first);
    let mut from = first;
    for p in pieces {
        let Some(&to) = pts.get(p.end) else { break };
        if let Some(shape) = p.arc {
            let a = shape.resolve(&from, &to);
            let n = a.chords_within(sagitta);
            for s in 1..n {
                let [x, y] = a.point_at(s as f64 / n as f64);
                out.push([x, y, from[2]]);
            }
        }
        out.push(to);
        from = to;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A firmware that cuts arcs finely (1° segments).
    const FINE: Firmware<'static> = Firmware {
        segments: &|r, len, _| (len / r / 1f64.to_radians()).ceil() as usize,
        max_turn_rad: 0.5,
    };

    fn on_circle(c: [f64; 2], r: f64, a0: f64, a1: f64, n: usize) -> Vec<[f64; 3]> {
        (0..=n)
            .map(|k| {
                let t = a0 + (a1 - a0) * k as f64 / n as f64;
                [c[0] + r * t.cos(), c[1] + r * t.sin(), 0.2]
            })
            .collect()
    }

    #[test]
    fn points_on_a_circle_make_one_arc() {
        let pts = on_circle([10.0, 20.0], 2.0, 0.0, 1.5, 6);
        let feed = vec![30.0; 6];
        let p = pieces(&pts, &feed, 0.005, &FINE);
        assert_eq!(p.len(), 1);
        let a = p[0].arc.expect("arc");
        assert!(a.ccw);
        assert!((a.center[0] - 10.0).abs() < 1e-9 && (a.center[1] - 20.0).abs() < 1e-9);
        assert_eq!((p[0].end, p[0].feed), (6, 30.0));
        // Clockwise the other way round.
        let back: Vec<_> = pts.iter().rev().copied().collect();
        assert!(!pieces(&back, &feed, 0.005, &FINE)[0].arc.expect("arc").ccw);
        // Measured as an arc, it is the circle.
        for q in flatten(&pts, &p, 1e-4) {
            assert!(((q[0] - 10.0).hypot(q[1] - 20.0) - 2.0).abs() < 1e-9);
        }
    }

    /// Points on the circle `Δ` apart: the chords' sagitta `R(1 − cos(Δ/2))`; a point pushed
    /// out by `f` adds its offset. And the bound holds against the arcs flattened finely and
    /// the polyline, both ways (sampled densely).
    #[test]
    fn the_offset_bound_is_the_sagitta_and_holds_against_the_flattened_arcs() {
        let (r, n) = (2.0, 6);
        let pts = on_circle([10.0, 20.0], r, 0.0, 1.5, n);
        let p = pieces(&pts, &[30.0; 6], 0.005, &FINE);
        assert!(p.len() == 1 && p[0].arc.is_some());
        let sagitta = r * (1.0 - (0.5 * 1.5 / n as f64).cos());
        assert!((offset_bound(&pts, &p) - sagitta).abs() < 1e-9);
        assert_eq!(offset_bound(&pts, &lines(&[30.0; 6])), 0.0);
        // The middle point pushed out by 0.004 mm.
        let mut out = pts.clone();
        let k = (r + 0.004) / r;
        out[3] = [
            10.0 + (out[3][0] - 10.0) * k,
            20.0 + (out[3][1] - 20.0) * k,
            0.2,
        ];
        let p = pieces(&out, &[30.0; 6], 0.005, &FINE);
        assert!(p.len() == 1 && p[0].arc.is_some(), "{p:?}");
        let bound = offset_bound(&out, &p);
        assert!(bound >= 0.004 - 1e-12, "{bound}");
        let arc = flatten(&out, &p, 1e-6);
        let measured = crate::vtg::deviation::both_ways(&arc, &out, 1e-4, 0.0);
        assert!(measured <= bound + 1e-4, "{measured} vs {bound}");
        assert!(measured >= 0.5 * bound, "{measured} vs {bound}");
    }

    #[test]
    fn lines_corners_and_mixed_feeds_stay_lines() {
        let square = [
            [0.0, 0.0, 0.2],
            [1.0, 0.0, 0.2],
            [1.0, 1.0, 0.2],
            [0.0, 1.0, 0.2],
            [0.0, 0.0, 0.2],
        ];
        let p = pieces(&square, &[20.0; 4], 0.005, &FINE);
        assert!(p.iter().all(|p| p.arc.is_none()) && p.len() == 4);
        let pts = on_circle([0.0, 0.0], 1.0, 0.0, 1.0, 4);
        let p = pieces(&pts, &[20.0, 20.0, 40.0, 20.0], 0.005, &FINE);
        assert!(p.iter().all(|p| p.arc.is_none()));
        // A straight run, then an arc, then a straight run.
        let mut pts = vec![[-5.0, -1.0, 0.2]];
        pts.extend(on_circle(
            [0.0, 0.0],
            1.0,
            -0.5 * std::f64::consts::PI,
            0.0,
            5,
        ));
        pts.push([1.0, 5.0, 0.2]);
        let p = pieces(&pts, &[20.0; 7], 0.005, &FINE);
        let kinds: Vec<bool> = p.iter().map(|p| p.arc.is_some()).collect();
        assert_eq!(kinds, [false, true, false]);
        assert_eq!(p.iter().map(|p| p.end).collect::<Vec<_>>(), [1, 6, 7]);
    }

    #[test]
    fn points_off_the_circle_by_more_than_the_tolerance_are_not_one_arc() {
        // A quarter circle of radius 1 in 4 steps, one inner point pushed 0.01 mm outwards.
        let mut pts = on_circle([0.0, 0.0], 1.0, 0.0, std::f64::consts::FRAC_PI_2, 4);
        pts[1] = [pts[1][0] * 1.01, pts[1][1] * 1.01, 0.2];
        assert!(pieces(&pts, &[20.0; 4], 0.005, &FINE).len() > 1);
        assert_eq!(pieces(&pts, &[20.0; 4], 0.05, &FINE).len(), 1);
    }

    #[test]
    fn an_arc_the_firmware_would_cut_coarsely_stays_lines() {
        // A 75° fillet of radius 0.4 walked in 6 steps of 12.4°. A firmware that runs any arc as
        // one chord would turn by at least 37° at the ends of the shortest arc (3 steps): lines.
        let pts = on_circle([0.0, 0.0], 0.4, 0.0, 1.3, 6);
        let coarse = Firmware {
            segments: &|_, _, _| 1,
            max_turn_rad: 0.47,
        };
        assert!(pieces(&pts, &[20.0; 6], 0.005, &coarse)
            .iter()
            .all(|p| p.arc.is_none()));
        assert_eq!(pieces(&pts, &[20.0; 6], 0.005, &FINE).len(), 1);
    }
}
