//! Corner blends: the shape a sharp corner is rounded to before the path is fitted.
//!
//! Fitting a B-spline by least squares straight to a polyline's corners lets the fit bend as
//! tightly as its tolerance allows, wherever the residuals put the knots: the curvature peaks
//! high, varies from step to step (and with it the VTG eq. 29 feed caps), and the curve rings along
//! the legs. So each corner is first replaced by a transition of known shape and size, and the
//! fit is given points of the blended path: its curvature is then what the tolerance permits
//! at best, and smooth.
//!
//! The transition is a circular fillet tangent to both legs. Of all curves that turn by `θ`
//! and pass within `ε` of the vertex, the circle has the lowest peak curvature, and the peak
//! curvature is what sets the corner speed (`v = √(A_n/κ)`, VTG eq. 29): a curvature-continuous
//! (G2) transition of the same deviation peaks higher (the symmetric five-point cubic B-spline
//! corner of CNC smoothing by 1.7× at 90°), so the machine would have to slow down more. G2
//! continuity buys little on G-code anyway: the firmware executes the written polyline, whose
//! acceleration arrives as velocity steps at the junctions whatever the curve's continuity; the
//! walk of a circle spreads the turn in equal steps, and the cubic fit (C²) smooths the
//! curvature where the fillet meets the legs.
//!
//! With extent `L` (the distance from the vertex to where the fillet meets each leg) the radius
//! is `r = L / tan(θ/2)`, the distance from the vertex to the fillet `ε = r (sec(θ/2) − 1)` and
//! the curvature `1/r`.
//!
//! Each leg is shared by the corners at its two ends: each corner asks for the `L` its share of
//! the tolerance allows, and a leg too short for both requests is split between them so the
//! larger of their curvatures is least (a gentle corner beside a sharp one leaves the sharp
//! one the room it needs).
//!
//! Where the path has room either side, the corner then takes the racing line (`racing`):
//! the path eases out to the far edge of the tolerance band before the corner, turns on a
//! circle tangent to the legs' offsets that still passes `ε` inside the vertex, and eases back,
//! which widens the circle by `1 + sec(θ/2)` (2.4× at 90°). "Within `ε` of the vertex" above
//! is then the whole story only for the inside line ([`Line::Inside`]), which the pipeline
//! still uses where the wider circle cannot be walked.

use super::{CornerKind, Cost, Proposal, Replacement, Site};
use crate::vec3::{dot, norm, sub};
use crate::vtg::smooth::Settings;
use crate::vtg::tuning::TUNING;

/// Samples per blend given to the fit (its ends included).
pub(crate) const SAMPLES: usize = 9;
/// Turns at or below this are treated as straight, rad (0.5°: nothing to round).
const STRAIGHT_RAD: f64 = 0.5 * std::f64::consts::PI / 180.0;
/// Turns above this are not blended, rad (160°: the fillet's radius falls towards nothing and
/// such reversals cannot be rounded within any useful tolerance anyway).
pub(crate) const MAX_TURN_RAD: f64 = 160.0 * std::f64::consts::PI / 180.0;

/// A corner transition at one vertex.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Blend {
    /// Extent along each leg from the vertex, mm (0: the vertex is kept as it is).
    pub(crate) extent_mm: f64,
    /// Turn of the path at the vertex, rad.
    pub(crate) turn_rad: f64,
    /// Largest distance of the transition from the vertex, mm.
    pub(crate) deviation_mm: f64,
    /// Largest curvature of the transition, 1/mm.
    pub(crate) max_curvature: f64,
    /// How far outside the legs the fillet's tangent lines run (the racing line), mm; 0: the
    /// fillet is tangent to the legs themselves.
    pub(crate) offset_mm: f64,
    /// Length of leg beyond `extent_mm` over which the path eases out to the offset and back
    /// onto the leg, mm (0 without an offset).
    pub(crate) ramp_mm: f64,
}

impl Blend {
    const NONE: Blend = Blend {
        extent_mm: 0.0,
        turn_rad: 0.0,
        deviation_mm: 0.0,
        max_curvature: 0.0,
        offset_mm: 0.0,
        ramp_mm: 0.0,
    };

