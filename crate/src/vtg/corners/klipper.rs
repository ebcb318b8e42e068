//! Klipper corners: a sharp corner replaced by a polygon placed for the firmware's look-ahead.
//!
//! Klipper plans every segment it is sent, and takes a junction that turns by `t` between
//! moves of length `d` no faster than `v² = ½ d a cot(t/2)` (its centripetal limit: the
//! polygon read as a circle of radius about `d / t`), besides the junction-deviation limit of
//! the square-corner velocity. A curve fitted and walked in steps sized by the chord error
//! (the rest of the pipeline) spends part of the tolerance on the fit and on the chords' sag,
//! and its steps are shorter than the band allows. Searched freely, the fastest polygon
//! within the band (on our own planner, a 20 mm square at 5000 mm/s² and a 50 mm/s
//! square-corner velocity) is a pair of discrete clothoids in equal steps: one vertex on the
//! bisector turning by the most a step may, turns falling about linearly on either side, and
//! at each end a long ramp that moves the path out to the edge of the band along the leg and
//! back. That is the shape written here, in one family:
//!
//! - the apex vertex turns by `t₀` (the walk's largest turn, or a share of it);
//! - `m` vertices on each side turn by `t₀ − kΔ`, `k = 1..m`, with Δ set so the half-turn
//!   comes to `θ/2 + γ`;
//! - a ramp of heading `γ` off the leg brings the path back onto the leg, where it turns by
//!   `−γ`.
//!
//! All clothoid steps are one length `d`. With the turns fixed, the shape scales with `d`,
//! and so does its distance from the original corner; so the shape is placed on the bisector
//! where its largest distance from the corner (both ways) is least, and `d` is then the
//! largest the tolerance allows. Of the family's members that fit the legs, the one the
//! look-ahead (as Klipper plans it: `stretch_time`) runs through fastest is kept.

use super::{CornerKind, Cost, Proposal, Replacement, Site};
use crate::vec3::{dot, norm, sub};
use crate::vtg::deviation::both_ways;
use crate::vtg::hairpin::{cross_z, unit, Hairpin};
use crate::vtg::smooth::{Settings, SmoothPath};
use crate::vtg::tuning::TUNING;

/// What the firmware does at a corner: its limits there and the speeds either side.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Firmware {
    /// Acceleration of the moves, mm/s².
    pub(crate) accel_mm_s2: f64,
    /// Junction deviation equivalent to the square-corner velocity, mm.
    pub(crate) junction_deviation_mm: f64,
    /// Programmed feed of the leg before and of the leg after, mm/s.
    pub(crate) feed_mm_s: [f64; 2],
    /// Planned speed at the far end of each leg (the start of the one before, the end of the
    /// one after), mm/s.
    pub(crate) ends_mm_s: [f64; 2],
}

/// The constraints of a polygon corner.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bounds {
    /// Largest distance from the original both ways, mm.
    pub(crate) tolerance_mm: f64,
    /// Largest turn of one vertex, rad.
    pub(crate) max_turn_rad: f64,
    /// Shortest step, mm.
    pub(crate) min_step_mm: f64,
    /// How far along each leg from the corner the polygon may reach, mm.
    pub(crate) room_mm: [f64; 2],
}

/// A corner's polygon, and how the firmware runs it.
#[derive(Debug, Clone)]
pub(crate) struct Corner {
    /// The polygon as a one-corner [`Hairpin`] (for [`crate::vtg::hairpin::substitute`]).
    pub(crate) pin: Hairpin,
    /// Measured largest distance from the original, both ways, mm.
    pub(crate) deviation_mm: f64,
    /// Slowest speed through the polygon, mm/s.
    pub(crate) slowest_mm_s: f64,
    /// Slowest speed through the sharp corner, mm/s (the same model).
    pub(crate) sharp_mm_s: f64,
    /// Time through the legs and the sharp corner, s.
    #[cfg_attr(not(test), allow(dead_code))] // checked by the tests only
    pub(crate) sharp_time_s: f64,
}

/// Shares of the largest turn tried at the apex.
const APEX_SHARES: [f64; 2] = [1.0, 0.85];
/// Headings of the ramps off the legs tried, degrees.
const RAMP_DEG: [f64; 8] = [1.5, 2.5, 4.0, 6.0, 9.0, 13.0, 18.0, 24.0];
/// Most vertices either side of the apex.
const MAX_SIDE_VERTICES: usize = 12;
/// Golden-section steps of the placement search.
const PLACEMENT_STEPS: usize = 48;

