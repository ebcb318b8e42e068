//! Keyholes: a single corner too sharp to fillet, turned around a small loop instead.
//!
//! The tip of a thin wedge (a perimeter around a narrow spike, a vase's seam fold) turns by
//! 120–150° at one point. A fillet tangent to both legs within the tolerance has a radius of a
//! few hundredths of a millimetre there (at 136° and 0.08 mm, 0.06 mm), far tighter than a
//! Marlin-sized step of 0.06 mm can walk without turning by more than the critical angle, so the
//! corner would stay sharp. The legs are so close to each other near the tip, though, that a
//! circle of the smallest radius the walk can follow, centred on the bisector a little inside
//! the tip, lies within the tolerance of both legs and of the tip itself. The path leaves leg A
//! with a small counter-turn (well under the critical angle), runs along a tangent to the
//! circle, around it past the tip, and back onto leg B the same way: every turn on the way is
//! below the critical angle, and the machine no longer stops at the tip.
//!
//! Of the circles on the bisector, the one whose keyhole strays least from the original, both
//! ways (ranked by the distances of the two polylines' points, then measured in full), is
//! taken; the departure points are the nearest to the tip whose counter-turn stays
//! within its limit. The loop is longer than the stretch it replaces; the stretch's filament is
//! spread over it by length (see [`crate::vtg::hairpin::substitute`]), so the tip gets the material
//! it had, in the same place.

use super::{CornerKind, Cost, Proposal, Replacement, Site};
use crate::vec3::angle;
use crate::vec3::{dot, lerp, norm, sub};
use crate::vtg::bspline::segment_at;
use crate::vtg::deviation::{both_ways, point_polyline};
use crate::vtg::hairpin::{arc_polygon, cross_z, min_radius, unit, Hairpin};
use crate::vtg::smooth::Settings;
use crate::vtg::tuning::TUNING;

/// Smallest turn a keyhole is tried at, rad (60°: below it a corner fillets within the
/// tolerance, or the legs are too short for anything).
const MIN_TURN_RAD: f64 = std::f64::consts::FRAC_PI_3;
/// Largest turn, rad (170°: past it the legs are too close for a loop of any useful radius).
const MAX_TURN_RAD: f64 = 170.0 * std::f64::consts::PI / 180.0;
/// Centres tried along the bisector.
const CENTRES: usize = 12;
/// Spacing of the departure points tried along each leg, mm.
const DEPARTURE_STEP_MM: f64 = 0.01;
/// Farthest departure point tried, in loop radii from the corner (farther, the tangent runs
/// nearly along the leg and the counter-turn no longer shrinks).
const MAX_DEPARTURE_RADII: f64 = 6.0;
/// Distance along each leg over which its direction is read, mm (at most its room).
const PROBE_MM: f64 = 0.3;

/// A polyline with its arc lengths: the point at any arc length.
struct Measured<'a> {
    pts: &'a [[f64; 3]],
    arc: &'a [f64],
}

impl Measured<'_> {
    /// The point at arc length `u`, and the unit direction of the segment it lies on.
    fn at(&self, u: f64) -> Option<([f64; 3], [f64; 3])> {
        let k = segment_at(self.arc, u, self.pts.len().checked_sub(1)?);
        let (a0, a1) = (*self.arc.get(k)?, *self.arc.get(k + 1)?);
        let (p, q) = (self.pts.get(k)?, self.pts.get(k + 1)?);
        let t = if a1 > a0 {
            ((u - a0) / (a1 - a0)).clamp(0.0, 1.0)
        } else {
            0.0
        };
        Some((lerp(p, q, t), unit(sub(q, p))?))
    }

    /// The points strictly between arc lengths `u0 < u1`.
    fn inside(&self, u0: f64, u1: f64) -> &[[f64; 3]] {
        let lo = self.arc.partition_point(|&a| a <= u0);
        let hi = self.arc.partition_point(|&a| a < u1).max(lo);
        self.pts.get(lo..hi).unwrap_or(&[])
    }

    /// The polyline between arc lengths `u0 < u1`, ends included.
    fn between(&self, u0: f64, u1: f64) -> Option<Vec<[f64; 3]>> {
        let mut out = vec![self.at(u0)?.0];
        out.extend_from_slice(self.inside(u0, u1));
        out.push(self.at(u1)?.0);
        Some(out)
    }
}