    /// Length of each leg the blend takes: the fillet's extent and the ramp beyond it.
    fn reach(&self) -> f64 {
        self.extent_mm + self.ramp_mm
    }

    /// Whether the blend can be walked in steps of at least the minimum step, each turning
    /// less than the critical angle (a tighter blend would only trade one sharp turn for
    /// several).
    pub(crate) fn roundable(&self, s: &Settings) -> bool {
        self.extent_mm > 0.0
            && self.max_curvature * s.min_step_mm <= TUNING.step_turn_share * s.critical_rad
    }
}

/// The corner kind of the blends `plan` laid out for a path: each corner's own fillet (or
/// racing line), where it can be walked; it costs its peak curvature.
pub(crate) struct Fillets<'a>(pub(crate) &'a [Blend]);

impl CornerKind for Fillets<'_> {
    fn asks_about(&self, site: &Site<'_>, i: usize) -> bool {
        site.marks.sharp[i]
    }

    fn propose(&self, site: &Site<'_>, i: usize) -> Option<Proposal> {
        let b = self.0.get(i).filter(|b| b.roundable(site.settings))?;
        Some(Proposal {
            replacement: Replacement::Fillet,
            cost: Cost::Curvature(b.max_curvature),
        })
    }
}

/// The shape constants of a fillet turning by `turn` (rad) for `L = 1`: the distance from the
/// vertex to the fillet, and the curvature.
pub(crate) fn shape(turn: f64) -> (f64, f64) {
    let half = 0.5 * turn;
    let tan = crate::math::tan(half);
    let radius = 1.0 / tan;
    (radius * (1.0 / crate::math::cos(half) - 1.0), tan)
}

/// The fillet at vertex `v` between unit directions `a` (in) and `b` (out) turning by `turn`,
/// extent `l`: its point at fraction `t` of the turn.
fn fillet_point(v: &[f64; 3], a: &[f64; 3], b: &[f64; 3], turn: f64, l: f64, t: f64) -> [f64; 3] {
    let half = 0.5 * turn;
    let r = l / crate::math::tan(half);
    // The centre lies on the inner bisector, r / cos(θ/2) from the vertex.
    let m = sub(b, a);
    let lm = norm(m);
    let reach = r / crate::math::cos(half) / lm;
    let c = [
        v[0] + m[0] * reach,
        v[1] + m[1] * reach,
        v[2] + m[2] * reach,
    ];
    // Unit vectors from the centre to the two tangent points, and the slerp between them.
    let t1 = [v[0] - a[0] * l, v[1] - a[1] * l, v[2] - a[2] * l];
    let t2 = [v[0] + b[0] * l, v[1] + b[1] * l, v[2] + b[2] * l];
    let (u1, u2) = (sub(t1, c), sub(t2, c));
    let sin = crate::math::sin;
    let s = sin(turn);
    let (w1, w2) = (sin((1.0 - t) * turn) / s, sin(t * turn) / s);
    [
        c[0] + u1[0] * w1 + u2[0] * w2,
        c[1] + u1[1] * w1 + u2[1] * w2,
        c[2] + u1[2] * w1 + u2[2] * w2,
    ]
}

/// The blend at every vertex of `pts` (none at the two ends) for a deviation of at most
/// `tolerance_mm` from each vertex. No blend asks for more than it needs to bring its peak
/// curvature down to `enough_curvature` (1/mm; the curvature at which the machine's limits no
/// longer slow it, `K_cr`): a gentle turn could be spread over metres within the tolerance, and
/// would take the leg a sharp neighbour needs.
pub(crate) fn plan(
    pts: &[[f64; 3]],
    tolerance_mm: f64,
    enough_curvature: f64,
    line: Line,
) -> Vec<Blend> {
    let n = pts.len();
    if n < 3 {
        return vec![Blend::NONE; n];
    }
    let (mut out, through) = inside_fillets(pts, tolerance_mm, enough_curvature);
    if line == Line::Inside {
        return out;
    }
    // Then, corner by corner, the racing line where the path has room for it: up to the
    // nearest vertex either way that is not straight (less what its own blend takes), or the
    // path's end.
    let along = crate::vtg::bspline::arc_lengths(pts);
    for i in 1..n - 1 {
        if out[i].extent_mm <= 0.0 || out[i].max_curvature <= enough_curvature {
            continue;
        }
        let room = |other: usize| {
            let used = if other == 0 || other == n - 1 {
                0.0
            } else {
                out[other].reach()
            };
            TUNING.leg_share * (along[i] - along[other]).abs() - used
        };
        let back = (0..i).rev().find(|&k| !through[k]).unwrap_or(0);
        let on = (i + 1..n).find(|&k| !through[k]).unwrap_or(n - 1);
        let room = room(back).min(room(on));
        if let Some(r) = racing(out[i], tolerance_mm, enough_curvature, room) {
            out[i] = r;
        }
    }
    out
}