/// The polygon for corner `i` of `pts` that the firmware runs through fastest, if one fits.
pub(crate) fn find(pts: &[[f64; 3]], i: usize, bounds: &Bounds, fw: &Firmware) -> Option<Corner> {
    let (p0, v, p2) = (*pts.get(i.checked_sub(1)?)?, *pts.get(i)?, *pts.get(i + 1)?);
    if (p0[2] - v[2]).abs() > 1e-9 || (p2[2] - v[2]).abs() > 1e-9 {
        return None;
    }
    let a = unit(sub(v, p0))?;
    let b = unit(sub(p2, v))?;
    let side = cross_z(&a, &b).signum();
    let theta = crate::math::atan2(cross_z(&a, &b).abs(), dot(a, b));
    if !(theta > bounds.max_turn_rad && theta < 170f64.to_radians()) {
        return None;
    }
    let legs = [norm(sub(v, p0)), norm(sub(p2, v))];
    let sharp = stretch_time(&legs_frame(theta, legs, Vec::new()), fw);
    let budget = TUNING.corner_tolerance_share * bounds.tolerance_mm;
    // Most corners have short legs: where the most compact member (the steepest ramp, the
    // fewest vertices) reaches past the room, so would every other.
    let steepest = RAMP_DEG[RAMP_DEG.len() - 1].to_radians();
    let fewest = ((0.5 * theta + steepest) / bounds.max_turn_rad - 0.5)
        .ceil()
        .max(1.0) as usize;
    if Shape::new(theta, bounds.max_turn_rad, steepest, fewest, budget)
        .is_some_and(|compact| compact.reach() > bounds.room_mm[0].min(bounds.room_mm[1]))
    {
        return None;
    }
    let mut best: Option<(Shape, Timing)> = None;
    for apex in APEX_SHARES {
        for ramp in RAMP_DEG {
            let t0 = apex * bounds.max_turn_rad;
            let h = 0.5 * theta + ramp.to_radians();
            let lo = ((h / t0 - 0.5).ceil() as usize).max(1);
            let hi = ((2.0 * h / t0).floor() as usize).min(MAX_SIDE_VERTICES);
            for m in lo..=hi {
                let Some(shape) = Shape::new(theta, t0, ramp.to_radians(), m, budget) else {
                    continue;
                };
                if !shape.fits(bounds) {
                    continue;
                }
                let timing = stretch_time(&legs_frame(theta, legs, shape.polygon()), fw);
                if best.as_ref().is_none_or(|b| timing.time_s < b.1.time_s) {
                    best = Some((shape, timing));
                }
            }
        }
    }
    let (shape, timing) = best?;
    // Into the file's frame: x along the mid-direction, y towards the inside of the turn.
    let c = unit([a[0] + b[0], a[1] + b[1], 0.0])?;
    let n = [-c[1] * side, c[0] * side, 0.0];
    let world = |p: &[f64; 2]| {
        [
            v[0] + c[0] * p[0] + n[0] * p[1],
            v[1] + c[1] * p[0] + n[1] * p[1],
            v[2],
        ]
    };
    let arc: Vec<[f64; 3]> = shape.polygon().iter().map(world).collect();
    let (first, last) = (*arc.first()?, *arc.last()?);
    let deviation = both_ways(&arc, &[first, v, last], budget / 10.0, bounds.tolerance_mm);
    if deviation.is_nan() || deviation > bounds.tolerance_mm {
        return None;
    }
    Some(Corner {
        pin: Hairpin {
            at: i,
            corners: 1,
            radius_mm: shape.d / shape.t0,
            before_mm: dot(a, sub(v, first)),
            after_mm: dot(b, sub(last, v)),
            arc,
        },
        deviation_mm: deviation,
        slowest_mm_s: timing.slowest_mm_s,
        sharp_mm_s: sharp.slowest_mm_s,
        sharp_time_s: sharp.time_s,
    })
}

/// The corner kind of a sharp corner on a Klipper machine whose own fillet does not round it
/// at no loss of speed (the fitted curve rings less than a polygon of the largest turns): the
/// polygon the firmware runs through fastest, written as it is, within the tolerance and the
/// legs' room (all of the leg where it ends the path, half where it is shared, less a shortest
/// step). It costs its slowest planned speed against the sharp corner's.
pub(crate) struct Polygons;

