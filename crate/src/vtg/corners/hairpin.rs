//! Hairpins: two sharp corners joined by a short leg, rounded as one turn.
//!
//! Infill that zig-zags turns back at the end of each line in two corners a line spacing apart
//! (lines at 45° and a connector along the wall: 45° then 135°; square to the wall: 90° and
//! 90°). A fillet within the tolerance at each corner alone is far too tight to walk in steps
//! the firmware keeps (at 135° and 0.1 mm, radius 0.05 mm; Marlin drops blocks under about
//! 0.06 mm), so both corners would stay sharp. Taken together they are one turn of up to 180°
//! across the line spacing: a circular arc tangent to the two long legs, of about half the
//! spacing in radius (0.2 mm for 0.45 mm lines), bulging past the connector by no more than
//! the tolerance, and that can be walked.
//!
//! The arc's centre is equidistant from the two legs' lines, on the inside of the turn, so it
//! lies on one line (their bisector, or for parallel legs the midline); of the arcs with their
//! centre on it, the one with the largest radius whose distance to the original polyline, both
//! ways, stays within the tolerance is taken. It replaces the two corners and the connector by
//! a fine polygon of the arc, which the rest of the pipeline blends, fits and walks like any
//! other path.

use super::{CornerKind, Cost, Proposal, Replacement, Site};
use crate::vec3::{cross, dot, norm, sub};
use crate::vtg::bspline::{arc_lengths, segment_at};
use crate::vtg::deviation::{both_ways, point_polyline};
use crate::vtg::smooth::Settings;
use crate::vtg::tuning::TUNING;

/// Smallest combined turn of a hairpin, rad (90°: below it the corners are separate turns).
const MIN_TURN_RAD: f64 = std::f64::consts::FRAC_PI_2;
/// Largest combined turn, rad (200°: legs that diverge a little past parallel).
const MAX_TURN_RAD: f64 = 200.0 * std::f64::consts::PI / 180.0;
/// Centres tried along the bisector on the coarse pass, each side of the closest one.
const COARSE_STEPS: i32 = 16;

/// The arc a hairpin is rounded to.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Hairpin {
    /// Index of the first of the corners it replaces.
    pub(crate) at: usize,
    /// How many corners it replaces: 2 for a hairpin (the second is the next point), 1 for a
    /// [`crate::vtg::corners::keyhole`].
    pub(crate) corners: usize,
    /// Radius, mm.
    pub(crate) radius_mm: f64,
    /// Points of the arc, from where it leaves the first long leg to where it meets the second.
    pub(crate) arc: Vec<[f64; 3]>,
    /// Distance from the first corner back along the first leg to where the arc starts, mm
    /// (negative: on the leg's extension past the corner).
    pub(crate) before_mm: f64,
    /// Distance from the second corner along the second leg to where the arc ends, mm.
    pub(crate) after_mm: f64,
}

impl Hairpin {
    /// Index of the last corner it replaces, within a polyline of `points` points.
    fn last_corner(&self, points: usize) -> usize {
        (self.at + self.corners.max(1) - 1).min(points.saturating_sub(1))
    }

    /// The stretch of the original it replaces, as arc lengths `(u0, u1)` along it (`arc`:
    /// the original's arc length at each point).
    pub(crate) fn span(&self, arc: &[f64]) -> (f64, f64) {
        (
            arc[self.at] - self.before_mm.max(0.0),
            arc[self.last_corner(arc.len())] + self.after_mm.max(0.0),
        )
    }
}

/// `v / |v|`, or `None` for a tiny vector. (Divides: `crate::vec3::normalize` multiplies by
/// the reciprocal, which rounds differently and would move the arcs in the last bit.)
pub(crate) fn unit(v: [f64; 3]) -> Option<[f64; 3]> {
    let l = norm(v);
    (l > 1e-12).then(|| [v[0] / l, v[1] / l, v[2] / l])
}