/// The point where a path from `d` meets the circle (`centre`, `r`) tangentially, travelling
/// round it with the turn's `side` (+1 anticlockwise); `leaving` for the point where a path
/// leaves the circle towards `d`. `None` if `d` is inside the circle.
fn tangent_point(
    d: &[f64; 3],
    centre: &[f64; 3],
    r: f64,
    side: f64,
    leaving: bool,
) -> Option<[f64; 3]> {
    let v = sub(d, centre);
    let dist = norm(v);
    if dist <= r * 1.001 {
        return None;
    }
    let phi = side * crate::math::acos(r / dist) * if leaving { -1.0 } else { 1.0 };
    let (sin, cos) = (crate::math::sin(phi), crate::math::cos(phi));
    let u = [v[0] / dist, v[1] / dist];
    Some([
        centre[0] + r * (u[0] * cos - u[1] * sin),
        centre[1] + r * (u[0] * sin + u[1] * cos),
        centre[2],
    ])
}

/// The keyhole at corner `i` of `pts` (arc lengths `arc`): a loop of radius `radius_mm` that
/// replaces the corner within `tolerance_mm` of the original both ways, leaving the path no
/// more than `room_mm[0]` before the corner and rejoining it no more than `room_mm[1]` after,
/// with counter-turns of at most `max_kink_rad` where it leaves and rejoins. The stretch must
/// lie in one plane of constant Z and turn by 60–170° in all.
pub(crate) fn find(
    pts: &[[f64; 3]],
    arc: &[f64],
    i: usize,
    tolerance_mm: f64,
    radius_mm: f64,
    max_kink_rad: f64,
    room_mm: [f64; 2],
) -> Option<Hairpin> {
    let path = Measured { pts, arc };
    let v = *pts.get(i)?;
    let ui = *arc.get(i)?;
    let (room_a, room_b) = (room_mm[0].min(ui), room_mm[1].min(arc.last()? - ui));
    if !(room_a > 0.0 && room_b > 0.0) {
        return None;
    }
    let z = v[2];
    let (first, last) = (path.at(ui - room_a)?.0, path.at(ui + room_b)?.0);
    let flat = path
        .inside(ui - room_a, ui + room_b)
        .iter()
        .chain([&first, &last])
        .all(|p| (p[2] - z).abs() <= 1e-9);
    if !flat {
        return None;
    }
    // The legs' directions, read over the probe length.
    let a = unit(sub(v, path.at(ui - room_a.min(PROBE_MM))?.0))?;
    let b = unit(sub(path.at(ui + room_b.min(PROBE_MM))?.0, v))?;
    let turn = angle(a, b);
    if !(MIN_TURN_RAD..=MAX_TURN_RAD).contains(&turn) {
        return None;
    }
    let wedge = Wedge {
        path,
        i,
        v,
        ui,
        room: [room_a, room_b],
        turn,
        side: cross_z(&a, &b).signum(),
        // Into the wedge, halfway between the legs.
        inward: unit(sub(b, a))?,
        tolerance_mm,
        radius_mm,
        max_kink_rad,
    };
    // The corner is within the tolerance of the circle only for centres `c` from the corner
    // within `r ± tol`, and the circle bulges past leg A's line by `r − c sin(α/2)` (α the
    // wedge's angle, π − turn), which must be within the tolerance too.
    let half_wedge = 0.5 * (std::f64::consts::PI - turn);
    let lo = (radius_mm - tolerance_mm)
        .max((radius_mm - tolerance_mm) / crate::math::sin(half_wedge).max(1e-9))
        .max(0.0);
    let hi = radius_mm + tolerance_mm;
    if lo > hi {
        return None;
    }
    let mut found: Vec<_> = (0..=CENTRES)
        .filter_map(|k| wedge.candidate(lo + (hi - lo) * k as f64 / CENTRES as f64))
        .collect();
    found.sort_by(|x, y| x.0.total_cmp(&y.0));
    // The closest that the full measurement, both ways, keeps within the tolerance.
    found
        .into_iter()
        .find(|(_, h, original)| {
            both_ways(&h.arc, original, tolerance_mm / 10.0, tolerance_mm) <= tolerance_mm
        })
        .map(|(_, h, _)| h)
}