impl CornerKind for Polygons {
    fn applies(&self, path: &SmoothPath<'_>, s: &Settings) -> bool {
        s.klipper_scv_mm_s.is_some() && !path.planned.is_empty()
    }

    fn asks_about(&self, site: &Site<'_>, i: usize) -> bool {
        site.marks.sharp[i] && !site.marks.alone[i]
    }

    fn propose(&self, site: &Site<'_>, i: usize) -> Option<Proposal> {
        let (path, s) = (site.path, site.settings);
        let scv = s.klipper_scv_mm_s?;
        let pts = path.pts;
        let n = pts.len();
        let (before, after) = (path.planned.get(i - 1)?, path.planned.get(i)?);
        let accel = before.acceleration.min(after.acceleration);
        if accel.is_nan() || accel <= 0.0 {
            return None;
        }
        let room = |from: usize, to: usize, end: bool| {
            let l = norm(sub(pts[to], pts[from]));
            (if end { TUNING.leg_share } else { 0.5 } * l - s.min_step_mm).max(0.0)
        };
        let bounds = Bounds {
            tolerance_mm: s.tolerance_mm - 0.001,
            max_turn_rad: TUNING.step_turn_share * s.critical_rad,
            min_step_mm: s.min_step_mm,
            room_mm: [room(i - 1, i, i == 1), room(i, i + 1, i + 2 == n)],
        };
        let fw = Firmware {
            accel_mm_s2: accel,
            junction_deviation_mm: crate::plan::junction::klipper_junction_deviation(scv, accel),
            feed_mm_s: [path.feed[i - 1], path.feed[i]],
            ends_mm_s: [before.entry, after.exit],
        };
        let c = find(pts, i, &bounds, &fw)?;
        Some(Proposal {
            replacement: Replacement::Written(c.pin, c.deviation_mm),
            cost: Cost::Planned {
                slowest_mm_s: c.slowest_mm_s,
                sharp_mm_s: c.sharp_mm_s,
            },
        })
    }
}

/// The minimum of `f` on `[lo, hi]` by golden-section search in [`PLACEMENT_STEPS`] steps, and
/// where it lies: the apex height at which a shape strays least from the corner.
fn golden_min(mut lo: f64, mut hi: f64, f: impl Fn(f64) -> f64) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let (mut x1, mut x2) = (hi - g * (hi - lo), lo + g * (hi - lo));
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..PLACEMENT_STEPS {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = f(x2);
        }
    }
    if f1 <= f2 {
        (x1, f1)
    } else {
        (x2, f2)
    }
}

/// One member of the family, placed and sized, in the corner's frame: the corner at the
/// origin, the turn to the left, x along the mid-direction of the legs.
#[derive(Debug, Clone)]
struct Shape {
    theta: f64,
    t0: f64,
    ramp: f64,
    /// Step, mm.
    d: f64,
    /// The right half: apex, clothoid vertices, ramp start, ramp end (on the leg).
    half: Vec<[f64; 2]>,
}