/// The `segments + 1` points of a circular arc in the plane of constant Z through `centre`,
/// from `start` on, sweeping `sweep` rad (positive: anticlockwise seen from above): the radius
/// vector turned step by step.
pub(crate) fn arc_polygon(
    centre: &[f64; 3],
    start: &[f64; 3],
    sweep: f64,
    segments: usize,
) -> impl Iterator<Item = [f64; 3]> {
    let (c, u) = (*centre, sub(start, centre));
    (0..=segments).map(move |j| {
        let phi = sweep * j as f64 / segments as f64;
        let (sin, cos) = (crate::math::sin(phi), crate::math::cos(phi));
        [
            c[0] + u[0] * cos - u[1] * sin,
            c[1] + u[0] * sin + u[1] * cos,
            c[2],
        ]
    })
}

/// The Z component of `a × b` (the turn's sense, seen from above).
pub(crate) fn cross_z(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    cross(a, b)[2]
}

/// The hairpin at corners `i` and `i + 1` of `pts`, if the two corners turn the same way by 90° to
/// 200° together across a connector of at most `Tuning::hairpin_max_connector_mm`, lie in one plane
/// of constant Z, and an arc of radius at least `min_radius_mm` rounds them within `tolerance_mm`
/// starting no more than `room_mm[0]` before corner `i` and ending no more than `room_mm[1]` after
/// corner `i + 1`.
pub(crate) fn find(
    pts: &[[f64; 3]],
    i: usize,
    tolerance_mm: f64,
    min_radius_mm: f64,
    room_mm: [f64; 2],
) -> Option<Hairpin> {
    let (p0, v1, v2, p3) = (
        *pts.get(i.checked_sub(1)?)?,
        *pts.get(i)?,
        *pts.get(i + 1)?,
        *pts.get(i + 2)?,
    );
    let z = v1[2];
    if [p0, v2, p3].iter().any(|p| (p[2] - z).abs() > 1e-9) {
        return None;
    }
    let a = unit(sub(v1, p0))?;
    let b = unit(sub(p3, v2))?;
    let connector = sub(v2, v1);
    let c_len = norm(connector);
    if !(c_len > 0.0 && c_len <= TUNING.hairpin_max_connector_mm) {
        return None;
    }
    let c = unit(connector)?;
    let (side, turn) = turn_of(&a, &c, &b)?;
    // Normals towards the inside of the turn; the centre `C` has n_a·(C − v1) = n_b·(C − v2)
    // = r > 0, a line m·C = k.
    let (na, nb) = (
        [-a[1] * side, a[0] * side, 0.0],
        [-b[1] * side, b[0] * side, 0.0],
    );
    let m = sub(na, nb);
    let m2 = dot(m, m);
    if m2 < 1e-12 {
        return None;
    }
    let k = dot(na, v1) - dot(nb, v2);
    let s0 = (k - dot(m, v1)) / m2;
    let ml = m2.sqrt();
    // The original around the hairpin, and the same stretch with the arc in place.
    let (la, lb) = (norm(sub(v1, p0)), norm(sub(p3, v2)));
    let (room_a, room_b) = (room_mm[0].min(la), room_mm[1].min(lb));
    let pa = [v1[0] - a[0] * room_a, v1[1] - a[1] * room_a, z];
    let pb = [v2[0] + b[0] * room_b, v2[1] + b[1] * room_b, z];
    let u = UTurn {
        i,
        legs: [a, b],
        normals: [na, nb],
        corners: [v1, v2],
        c0: [v1[0] + m[0] * s0, v1[1] + m[1] * s0, z],
        along: [-m[1] / ml, m[0] / ml, 0.0],
        side,
        turn,
        room: [room_a, room_b],
        original: [pa, v1, v2, pb],
        segments: (turn / TUNING.polygon_turn_rad).ceil().max(2.0) as usize,
        tolerance_mm,
        min_radius_mm,
    };
    // Coarse then fine: centres every `span / COARSE_STEPS` either side of the one closest to
    // the first corner, then around the best of those.
    let span = 2.0 * (c_len + tolerance_mm + min_radius_mm);
    let coarse = span / COARSE_STEPS as f64;
    let best = |from: f64, step: f64, n: i32| {
        (-n..=n)
            .filter_map(|j| u.candidate(from + step * j as f64).map(|c| (j, c)))
            .max_by(|x, y| {
                (x.1.radius_mm)
                    .total_cmp(&y.1.radius_mm)
                    .then(y.0.abs().cmp(&x.0.abs()))
            })
            .map(|(j, c)| (from + step * j as f64, c))
    };
    let (t, first) = best(0.0, coarse, COARSE_STEPS)?;
    Some(best(t, coarse / 8.0, 8).map_or(first, |(_, c)| c))
}