/// [`plan`] on the inside line (at least three points): each corner's fillet with the legs
/// shared between neighbours; and the vertices a ramp out to a racing line may run through
/// (the path is straight there), which the racing lines are then fitted between.
fn inside_fillets(
    pts: &[[f64; 3]],
    tolerance_mm: f64,
    enough_curvature: f64,
) -> (Vec<Blend>, Vec<bool>) {
    let n = pts.len();
    let mut out = vec![Blend::NONE; n];
    let lens: Vec<f64> = pts.windows(2).map(|w| norm(sub(w[1], w[0]))).collect();
    // What each corner asks for.
    let mut want = vec![0.0f64; n];
    let mut shapes = vec![(0.0, 0.0); n];
    let mut through = vec![false; n];
    for i in 1..n - 1 {
        let (la, lb) = (lens[i - 1], lens[i]);
        if la <= 0.0 || lb <= 0.0 {
            continue;
        }
        let a = sub(pts[i], pts[i - 1]);
        let b = sub(pts[i + 1], pts[i]);
        let turn = crate::math::acos((dot(a, b) / (la * lb)).clamp(-1.0, 1.0));
        through[i] = turn <= STRAIGHT_RAD;
        if turn <= STRAIGHT_RAD || turn > MAX_TURN_RAD {
            continue;
        }
        let (c, k) = shape(turn);
        if c <= 0.0 {
            continue;
        }
        out[i].turn_rad = turn;
        shapes[i] = (c, k);
        want[i] = tolerance_mm / c;
        if enough_curvature > 0.0 {
            want[i] = want[i].min(k / enough_curvature);
        }
    }
    // Each leg shared between the corners at its ends so that the larger of their two
    // curvatures is as small as it can be: a blend's curvature is k(θ)/L, so in proportion to
    // k(θ), each at most what it asked for, and what one does not need goes to the other.
    let share = |leg: usize, me: usize, other: Option<usize>| -> f64 {
        let room = TUNING.leg_share * lens[leg];
        let Some(j) = other.filter(|&j| want[j] > 0.0) else {
            return room;
        };
        let (ki, kj) = (shapes[me].1, shapes[j].1);
        let fair = room * ki / (ki + kj);
        if want[j] < room - fair {
            room - want[j]
        } else {
            fair
        }
    };
    for i in 1..n - 1 {
        if want[i] <= 0.0 {
            continue;
        }
        // The path's own ends take no room.
        let before = share(i - 1, i, (i >= 2).then(|| i - 1));
        let after = share(i, i, (i + 2 < n).then_some(i + 1));
        let l = want[i].min(before).min(after);
        let (c, k) = shapes[i];
        out[i].extent_mm = l;
        out[i].deviation_mm = c * l;
        out[i].max_curvature = k / l;
    }
    (out, through)
}

/// Which side of the vertex a blend may use.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Line {
    /// Fillets tangent to the legs: the path stays on or inside the corner.
    Inside,
    /// The racing line where there is room for it, else the inside fillet.
    Racing,
}

/// Peak of `|o''|` of the quintic ease `o(x) = 1 − (10x³ − 15x⁴ + 6x⁵)` on `0..1` (at
/// `x = 1/2 ± √3/6`): `10/√3`.
const EASE_PEAK: f64 = 5.773_502_691_896_258;

/// The quintic ease from 1 (at `x ≤ 0`) to 0 (at `x ≥ 1`), flat and straight at both ends.
fn ease(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    1.0 - x * x * x * (10.0 + x * (6.0 * x - 15.0))
}