/// The corner kind of a single corner too tight to fillet, where keyholes are on: a loop round
/// it, of the smallest radius the walk follows, so its cost (the loop's curvature) is known
/// before it is sought.
pub(crate) struct Keyholes;

impl CornerKind for Keyholes {
    fn asks_about(&self, site: &Site<'_>, i: usize) -> bool {
        site.settings.keyholes && site.marks.tight[i] && !site.marks.pinned[i]
    }

    fn known_cost(&self, s: &Settings) -> Option<Cost> {
        Some(Cost::Curvature(1.0 / min_radius(s)))
    }

    fn propose(&self, site: &Site<'_>, i: usize) -> Option<Proposal> {
        Some(Proposal {
            replacement: Replacement::Fitted(within(site, i)?),
            cost: self.known_cost(site.settings)?,
        })
    }
}

/// [`find`] at corner `i` of `site` within its blend share of the tolerance, on a loop of the
/// hairpins' smallest radius, with counter-turns of at most `Tuning::kink_share` of the
/// critical angle. The loop may reach along the path up to `Tuning::leg_share` of the way to
/// the path's ends and half the way to the nearest corner that is sharp, already replaced or
/// degenerate (which the piece may be cut at).
fn within(site: &Site<'_>, i: usize) -> Option<Hairpin> {
    let (pts, arc, m, s) = (site.path.pts, site.arc, site.marks, site.settings);
    let n = pts.len();
    let stop = |k: usize| k == 0 || k + 1 == n || m.sharp[k] || m.pinned[k] || m.degenerate[k];
    let share = |k: usize| {
        if k == 0 || k + 1 == n {
            TUNING.leg_share
        } else {
            0.5
        }
    };
    let back = (0..i).rev().find(|&k| stop(k))?;
    let on = (i + 1..n).find(|&k| stop(k))?;
    let room = [
        share(back) * (arc[i] - arc[back]),
        share(on) * (arc[on] - arc[i]),
    ];
    find(
        pts,
        arc,
        i,
        site.blend_tol_mm,
        min_radius(s),
        TUNING.kink_share * s.critical_rad,
        room,
    )
}

/// A flat corner a keyhole is sought for, with what every candidate loop is measured against:
/// split from [`find`] so the search over centres reads apart from building one loop.
struct Wedge<'a> {
    path: Measured<'a>,
    /// The corner's index, its point and arc length.
    i: usize,
    v: [f64; 3],
    ui: f64,
    /// Room before and after the corner, mm.
    room: [f64; 2],
    /// The corner's turn, rad, and its sense about +Z.
    turn: f64,
    side: f64,
    /// Into the wedge, halfway between the legs.
    inward: [f64; 3],
    tolerance_mm: f64,
    radius_mm: f64,
    max_kink_rad: f64,
}