/// The sense about +Z and the size (rad) of the turn from unit direction `a` through `c` to
/// `b`, if both corners turn the same way and by 90° to 200° together: the shape [`find`]
/// rounds as one arc.
fn turn_of(a: &[f64; 3], c: &[f64; 3], b: &[f64; 3]) -> Option<(f64, f64)> {
    // Both corners turn the same way.
    let (t1, t2) = (cross_z(a, c), cross_z(c, b));
    if t1 * t2 <= 0.0 {
        return None;
    }
    let side = t1.signum();
    let mut turn = crate::math::atan2(side * cross_z(a, b), dot(a, b));
    if turn < 0.0 {
        turn += 2.0 * std::f64::consts::PI;
    }
    if !(MIN_TURN_RAD..=MAX_TURN_RAD).contains(&turn) {
        return None;
    }
    Some((side, turn))
}

/// Two corners [`find`] may round as one arc, with what every candidate centre is measured
/// against: split from it so the search over centres reads apart from building one arc.
struct UTurn {
    /// The first corner's index.
    i: usize,
    /// Unit directions of the legs into the first corner and out of the second.
    legs: [[f64; 3]; 2],
    /// The legs' normals towards the inside of the turn.
    normals: [[f64; 3]; 2],
    /// The two corners.
    corners: [[f64; 3]; 2],
    /// The centre closest to the first corner, and the unit direction of the line of centres.
    c0: [f64; 3],
    along: [f64; 3],
    /// The turn's sense about +Z, and its size, rad.
    side: f64,
    turn: f64,
    /// Room before the first corner and after the second, mm.
    room: [f64; 2],
    /// The original stretch around the hairpin.
    original: [[f64; 3]; 4],
    /// Sides of the arc's polygon.
    segments: usize,
    tolerance_mm: f64,
    min_radius_mm: f64,
}

impl UTurn {
    /// The hairpin round the centre `t` along the line of centres from `c0`, if its radius is
    /// large enough, it fits in the room and it keeps the tolerance both ways.
    fn candidate(&self, t: f64) -> Option<Hairpin> {
        let (c0, along, z) = (self.c0, self.along, self.c0[2]);
        let ([a, b], [na, nb], [v1, v2]) = (self.legs, self.normals, self.corners);
        let [pa, _, _, pb] = self.original;
        let (tolerance_mm, segments) = (self.tolerance_mm, self.segments);
        let centre = [c0[0] + along[0] * t, c0[1] + along[1] * t, z];
        let r = dot(na, sub(centre, v1));
        if !(r >= self.min_radius_mm && r.is_finite()) {
            return None;
        }
        let ta = [centre[0] - na[0] * r, centre[1] - na[1] * r, z];
        let tb = [centre[0] - nb[0] * r, centre[1] - nb[1] * r, z];
        let before = dot(a, sub(v1, ta));
        let after = dot(b, sub(tb, v2));
        if before > self.room[0] || after > self.room[1] {
            return None;
        }
        let arc: Vec<[f64; 3]> =
            arc_polygon(&centre, &ta, self.side * self.turn, segments).collect();
        let mut new = Vec::with_capacity(arc.len() + 2);
        new.push(pa);
        new.extend_from_slice(&arc);
        new.push(pb);
        // Points the full measurement below would take anyway, first: the middle of the arc
        // and the two corners (most centres fail on one of them).
        if point_polyline(&arc[segments / 2], &self.original) > tolerance_mm
            || point_polyline(&v1, &new) > tolerance_mm
            || point_polyline(&v2, &new) > tolerance_mm
        {
            return None;
        }
        let step = tolerance_mm / 10.0;
        (both_ways(&new, &self.original, step, tolerance_mm) <= tolerance_mm).then_some(Hairpin {
            at: self.i,
            corners: 2,
            radius_mm: r,
            arc,
            before_mm: before,
            after_mm: after,
        })
    }
}