/// The racing-line version of `inside` (a fillet tangent to the legs within `tolerance_mm` of
/// the vertex) that fits in `room` of each leg, if one rounds the corner wider.
///
/// A fillet tangent to the legs has to pass within the tolerance of the vertex from the inside
/// only, which caps its radius at `ε / (sec(θ/2) − 1)`. The tolerance is a band on both sides
/// of the path, though: if the path eases out by `s` before the corner, runs round a fillet
/// tangent to the legs' offsets, and eases back after it (out, in, out, as a driver takes a
/// bend), the fillet's innermost point may still pass `ε` inside the vertex, and its radius is
/// `(ε + s sec(θ/2)) / (sec(θ/2) − 1)`: with `s = ε`, `1 + sec(θ/2)` times the inside fillet's
/// (2.4× at 90°, 3.6× at 135°). The machine's speed through it, `√(a r)`, rises by the root of
/// that, which on firmware that takes sharp corners fast (Klipper's square-corner velocity)
/// makes rounding a corner cost no time where the inside fillet did. No radius beyond the
/// `enough_curvature` one is asked for. The ramps are quintic eases whose peak curvature is
/// `Tuning::ramp_curvature_share` of the fillet's.
fn racing(inside: Blend, tolerance_mm: f64, enough_curvature: f64, room: f64) -> Option<Blend> {
    let half = 0.5 * inside.turn_rad;
    let sec = 1.0 / crate::math::cos(half);
    let tan = crate::math::tan(half);
    if !(sec > 1.0 && tan.is_finite()) {
        return None;
    }
    let cap = if enough_curvature > 0.0 {
        1.0 / enough_curvature
    } else {
        f64::INFINITY
    };
    let inside_radius = 1.0 / inside.max_curvature;
    TUNING.racing_offset_shares.iter().find_map(|&share| {
        let radius = ((tolerance_mm + share * tolerance_mm * sec) / (sec - 1.0)).min(cap);
        let offset = ((sec - 1.0) * radius - tolerance_mm) / sec;
        let offset = offset.clamp(0.0, tolerance_mm);
        if radius <= inside_radius || offset <= 0.0 {
            return None;
        }
        let extent = (radius - offset) * tan;
        let ramp = (EASE_PEAK * offset * radius / TUNING.ramp_curvature_share).sqrt();
        (extent > 0.0 && extent + ramp <= room).then_some(Blend {
            extent_mm: extent,
            turn_rad: inside.turn_rad,
            deviation_mm: ((sec - 1.0) * radius - offset * sec).max(offset),
            max_curvature: 1.0 / radius,
            offset_mm: offset,
            ramp_mm: ramp,
        })
    })
}