impl Shape {
    /// The member with apex turn `t0`, ramp heading `ramp` and `m` vertices a side, for a turn
    /// of `theta`, placed and sized to stay within `budget` of the corner both ways.
    fn new(theta: f64, t0: f64, ramp: f64, m: usize, budget: f64) -> Option<Shape> {
        let half_turn = 0.5 * theta + ramp;
        let mf = m as f64;
        let delta = (t0 * (mf + 0.5) - half_turn) * 2.0 / (mf * (mf + 1.0));
        if delta.is_nan() || delta < 0.0 || t0 - mf * delta < 0.0 {
            return None;
        }
        // The unit shape (d = 1) with its apex at the origin: apex and clothoid vertices.
        let mut unit_half = Vec::with_capacity(m + 3);
        let (mut p, mut heading) = ([0.0, 0.0], 0.5 * t0);
        unit_half.push(p);
        for k in 1..=m {
            p = [
                p[0] + crate::math::cos(heading),
                p[1] + crate::math::sin(heading),
            ];
            unit_half.push(p);
            heading += t0 - k as f64 * delta;
        }
        let (s, c) = (crate::math::sin(0.5 * theta), crate::math::cos(0.5 * theta));
        let (sin_ramp, u) = (
            crate::math::sin(ramp),
            [crate::math::cos(heading), crate::math::sin(heading)],
        );
        // The outgoing leg's inward normal; the ramp end for the apex at height `y`.
        let normal = [-s, c];
        let ramp_end = |q: [f64; 2]| -> Option<[f64; 2]> {
            let offset = normal[0] * q[0] + normal[1] * q[1];
            (offset < 0.0 && sin_ramp > 0.0).then(|| {
                let l = -offset / sin_ramp;
                [q[0] + u[0] * l, q[1] + u[1] * l]
            })
        };
        let placed = |y: f64| unit_half.iter().map(move |p| [p[0], p[1] + y]);
        // Largest distance from the corner both ways (the half is the mirror of the other).
        let leg = [c, s];
        let spread = |y: f64| -> f64 {
            let Some(q) = placed(y).next_back() else {
                return f64::INFINITY;
            };
            let Some(end) = ramp_end(q) else {
                return f64::INFINITY;
            };
            let out = placed(y).map(|p| to_legs(&p, leg)).fold(0.0, f64::max);
            let sides = placed(y).zip(placed(y).skip(1));
            let to_corner = sides
                .map(|(a, b)| point_segment_2d([0.0, 0.0], a, b))
                .fold(point_segment_2d([0.0, 0.0], q, end), f64::min);
            out.max(to_corner)
        };
        // Feasible while the ramp can reach the leg: the apex below `y_max`.
        let q = *unit_half.last()?;
        let y_max = if c > 1e-9 {
            -(normal[0] * q[0] + normal[1] * q[1]) / c
        } else {
            return None;
        };
        let span = 2.0 * (mf + 1.0);
        let (y, unit_spread) = golden_min(y_max - span, y_max - 1e-9 * span, spread);
        if !(unit_spread.is_finite() && unit_spread > 0.0) {
            return None;
        }
        let d = budget / unit_spread;
        let mut half: Vec<[f64; 2]> = placed(y).map(|p| [p[0] * d, p[1] * d]).collect();
        let q_end = ramp_end(placed(y).next_back()?)?;
        half.push([q_end[0] * d, q_end[1] * d]);
        Some(Shape {
            theta,
            t0,
            ramp,
            d,
            half,
        })
    }

    /// How far along each leg from the corner the polygon reaches, mm.
    fn reach(&self) -> f64 {
        let end = self.half[self.half.len() - 1];
        end[0] * crate::math::cos(0.5 * self.theta) + end[1] * crate::math::sin(0.5 * self.theta)
    }

    /// Whether the steps are long enough and the ramps end within the room on the legs.
    fn fits(&self, bounds: &Bounds) -> bool {
        let n = self.half.len();
        let ramp_len = norm2(sub2(self.half[n - 1], self.half[n - 2]));
        let along = self.reach();
        self.d >= bounds.min_step_mm
            && ramp_len >= bounds.min_step_mm
            && along >= 0.0
            && along <= bounds.room_mm[0].min(bounds.room_mm[1])
            && self.ramp > 0.0
    }

    /// The whole polygon, from the ramp's end on the leg before to its end on the leg after.
    fn polygon(&self) -> Vec<[f64; 2]> {
        let left = self.half.iter().rev().map(|p| [-p[0], p[1]]);
        left.chain(self.half.iter().skip(1).copied()).collect()
    }
}

/// `between` (points in the corner's frame) with the far ends of legs of lengths `legs` before
/// and after it, and the corner itself if `between` is empty.
fn legs_frame(theta: f64, legs: [f64; 2], between: Vec<[f64; 2]>) -> Vec<[f64; 2]> {
    let (s, c) = (crate::math::sin(0.5 * theta), crate::math::cos(0.5 * theta));
    let middle = if between.is_empty() {
        vec![[0.0, 0.0]]
    } else {
        between
    };
    std::iter::once([-legs[0] * c, legs[0] * s])
        .chain(middle)
        .chain(std::iter::once([legs[1] * c, legs[1] * s]))
        .collect()
}

/// Distance from `p` to the two legs of the corner at the origin (rays along `(−c, s)` and
/// `(c, s)`: the legs of a left turn in the corner's frame).
fn to_legs(p: &[f64; 2], leg: [f64; 2]) -> f64 {
    let ray = |dir: [f64; 2]| {
        let t = (p[0] * dir[0] + p[1] * dir[1]).max(0.0);
        norm2([p[0] - t * dir[0], p[1] - t * dir[1]])
    };
    ray(leg).min(ray([-leg[0], leg[1]]))
}