/// The corner kind of two sharp corners across a short leg that are not both rounded alone:
/// one arc for the two, taken wherever it fits (its cost is not weighed).
pub(crate) struct Hairpins;

impl CornerKind for Hairpins {
    fn asks_about(&self, site: &Site<'_>, i: usize) -> bool {
        let m = site.marks;
        i + 2 < m.sharp.len()
            && !m.pinned[i]
            && m.sharp[i]
            && m.sharp[i + 1]
            && !(m.alone[i] && m.alone[i + 1])
    }

    fn propose(&self, site: &Site<'_>, i: usize) -> Option<Proposal> {
        let pin = within(site.path.pts, i, site.blend_tol_mm, site.settings)?;
        Some(Proposal {
            replacement: Replacement::Fitted(pin),
            cost: Cost::Unweighed,
        })
    }

    fn again(&self, pts: &[[f64; 3]], pin: &Hairpin, tol: f64, s: &Settings) -> Option<Hairpin> {
        within(pts, pin.at, tol, s)
    }
}

/// [`find`] at corners `i`, `i + 1` of `pts` within `blend_tol`, for an arc the walk can follow
/// in steps of at least the minimum step each turning by less than its share of the critical
/// angle (with 5 % to spare), reaching along each long leg as far as [`rooms`] allows.
fn within(pts: &[[f64; 3]], i: usize, blend_tol: f64, s: &Settings) -> Option<Hairpin> {
    find(pts, i, blend_tol, min_radius(s), rooms(pts, i)?)
}

/// How far along each long leg of the hairpin at corners `i`, `i + 1` of `pts` its arc may
/// reach: `Tuning::leg_share` of a leg that ends the path, half that where another corner
/// shares it.
pub(crate) fn rooms(pts: &[[f64; 3]], i: usize) -> Option<[f64; 2]> {
    let n = pts.len();
    let room = |leg: usize, far_end: usize| {
        let l = norm(sub(pts.get(leg + 1)?, pts.get(leg)?));
        let shared = far_end != 0 && far_end + 1 != n;
        Some(TUNING.leg_share * l * if shared { 0.5 } else { 1.0 })
    };
    Some([room(i.checked_sub(1)?, i - 1)?, room(i + 1, i + 2)?])
}

/// The smallest radius of a loop the walk can follow in steps of at least the minimum step,
/// each turning by less than its share of the critical angle, with 5 % to spare.
pub(crate) fn min_radius(s: &Settings) -> f64 {
    1.05 * s.min_step_mm / (TUNING.step_turn_share * s.critical_rad)
}

/// A path with its hairpins replaced by their arcs: points, filament at each, and the feed and
/// planned profile of each segment (those of the original segment its middle stands for).
#[derive(Debug, Clone, Default)]
pub(crate) struct Substituted {
    /// The points.
    pub(crate) pts: Vec<[f64; 3]>,
    /// Filament pushed from the path start to each point.
    pub(crate) e: Vec<f64>,
    /// Feed of each segment, mm/s.
    pub(crate) feed: Vec<f64>,
    /// Planned profile of each segment (empty if the original had none).
    pub(crate) planned: Vec<crate::plan::Profile>,
    /// Index of each pin's first point (its arc then runs on for `arc.len()` points).
    pub(crate) starts: Vec<usize>,
}