/// Points of the blended path for the fit, with parameters: the arc length of the original
/// polyline at the point each one stands for (a blend point at fraction `u` of the transition
/// stands for the original point at the same fraction of the stretch it replaces), so the
/// filament pushed up to a point is read off the original. Straight stretches get points at
/// most `spacing_mm` apart, denser near the blends so the knot spans grow gradually.
pub(crate) fn samples(
    pts: &[[f64; 3]],
    blends: &[Blend],
    spacing_mm: f64,
) -> (Vec<[f64; 3]>, Vec<f64>) {
    let n = pts.len();
    let mut out = Sampled {
        data: Vec::with_capacity(n * (SAMPLES + 4)),
        par: Vec::with_capacity(n * (SAMPLES + 4)),
    };
    if n == 0 || blends.len() != n {
        return (out.data, out.par);
    }
    out.push(pts[0], 0.0);
    // The ramps out to the racing lines: each runs from its blend's end along the straight
    // stretch, possibly past straight vertices (no turn, so no blend), so each leg looks for
    // the nearest blend either way through those.
    let racers = Racer::all(pts, blends);
    let along = crate::vtg::bspline::arc_lengths(pts);
    let (prev_blend, next_blend) = nearest_blends(blends);
    let mut ts = Vec::new();
    for i in 0..n - 1 {
        let (a, b) = (pts[i], pts[i + 1]);
        let arc = along[i]; // arc length of the original at pts[i]
        let len = norm(sub(b, a));
        let dir = if len > 0.0 {
            [
                (b[0] - a[0]) / len,
                (b[1] - a[1]) / len,
                (b[2] - a[2]) / len,
            ]
        } else {
            [0.0; 3]
        };
        // The ramps reaching into this leg: the one after the blend before it, the one before
        // the blend after it (arc lengths of their far ends at full offset, signs of travel).
        let racer = |j: Option<usize>| j.and_then(|j| racers[j].map(|r| (along[j], r)));
        let before =
            racer(prev_blend[i]).map(|(at, r)| (r.o.after, at + r.blend.extent_mm, 1.0, r.blend));
        let after = racer(next_blend[i + 1])
            .map(|(at, r)| (r.o.before, at - r.blend.extent_mm, -1.0, r.blend));
        let ramps = [before, after];
        let at = |t: f64| {
            let mut p = [a[0] + dir[0] * t, a[1] + dir[1] * t, a[2] + dir[2] * t];
            for &(normal, from, sign, bl) in ramps.iter().flatten() {
                let offset = bl.offset_mm * ease(sign * (arc + t - from) / bl.ramp_mm);
                // (`racers` holds only blends with a ramp: no division by zero here.)
                for k in 0..3 {
                    p[k] += normal[k] * offset;
                }
            }
            p
        };
        // The straight stretch of this leg, between the blends at its ends.
        let (t0, t1) = (blends[i].extent_mm, len - blends[i + 1].extent_mm);
        if t1 > t0 {
            ts.clear();
            straight(t0, t1, spacing_mm, |t| ts.push(t));
            for &(_, from, sign, bl) in ramps.iter().flatten() {
                ts.extend(
                    (1..RAMP_SAMPLES)
                        .map(|k| from + sign * bl.ramp_mm * k as f64 / RAMP_SAMPLES as f64 - arc)
                        .filter(|t| (t0..=t1).contains(t)),
                );
            }
            ts.sort_by(f64::total_cmp);
            for &t in &ts {
                out.push(at(t), arc + t);
            }
        }
        // The blend at the far end of the leg.
        let bl = &blends[i + 1];
        if i + 2 < n && bl.extent_mm > 0.0 {
            out.fillet(pts, i + 1, bl, racers[i + 1], &dir, arc + len);
        } else {
            out.push(b, arc + len);
        }
    }
    (out.data, out.par)
}

/// The blend nearest each vertex looking back and looking on, through straight vertices (a
/// turn without a blend, the path's ends included, stops the search with `None`): where the
/// racing-line ramps reaching into each leg come from.
fn nearest_blends(blends: &[Blend]) -> (Vec<Option<usize>>, Vec<Option<usize>>) {
    let n = blends.len();
    // The blend at vertex `i` itself, or `None` past a turn without one (a path end included).
    let here = |i: usize| {
        if i == 0 || i + 1 == n || blends[i].turn_rad != 0.0 {
            Some((blends[i].extent_mm > 0.0).then_some(i))
        } else {
            None
        }
    };
    let mut prev_blend = vec![None; n];
    let mut next_blend = vec![None; n];
    for i in 0..n {
        prev_blend[i] = here(i).unwrap_or_else(|| prev_blend[i - 1]);
    }
    for i in (0..n).rev() {
        next_blend[i] = here(i).unwrap_or_else(|| next_blend[i + 1]);
    }
    (prev_blend, next_blend)
}

/// The fit's data points and their parameters, as [`samples`] builds them.
struct Sampled {
    data: Vec<[f64; 3]>,
    par: Vec<f64>,
}

impl Sampled {
    /// Adds point `p` at parameter `u`, unless `u` does not move on from the last one.
    fn push(&mut self, p: [f64; 3], u: f64) {
        if self.par.last().is_none_or(|&last| u > last + 1e-9) {
            self.data.push(p);
            self.par.push(u);
        }
    }