impl Wedge<'_> {
    /// The first departure point from the corner, `sign` -1 back along leg A, +1 on along leg
    /// B, whose counter-turn onto the tangent of the circle centred `centre` stays within the
    /// limit: its distance from the corner, the point and the tangent point.
    fn depart(&self, centre: &[f64; 3], sign: f64, room: f64) -> Option<(f64, [f64; 3], [f64; 3])> {
        let radius_mm = self.radius_mm;
        let steps =
            (room.min(MAX_DEPARTURE_RADII * radius_mm) / DEPARTURE_STEP_MM).floor() as usize;
        (1..=steps).find_map(|k| {
            let d = k as f64 * DEPARTURE_STEP_MM;
            let (p, dir) = self.path.at(self.ui + sign * d)?;
            let t = tangent_point(&p, centre, radius_mm, self.side, sign > 0.0)?;
            let line = if sign < 0.0 { sub(t, p) } else { sub(p, t) };
            (angle(dir, unit(line)?) <= self.max_kink_rad).then_some((d, p, t))
        })
    }

    /// A keyhole round the circle centred `c` from the corner, the original stretch it
    /// replaces, and how far their points are from each other's polyline (a lower bound of the
    /// deviation, close to it, and cheap: what the candidates are ranked by).
    fn candidate(&self, c: f64) -> Option<(f64, Hairpin, Vec<[f64; 3]>)> {
        let (v, inward, side) = (self.v, self.inward, self.side);
        let (tolerance_mm, radius_mm) = (self.tolerance_mm, self.radius_mm);
        let centre = [v[0] + inward[0] * c, v[1] + inward[1] * c, v[2]];
        // The corner must be within reach of the loop, and the loop's far side of the corner.
        if (norm(sub(v, centre)) - radius_mm).abs() > tolerance_mm {
            return None;
        }
        let (before, da, ta) = self.depart(&centre, -1.0, self.room[0])?;
        let (after, db, tb) = self.depart(&centre, 1.0, self.room[1])?;
        // Round the circle from `ta` to `tb` the way the corner turns.
        let (ra, rb) = (sub(ta, centre), sub(tb, centre));
        let mut span = side * crate::math::atan2(cross_z(&ra, &rb), dot(ra, rb));
        if span < 0.0 {
            span += 2.0 * std::f64::consts::PI;
        }
        if span > self.turn + 2.0 * self.max_kink_rad + 1e-9 {
            return None;
        }
        let segments = (span / TUNING.polygon_turn_rad).ceil().max(1.0) as usize;
        let mut loop_pts = Vec::with_capacity(segments + 3);
        loop_pts.push(da);
        loop_pts.extend(arc_polygon(&centre, &ta, side * span, segments));
        loop_pts.push(db);
        let original = self.path.between(self.ui - before, self.ui + after)?;
        let near = |a: &[[f64; 3]], b: &[[f64; 3]]| {
            a.iter().map(|p| point_polyline(p, b)).fold(0.0, f64::max)
        };
        let apart = near(&loop_pts, &original).max(near(&original, &loop_pts));
        (apart <= tolerance_mm).then_some((
            apart,
            Hairpin {
                at: self.i,
                corners: 1,
                radius_mm,
                arc: loop_pts,
                before_mm: before,
                after_mm: after,
            },
            original,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::vtg::bspline::arc_lengths;
    use crate::vtg::hairpin::substitute;

    /// A wedge tip turning by `turn_deg`, legs of `len` mm in steps of `step` mm.
    fn wedge(turn_deg: f64, len: f64, step: f64) -> (Vec<[f64; 3]>, usize) {
        let half = (180.0 - turn_deg).to_radians() / 2.0;
        let n = (len / step).round() as usize;
        let mut pts = Vec::new();
        for k in (1..=n).rev() {
            let d = k as f64 * step;
            pts.push([d * half.cos(), d * half.sin(), 0.2]);
        }
        pts.push([0.0, 0.0, 0.2]);
        for k in 1..=n {
            let d = k as f64 * step;
            pts.push([d * half.cos(), -d * half.sin(), 0.2]);
        }
        (pts, n)
    }

    fn turn_at(p: &[[f64; 3]], k: usize) -> f64 {
        angle(
            unit(sub(p[k], p[k - 1])).unwrap(),
            unit(sub(p[k + 1], p[k])).unwrap(),
        )
    }

    #[test]
    fn a_thin_wedge_tip_becomes_a_loop_within_the_tolerance() {
        let (p, i) = wedge(136.0, 1.0, 0.07);
        let arc = arc_lengths(&p);
        let (tol, r, kink) = (0.08, 0.134, 24f64.to_radians());
        let h = find(&p, &arc, i, tol, r, kink, [0.9, 0.9]).expect("keyhole");
        assert_eq!((h.at, h.corners), (i, 1));
        // It starts and ends on the legs, within the room.
        assert!(h.before_mm > 0.0 && h.before_mm <= 0.9 && h.after_mm <= 0.9);
        let (first, last) = (h.arc[0], h.arc[h.arc.len() - 1]);
        let on_leg = |q: &[f64; 3]| point_polyline(q, &p) < 1e-9;
        assert!(on_leg(&first) && on_leg(&last));
        // Every turn on it, joins included, is below the counter-turn limit or the polygon's.
        let mut whole = vec![p[0]];
        whole.extend_from_slice(&h.arc);
        whole.push(p[p.len() - 1]);
        for k in 1..whole.len() - 1 {
            let t = turn_at(&whole, k);
            assert!(t <= kink + 1e-9, "turn {} at {k}", t.to_degrees());
        }
        // The loop's sides are equal chords of the circle of radius `r`.
        let chord = norm(sub(h.arc[2], h.arc[1]));
        for w in h.arc[1..h.arc.len() - 1].windows(2) {
            assert!((norm(sub(w[1], w[0])) - chord).abs() < 1e-9);
        }
        assert!(chord <= r * TUNING.polygon_turn_rad + 1e-9);
        let d = both_ways(&whole, &p, 1e-3, 0.0);
        assert!(d <= tol + 1e-3, "{d}");
        // The tip itself is passed within the tolerance.
        assert!(point_polyline(&[0.0, 0.0, 0.2], &h.arc) <= tol);
    }

    /// In the path, the loop replaces the tip and the leg points it passes; it carries the
    /// filament of the stretch it replaces, and each of its sides is planned at the lower of
    /// the original's speeds at the two places it stands for.
    #[test]
    fn the_loop_keeps_the_filament_and_the_speed_of_the_stretch() {
        let (p, i) = wedge(136.0, 1.0, 0.07);
        let arc = arc_lengths(&p);
        let h = find(&p, &arc, i, 0.08, 0.134, 24f64.to_radians(), [0.9, 0.9]).expect("keyhole");
        let e: Vec<f64> = arc.iter().map(|a| 0.04 * a).collect();
        let feed = vec![30.0; p.len() - 1];
        // The original slows from 30 mm/s down to 5 at the tip and back up.
        let planned: Vec<crate::plan::Profile> = (0..p.len() - 1)
            .map(|k| {
                let v = |j: usize| 5.0 + 25.0 * (arc[j] - arc[i]).abs().min(1.0);
                let len = arc[k + 1] - arc[k];
                crate::plan::Profile::new(len, v(k), 30.0, v(k + 1), 1000.0)
            })
            .collect();
        let s = substitute(&p, &e, &feed, &planned, std::slice::from_ref(&h));
        let replaced = arc
            .iter()
            .filter(|&&a| a > arc[i] - h.before_mm && a < arc[i] + h.after_mm)
            .count();
        assert_eq!(s.pts.len(), p.len() - replaced + h.arc.len());
        assert_eq!(*s.e.last().unwrap(), *e.last().unwrap());
        assert!(s.e.windows(2).all(|w| w[1] >= w[0]));
        assert_eq!(
            (s.feed.len(), s.planned.len()),
            (s.pts.len() - 1, s.pts.len() - 1)
        );
        // The loop's sides (bar the two straights onto the legs) run at most at the speed the
        // original had within `before`/`after` of the tip, which is under 30 mm/s.
        let first = s.pts.iter().position(|q| *q == h.arc[0]).unwrap();
        for k in first + 1..first + h.arc.len() - 2 {
            let pr = &s.planned[k];
            assert_eq!(pr.entry, pr.exit);
            assert!(
                pr.peak < 5.0 + 25.0 * h.before_mm.max(h.after_mm) + 1e-9,
                "{pr:?}"
            );
        }
    }

    #[test]
    fn no_keyhole_where_the_legs_are_too_close_or_too_short() {
        // 165°: the legs are 0.06 mm apart 0.45 mm from the tip.
        let (p, i) = wedge(165.0, 1.0, 0.07);
        let arc = arc_lengths(&p);
        assert!(find(&p, &arc, i, 0.08, 0.134, 24f64.to_radians(), [0.9, 0.9]).is_none());
        // 136°, but climbing (a spiral vase): the loop would leave its plane.
        let (mut p, i) = wedge(136.0, 1.0, 0.07);
        for (k, q) in p.iter_mut().enumerate().skip(i + 1) {
            q[2] += 0.002 * (k - i) as f64;
        }
        let arc = arc_lengths(&p);
        assert!(find(&p, &arc, i, 0.08, 0.134, 24f64.to_radians(), [0.9, 0.9]).is_none());
        // 136° but only 0.1 mm of leg each side.
        let (p, i) = wedge(136.0, 1.0, 0.05);
        let arc = arc_lengths(&p);
        assert!(find(&p, &arc, i, 0.08, 0.134, 24f64.to_radians(), [0.1, 0.1]).is_none());
    }
}