/// `pts` (filament `e`, feeds `feed`, profiles `planned`) with each of `pins` (sorted, apart)
/// in place of its corners and of the stretch around them it replaces. Each new point stands
/// for the original point at the same fraction of length along the stretch, so the filament
/// pushed up to it is read off the original (spread by length over the new stretch) and the
/// path's total is unchanged.
pub(crate) fn substitute(
    pts: &[[f64; 3]],
    e: &[f64],
    feed: &[f64],
    planned: &[crate::plan::Profile],
    pins: &[Hairpin],
) -> Substituted {
    let arc_len = arc_lengths(pts);
    let segment = |u: f64| segment_at(&arc_len, u, feed.len());
    let e_at = |u: f64| {
        let k = segment(u);
        let (a0, a1) = (arc_len[k], arc_len[k + 1]);
        let t = if a1 > a0 {
            ((u - a0) / (a1 - a0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        e[k] + (e[k + 1] - e[k]) * t
    };
    let mut out = Substituted::default();
    let mut at = Vec::with_capacity(pts.len()); // original arc length of each new point
    let mut pin_of = Vec::with_capacity(pts.len()); // the pin each new point is on, if any
    let mut next = 0usize;
    for (index, pin) in pins.iter().enumerate() {
        let (u0, u1) = pin.span(&arc_len);
        // The original points it replaces: its corners and any strictly inside the stretch.
        let mut first = pin.at;
        while first > next && arc_len[first - 1] > u0 {
            first -= 1;
        }
        let mut last = pin.last_corner(pts.len());
        while last + 2 < pts.len() && arc_len[last + 1] < u1 {
            last += 1;
        }
        for k in next..first.min(pts.len()) {
            out.pts.push(pts[k]);
            out.e.push(e[k]);
            at.push(arc_len[k]);
            pin_of.push(None);
        }
        // Each new point stands for the original point at the same fraction of length.
        out.starts.push(out.pts.len());
        let new_len = arc_lengths(&pin.arc);
        let total = new_len.last().copied().unwrap_or(0.0);
        for (p, l) in pin.arc.iter().zip(&new_len) {
            let f = if total > 0.0 { l / total } else { 0.0 };
            let u = u0 + (u1 - u0) * f;
            out.pts.push(*p);
            out.e.push(e_at(u));
            at.push(u);
            pin_of.push(Some(index));
        }
        next = last + 1;
    }
    for k in next..pts.len() {
        out.pts.push(pts[k]);
        out.e.push(e[k]);
        at.push(arc_len[k]);
        pin_of.push(None);
    }
    out.segments(&at, &pin_of, &arc_len, feed, planned);
    out
}

impl Substituted {
    /// The feed and planned profile of each new segment, from the points' original arc
    /// lengths `at` (on `arc_len`) and the pin each is on: apart from [`substitute`] since
    /// the speeds on an arc are a rule of their own.
    fn segments(
        &mut self,
        at: &[f64],
        pin_of: &[Option<usize>],
        arc_len: &[f64],
        feed: &[f64],
        planned: &[crate::plan::Profile],
    ) {
        let out = self;
        let segment = |u: f64| segment_at(arc_len, u, feed.len());
        // The original's planned speed at original arc length `u`.
        let speed_at = |u: f64| {
            let k = segment(u);
            planned.get(k).map(|p| p.speed_at(u - arc_len[k]))
        };
        for j in 0..at.len().saturating_sub(1) {
            let k = segment(0.5 * (at[j] + at[j + 1]));
            out.feed.push(feed[k]);
            let Some(p) = planned.get(k) else { continue };
            // A side of an arc moves at the speed the original had where it stands for, the
            // lower of its two ends' (the original segment's own profile would be read at
            // distances along the new path, which do not match it).
            let on_arc = pin_of[j].is_some() && pin_of[j] == pin_of[j + 1];
            match (on_arc, speed_at(at[j]), speed_at(at[j + 1])) {
                (true, Some(v0), Some(v1)) => {
                    let v = v0.min(v1);
                    let len = norm(sub(out.pts[j + 1], out.pts[j]));
                    out.planned
                        .push(crate::plan::Profile::new(len, v, v, v, p.acceleration));
                }
                _ => out.planned.push(*p),
            }
        }
        if out.planned.len() != out.feed.len() {
            out.planned.clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vtg::deviation::both_ways;

    /// Two infill lines 0.45 mm apart joined square to them: 90° and 90°.
    fn square_u() -> Vec<[f64; 3]> {
        vec![
            [10.0, 0.0, 0.2],
            [0.0, 0.0, 0.2],
            [0.0, 0.45, 0.2],
            [10.0, 0.45, 0.2],
        ]
    }

    #[test]
    fn a_square_u_turn_becomes_a_half_circle_across_the_spacing() {
        let p = square_u();
        let h = find(&p, 1, 0.08, 0.13, [4.0, 4.0]).expect("hairpin");
        // Radius half the spacing (the legs are parallel), a half turn.
        assert!((h.radius_mm - 0.225).abs() < 1e-9, "{}", h.radius_mm);
        let (first, last) = (h.arc[0], h.arc[h.arc.len() - 1]);
        assert!(first[1].abs() < 1e-9 && (last[1] - 0.45).abs() < 1e-9);
        assert!((first[0] - last[0]).abs() < 1e-9);
        // Within the tolerance of the original both ways, and every arc point on the circle.
        let mut new = vec![p[0]];
        new.extend_from_slice(&h.arc);
        new.push(p[3]);
        let d = both_ways(&new, &p, 1e-3, 0.0);
        assert!(d <= 0.08 + 1e-3, "{d}");
        let centre = [first[0], 0.225, 0.2];
        for q in &h.arc {
            assert!((norm(sub(q, centre)) - 0.225).abs() < 1e-9);
        }
    }

    #[test]
    fn no_hairpin_where_the_arc_would_be_too_tight_or_the_corners_turn_apart() {
        let p = square_u();
        // Radius 0.225 is all the spacing allows.
        assert!(find(&p, 1, 0.08, 0.3, [4.0, 4.0]).is_none());
        // A zig-zag step (left then right) is no hairpin.
        let z = [
            [0.0, 0.0, 0.2],
            [5.0, 0.0, 0.2],
            [5.0, 0.45, 0.2],
            [10.0, 0.45, 0.2],
        ];
        assert!(find(&z, 1, 0.08, 0.1, [4.0, 4.0]).is_none());
        // Not in one plane.
        let mut q = square_u();
        q[2][2] = 0.4;
        assert!(find(&q, 1, 0.08, 0.1, [4.0, 4.0]).is_none());
    }

    #[test]
    fn the_arc_keeps_the_filament_of_the_stretch_it_replaces() {
        let p = square_u();
        let e = [0.0, 0.4, 0.418, 0.818];
        let feed = [40.0, 20.0, 40.0];
        let h = find(&p, 1, 0.08, 0.13, [4.0, 4.0]).expect("hairpin");
        let s = substitute(&p, &e, &feed, &[], std::slice::from_ref(&h));
        assert_eq!(s.pts.len(), 2 + h.arc.len());
        assert_eq!(s.feed.len() + 1, s.pts.len());
        assert_eq!(*s.e.last().unwrap(), 0.818);
        assert!(s.e.windows(2).all(|w| w[1] >= w[0]));
        // The arc starts where the original had pushed 0.4 − (what `before` mm of the first
        // leg carries) and its middle segment takes the connector's feed.
        let expect = 0.4 - 0.04 * h.before_mm;
        assert!((s.e[1] - expect).abs() < 1e-12, "{} {}", s.e[1], expect);
        assert_eq!(s.feed[h.arc.len() / 2], 20.0);
    }
}