    /// The points of blend `bl` at vertex `v` of `pts` (neither end), entered along `dir`,
    /// `vertex_arc` the original's arc length at the vertex; on a racing line (`racer`) the
    /// fillet is tangent to the legs' offsets, which meet outside the vertex.
    fn fillet(
        &mut self,
        pts: &[[f64; 3]],
        v: usize,
        bl: &Blend,
        racer: Option<Racer>,
        dir: &[f64; 3],
        vertex_arc: f64,
    ) {
        let (b, c) = (pts[v], pts[v + 1]);
        let lc = norm(sub(c, b));
        let out_dir = [(c[0] - b[0]) / lc, (c[1] - b[1]) / lc, (c[2] - b[2]) / lc];
        let l = bl.extent_mm;
        let (vertex, reach) = match racer {
            Some(r) => {
                let half = 0.5 * bl.turn_rad;
                let away = bl.offset_mm / crate::math::cos(half);
                let w = r.o.bisector;
                (
                    [b[0] + w[0] * away, b[1] + w[1] * away, b[2] + w[2] * away],
                    l + bl.offset_mm * crate::math::tan(half),
                )
            }
            None => (b, l),
        };
        for k in 0..SAMPLES {
            let u = k as f64 / (SAMPLES - 1) as f64;
            self.push(
                fillet_point(&vertex, dir, &out_dir, bl.turn_rad, reach, u),
                vertex_arc - l + 2.0 * l * u,
            );
        }
    }
}

/// A blend on a racing line, with its outward directions.
#[derive(Clone, Copy)]
struct Racer {
    blend: Blend,
    o: Outward,
}

impl Racer {
    /// The racing-line blend at each vertex of `pts`, with its outward directions (`None`:
    /// no ramp there).
    fn all(pts: &[[f64; 3]], blends: &[Blend]) -> Vec<Option<Racer>> {
        blends
            .iter()
            .enumerate()
            .map(|(j, bl)| {
                let o = (bl.offset_mm > 0.0 && bl.ramp_mm > 0.0)
                    .then(|| Outward::at(pts, j))
                    .flatten()?;
                Some(Racer { blend: *bl, o })
            })
            .collect()
    }
}

/// Samples across each ramp out to a racing line (its ends excluded).
const RAMP_SAMPLES: usize = 8;

/// The outward directions at a corner: away from the centre of its turn.
#[derive(Clone, Copy)]
struct Outward {
    /// Along the bisector of the two legs.
    bisector: [f64; 3],
    /// Square to the leg into the corner.
    before: [f64; 3],
    /// Square to the leg out of it.
    after: [f64; 3],
}

impl Outward {
    /// At vertex `i` of `pts` (neither end), if it turns.
    fn at(pts: &[[f64; 3]], i: usize) -> Option<Outward> {
        let unit = crate::vtg::hairpin::unit;
        let a = unit(sub(pts.get(i)?, pts.get(i.checked_sub(1)?)?))?;
        let b = unit(sub(pts.get(i + 1)?, pts.get(i)?))?;
        let w = unit(sub(a, b))?;
        let square = |d: &[f64; 3]| {
            let along = dot(w, d);
            unit([
                w[0] - d[0] * along,
                w[1] - d[1] * along,
                w[2] - d[2] * along,
            ])
        };
        Some(Outward {
            bisector: w,
            before: square(&a)?,
            after: square(&b)?,
        })
    }
}