fn sub2(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn norm2(a: [f64; 2]) -> f64 {
    (a[0] * a[0] + a[1] * a[1]).sqrt()
}

fn point_segment_2d(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    let ab = sub2(b, a);
    let l2 = ab[0] * ab[0] + ab[1] * ab[1];
    let t = if l2 > 0.0 {
        (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    norm2([p[0] - a[0] - t * ab[0], p[1] - a[1] - t * ab[1]])
}

/// How the look-ahead runs a stretch.
#[derive(Debug, Clone, Copy)]
struct Timing {
    time_s: f64,
    slowest_mm_s: f64,
}

/// Time through the polyline `pts` (2D) as Klipper's look-ahead plans it: each junction held
/// to its junction-deviation and centripetal limits (and the feeds), the speed changing at the
/// acceleration between, from and to the planned speeds at the two ends; and the slowest
/// junction. The first half of the polyline is on the leg before (feed `feed_mm_s[0]`), the
/// rest on the one after.
fn stretch_time(pts: &[[f64; 2]], fw: &Firmware) -> Timing {
    let n = pts.len();
    let a = fw.accel_mm_s2;
    let len: Vec<f64> = pts.windows(2).map(|w| norm2(sub2(w[1], w[0]))).collect();
    let feed = |k: usize| fw.feed_mm_s[usize::from(2 * k + 1 >= len.len())];
    // Squared speed caps at each point.
    let mut v2 = vec![0.0; n];
    v2[0] = fw.ends_mm_s[0].powi(2);
    v2[n - 1] = fw.ends_mm_s[1].powi(2);
    for k in 1..n - 1 {
        let (u, w) = (sub2(pts[k], pts[k - 1]), sub2(pts[k + 1], pts[k]));
        let cos = -(u[0] * w[0] + u[1] * w[1]) / (len[k - 1] * len[k]).max(1e-300);
        let sin_d2 = (0.5 * (1.0 - cos)).max(0.0).sqrt();
        let cos_d2 = (0.5 * (1.0 + cos)).max(0.0).sqrt();
        let mut cap = feed(k - 1).min(feed(k)).powi(2);
        if 1.0 - sin_d2 > 0.0 && cos_d2 > 0.0 {
            let quarter_tan = 0.25 * sin_d2 / cos_d2;
            cap = cap
                .min(sin_d2 / (1.0 - sin_d2) * fw.junction_deviation_mm * a)
                .min(2.0 * len[k - 1].min(len[k]) * a * quarter_tan);
        }
        v2[k] = cap;
    }
    for k in 1..n {
        v2[k] = v2[k].min(v2[k - 1] + 2.0 * a * len[k - 1]);
    }
    for k in (0..n - 1).rev() {
        v2[k] = v2[k].min(v2[k + 1] + 2.0 * a * len[k]);
    }
    let mut time = 0.0;
    for (k, &l) in len.iter().enumerate() {
        let (v0, v1, vc) = (v2[k].sqrt(), v2[k + 1].sqrt(), feed(k));
        let peak = vc.min(((2.0 * a * l + v2[k] + v2[k + 1]) * 0.5).sqrt());
        let ramps = (peak * peak - v2[k]) / (2.0 * a) + (peak * peak - v2[k + 1]) / (2.0 * a);
        time += (peak - v0) / a + (peak - v1) / a + (l - ramps).max(0.0) / peak.max(1e-9);
    }
    let slowest = v2[1..n - 1]
        .iter()
        .fold(f64::INFINITY, |m, &x| m.min(x))
        .sqrt();
    Timing {
        time_s: time,
        slowest_mm_s: slowest,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bounds() -> Bounds {
        Bounds {
            tolerance_mm: 0.099,
            max_turn_rad: 27f64.to_radians(),
            min_step_mm: 0.03,
            room_mm: [9.0, 9.0],
        }
    }

    fn k1c() -> Firmware {
        Firmware {
            accel_mm_s2: 5000.0,
            junction_deviation_mm: crate::plan::junction::klipper_junction_deviation(50.0, 5000.0),
            feed_mm_s: [200.0, 200.0],
            ends_mm_s: [50.0, 50.0],
        }
    }

    /// A right angle between 20 mm legs, at 200 mm/s, entered and left at 50 mm/s.
    fn square_corner() -> [[f64; 3]; 3] {
        [[0.0, 0.0, 0.2], [20.0, 0.0, 0.2], [20.0, 20.0, 0.2]]
    }

    /// The look-ahead model against closed forms: the square corner runs at exactly the
    /// square-corner velocity (Klipper's definition of it), and each leg accelerates from 50 to
    /// 200 mm/s over (200² − 50²) / (2 · 5000) = 3.75 mm, cruises, and brakes again.
    #[test]
    fn the_sharp_corner_runs_at_the_square_corner_velocity() {
        let c = find(&square_corner(), 1, &bounds(), &k1c()).expect("a polygon fits");
        assert!((c.sharp_mm_s - 50.0).abs() < 1e-9, "{}", c.sharp_mm_s);
        let leg = 2.0 * 150.0 / 5000.0 + (20.0 - 2.0 * 3.75) / 200.0;
        assert!(
            (c.sharp_time_s - 2.0 * leg).abs() < 1e-12,
            "{}",
            c.sharp_time_s
        );
    }

    /// The polygon keeps every bound it is built for, measured on its points: within the
    /// tolerance of the corner both ways, every turn at most the largest, every step at least
    /// the shortest, symmetric, and its ends on the legs within their room. Its slowest
    /// junction is the apex's centripetal limit, `½ d a cot(t₀/2)`.
    #[test]
    fn a_right_angle_polygon_keeps_its_bounds() {
        let pts = square_corner();
        let b = bounds();
        let c = find(&pts, 1, &b, &k1c()).expect("a polygon fits");
        let poly = &c.pin.arc;
        let d = both_ways(poly, &[poly[0], pts[1], poly[poly.len() - 1]], 1e-4, 0.0);
        assert!(d <= b.tolerance_mm && d > 0.9 * b.tolerance_mm, "{d}");
        let all: Vec<[f64; 3]> = std::iter::once(pts[0])
            .chain(poly.iter().copied())
            .chain(std::iter::once(pts[2]))
            .collect();
        let mut total = 0.0;
        let mut apex = (0.0f64, 0.0);
        for w in all.windows(3) {
            let (u, v) = (sub(w[1], w[0]), sub(w[2], w[1]));
            let turn = crate::math::atan2(cross_z(&u, &v), dot(u, v));
            assert!(turn.abs() <= b.max_turn_rad + 1e-9, "{}", turn.to_degrees());
            total += turn;
            if turn > apex.0 {
                apex = (turn, norm(u).min(norm(v)));
            }
        }
        assert!((total - std::f64::consts::FRAC_PI_2).abs() < 1e-9);
        assert!(all
            .windows(2)
            .all(|w| norm(sub(w[1], w[0])) >= b.min_step_mm));
        assert!((c.pin.before_mm - c.pin.after_mm).abs() < 1e-9);
        assert!(c.pin.before_mm > 0.0 && c.pin.before_mm <= b.room_mm[0]);
        assert!(poly[0][1].abs() < 1e-12 && (poly[poly.len() - 1][0] - 20.0).abs() < 1e-12);
        let centripetal = (0.5 * apex.1 * 5000.0 / (0.5 * apex.0).tan()).sqrt();
        assert!((c.slowest_mm_s - centripetal).abs() < 1e-6 * centripetal);
        // Within 5 % of the square corner's speed, and not faster.
        assert!(c.slowest_mm_s > 0.95 * c.sharp_mm_s && c.slowest_mm_s < c.sharp_mm_s);
    }

    /// Where the legs leave no room for the ramps, or the turn is not sharp, there is none.
    #[test]
    fn no_polygon_without_room_or_a_sharp_turn() {
        let tight = Bounds {
            room_mm: [0.05, 0.05],
            ..bounds()
        };
        assert!(find(&square_corner(), 1, &tight, &k1c()).is_none());
        let gentle = [[0.0, 0.0, 0.2], [20.0, 0.0, 0.2], [40.0, 5.0, 0.2]];
        assert!(find(&gentle, 1, &bounds(), &k1c()).is_none());
        let climbing = [[0.0, 0.0, 0.2], [20.0, 0.0, 0.2], [20.0, 20.0, 0.4]];
        assert!(find(&climbing, 1, &bounds(), &k1c()).is_none());
    }
}