/// Points of a straight stretch `t0..t1` (both ends included): dense at the ends, gaps growing
/// geometrically towards the middle, at most `spacing` apart.
fn straight(t0: f64, t1: f64, spacing: f64, mut each: impl FnMut(f64)) {
    let len = t1 - t0;
    let half = 0.5 * len;
    let first = (spacing.min(half) / 8.0).max(1e-3);
    let mut offsets = vec![0.0];
    let (mut t, mut gap) = (first, first);
    while t < half && offsets.len() < 64 {
        offsets.push(t);
        gap = (2.0 * gap).min(spacing);
        t += gap;
    }
    for &o in &offsets {
        each(t0 + o);
    }
    if half > 0.0 {
        each(t0 + half);
    }
    for &o in offsets.iter().rev() {
        each(t1 - o);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn right_angle_fillet_matches_its_closed_form() {
        // L = 1 at 90°: radius 1, the fillet passes √2 − 1 from the vertex.
        let (c, k) = shape(std::f64::consts::FRAC_PI_2);
        assert!((c - (std::f64::consts::SQRT_2 - 1.0)).abs() < 1e-12, "{c}");
        assert!((k - 1.0).abs() < 1e-12, "{k}");
        // The fillet runs from tangent point to tangent point at constant radius.
        let (a, b) = ([1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let half_pi = std::f64::consts::FRAC_PI_2;
        let p0 = fillet_point(&[0.0; 3], &a, &b, half_pi, 2.0, 0.0);
        let p1 = fillet_point(&[0.0; 3], &a, &b, half_pi, 2.0, 1.0);
        assert!(norm(sub(p0, [-2.0, 0.0, 0.0])) < 1e-12, "{p0:?}");
        assert!(norm(sub(p1, [0.0, 2.0, 0.0])) < 1e-12, "{p1:?}");
        for i in 0..=8 {
            let p = fillet_point(&[0.0; 3], &a, &b, half_pi, 2.0, i as f64 / 8.0);
            assert!((norm(sub(p, [-2.0, 2.0, 0.0])) - 2.0).abs() < 1e-12);
        }
        let mid = fillet_point(&[0.0; 3], &a, &b, half_pi, 2.0, 0.5);
        assert!((norm(mid) - 2.0 * c).abs() < 1e-12);
    }

    #[test]
    fn size_follows_the_tolerance_and_shares_short_legs() {
        let pts = [
            [0.0, 0.0, 0.0],
            [10.0, 0.0, 0.0],
            [10.0, 0.4, 0.0],
            [0.0, 0.4, 0.0],
        ];
        // Within 0.1 mm a right angle asks for 0.1 / (√2 − 1) = 0.241 mm of each leg; two of
        // them share the 0.4 mm leg: 0.9 · 0.2 each.
        let b = plan(&pts, 0.1, 0.0, Line::Inside);
        assert_eq!(b[0].extent_mm, 0.0);
        for bl in &b[1..3] {
            assert!((bl.extent_mm - 0.18).abs() < 1e-12, "{}", bl.extent_mm);
            assert!(bl.deviation_mm < 0.1);
        }
        // With room, the blend uses the whole tolerance.
        let wide = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0]];
        let b = plan(&wide, 0.05, 0.0, Line::Inside);
        assert!((b[1].deviation_mm - 0.05).abs() < 1e-12);
        // The samples stay within the tolerance of the polyline and run forward.
        let (data, par) = samples(&wide, &b, 2.0);
        assert!(par.windows(2).all(|w| w[1] > w[0]));
        for p in &data {
            let d = crate::vtg::deviation::point_polyline(p, &wide);
            assert!(d <= 0.05 + 1e-12, "{d}");
        }
        assert_eq!(data.first(), wide.first());
        assert_eq!(data.last(), wide.last());
    }

    #[test]
    fn the_racing_line_rounds_a_right_angle_wider_within_the_tolerance() {
        // Legs of 10 mm, 0.08 mm: the inside fillet's radius is ε / (√2 − 1); eased out by ε,
        // the racing line's is ε (1 + √2) / (√2 − 1), 2.414 times larger, and still passes ε
        // inside the vertex.
        let eps = 0.08;
        let pts = [[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0]];
        let inside = plan(&pts, eps, 0.0, Line::Inside)[1];
        let racing = plan(&pts, eps, 0.0, Line::Racing)[1];
        let r2 = std::f64::consts::SQRT_2;
        assert!((1.0 / inside.max_curvature - eps / (r2 - 1.0)).abs() < 1e-12);
        let radius = eps * (1.0 + r2) / (r2 - 1.0);
        assert!(
            (1.0 / racing.max_curvature - radius).abs() < 1e-12,
            "{racing:?}"
        );
        assert!((racing.offset_mm - eps).abs() < 1e-12);
        assert!((racing.extent_mm - (radius - eps)).abs() < 1e-12);
        assert!((racing.deviation_mm - eps).abs() < 1e-12);
        // The ramp's peak curvature is its share of the fillet's.
        let ramp_peak = EASE_PEAK * eps / (racing.ramp_mm * racing.ramp_mm);
        assert!((ramp_peak * radius - TUNING.ramp_curvature_share).abs() < 1e-12);
        // The samples: within ε of the corner both ways, outside the first leg by ε where the
        // fillet starts, on the leg again beyond the ramp, and ε inside the vertex at the
        // fillet's middle.
        let blends = [Blend::NONE, racing, Blend::NONE];
        let (data, par) = samples(&pts, &blends, 2.0);
        assert!(par.windows(2).all(|w| w[1] > w[0]));
        let d = crate::vtg::deviation::both_ways(&data, &pts, 1e-3, 0.0);
        assert!((d - eps).abs() <= 0.5e-3 + 1e-9, "{d}");
        let near = |x: f64| {
            data.iter()
                .zip(&par)
                .min_by(|a, b| (a.1 - x).abs().total_cmp(&(b.1 - x).abs()))
                .map(|(p, &u)| (*p, u))
                .expect("samples")
        };
        let (p, u) = near(10.0 - racing.extent_mm);
        assert!((u - (10.0 - racing.extent_mm)).abs() < 1e-9);
        assert!((p[1] + eps).abs() < 1e-9, "{p:?}");
        let beyond = 10.0 - racing.reach() - 0.01;
        assert!(data
            .iter()
            .zip(&par)
            .filter(|(_, &u)| u <= beyond)
            .all(|(p, _)| p[1] == 0.0));
        let (mid, _) = near(10.0);
        assert!((norm(sub(mid, pts[1])) - eps).abs() < 1e-9, "{mid:?}");
        assert!(mid[0] < 10.0 && mid[1] > 0.0);
    }

    #[test]
    fn the_racing_line_needs_room_and_a_ramp_may_run_through_straight_vertices() {
        let eps = 0.08;
        // A leg of 1 mm leaves no room for the full ramp: a smaller offset, or none.
        let short = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 10.0, 0.0]];
        let b = plan(&short, eps, 0.0, Line::Racing)[1];
        assert!(b.reach() <= TUNING.leg_share * 1.0 + 1e-12, "{b:?}");
        assert!(b.offset_mm < eps);
        // The same corner with its first leg cut by straight vertices has the room of the
        // whole leg, and samples that stay within ε.
        let mut cut: Vec<[f64; 3]> = (0..=10).map(|k| [k as f64, 0.0, 0.0]).collect();
        cut.push([10.0, 10.0, 0.0]);
        let blends = plan(&cut, eps, 0.0, Line::Racing);
        let whole = plan(
            &[[0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [10.0, 10.0, 0.0]],
            eps,
            0.0,
            Line::Racing,
        )[1];
        assert_eq!(blends[10], whole);
        assert!(blends[..10].iter().all(|b| b.extent_mm == 0.0));
        let (data, par) = samples(&cut, &blends, 2.0);
        assert!(par.windows(2).all(|w| w[1] > w[0]));
        let d = crate::vtg::deviation::both_ways(&data, &cut, 1e-3, 0.0);
        assert!((d - eps).abs() <= 0.5e-3 + 1e-9, "{d}");
        // Ramp samples were placed on the legs it crosses.
        let on_ramp = data
            .iter()
            .filter(|p| p[1] < -1e-6 && p[1] > -eps + 1e-6)
            .count();
        assert!(on_ramp >= RAMP_SAMPLES - 1, "{on_ramp}");
    }

    #[test]
    fn a_sharp_corner_beside_a_gentle_one_gets_the_room_it_needs() {
        // A 4° turn and a 113° turn 0.514 mm apart (an infill line's end on an oval): sharing
        // the leg in proportion to what each asks for would give the sharp one a fifth of its
        // fillet; shared by curvature, it gets all it asks for and the gentle one the rest.
        let pts = [
            [100.926, 103.954, 0.0],
            [101.13, 102.87, 0.0],
            [101.348, 102.165, 0.0],
            [101.539, 101.688, 0.0],
            [116.313, 116.462, 0.0],
        ];
        let tol = 0.072;
        let b = plan(&pts, tol, 0.05, Line::Inside);
        let sharp = &b[3];
        assert!(sharp.turn_rad.to_degrees() > 110.0);
        let (c, _) = shape(sharp.turn_rad);
        assert!((sharp.extent_mm - tol / c).abs() < 1e-12, "{sharp:?}");
        let leg = super::norm(super::sub(pts[3], pts[2]));
        assert!(b[2].extent_mm + sharp.extent_mm <= TUNING.leg_share * leg + 1e-12);
        assert!(b[2].extent_mm > 0.0);
    }
}
