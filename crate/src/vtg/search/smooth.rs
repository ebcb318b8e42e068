//! One extrusion path through the VTG pipeline: blend its corners, fit (within tolerance), walk
//! the curve with Algorithm 1, spread the path's filament over the new points, cap the feed
//! where the curvature is above `K_cr`, and check the result against the original polyline.
//! The feed each new segment is then written with is [`crate::vtg::feed`]'s business.
//!
//! The tolerance is shared: the corner blends ([`crate::vtg::blend`]) may use `Tuning::blend_share`
//! of it, the fit's residuals `Tuning::fit_share` and the chords of the walk `Tuning::chord_share`
//! (together a little more than all of it: they seldom peak at the same point). If the measured
//! deviation still exceeds the tolerance, the blends are made smaller and the path tried again; a
//! path that cannot be rounded within the tolerance is kept as it was.

use crate::plan::Profile;
use crate::vec3::{dot, norm, sub};
use crate::vtg::blend;
use crate::vtg::bspline::{arc_lengths, segment_at};
use crate::vtg::deviation::both_ways;
use crate::vtg::feed::StepSpeed;
use crate::vtg::fit::fit;
use crate::vtg::hairpin;
use crate::vtg::keyhole;
use crate::vtg::kinematics::KinematicLimits;
use crate::vtg::klipper;
use crate::vtg::resample::{walk_curve, Sample, Walk, WalkStats};
use crate::vtg::tuning::TUNING;

/// Settings for [`smooth_path`].
#[derive(Debug, Clone, Copy)]
pub(crate) struct Settings {
    /// Tolerance, mm.
    pub(crate) tolerance_mm: f64,
    /// Critical angle δθ, rad.
    pub(crate) critical_rad: f64,
    /// Kinematic limits (VTG eq. 29–30).
    pub(crate) limits: KinematicLimits,
    /// Lower the feed where the curvature is above what the limits allow (VTG eq. 29).
    pub(crate) limit_feed: bool,
    /// The machine's X/Y acceleration limit (`M201`), mm/s²: the ceiling of `A_n`. Where the
    /// original's planned moves are known, `A_n` of a stretch is the acceleration the firmware
    /// used there (files change it per feature), within this.
    pub(crate) max_normal_accel_mm_s2: f64,
    /// `f₁` when `J_n` follows `A_n` (`J_n = A_n f₁`, the default), Hz; `None` keeps
    /// `limits.normal_jerk_mm_s3` everywhere.
    pub(crate) jerk_per_accel_hz: Option<f64>,
    /// Shortest interpolation step, mm (`Tuning::klipper_min_step_mm` or
    /// `Tuning::marlin_min_step_mm`).
    pub(crate) min_step_mm: f64,
    /// The per-axis jerk of a classic-jerk firmware, mm/s (`None` on junction-deviation and
    /// Klipper planners): rising feeds are then ramped, since such a planner counts a rise of
    /// the feed from one block to the next as jerk against the new block's full speed.
    pub(crate) classic_jerk_mm_s: Option<f64>,
    /// The first scale of the VTG eq. 29 speeds a rewrite is tried with (1: the speeds as they
    /// are); [`crate::vtg::vtg`] raises it where the dynamics model finds the rewrite at 1
    /// rings more than the original.
    pub(crate) feed_cap_scale: f64,
    /// Write runs of new points that lie on a circle as arcs (`G2`/`G3`, [`crate::vtg::arcs`]).
    pub(crate) arcs: bool,
    /// The slowest a rounded corner may be run, as a share of the firmware's speed through the
    /// sharp one: 1 rounds only the corners the machine runs round at least as fast (the free
    /// rewrite); below 1, the dearer variants of a path that
    /// [`crate::vtg::VtgOptions::allow_slower_pct`] may buy (0 rounds every corner it can).
    pub(crate) min_speed_share: f64,
    /// Turn single corners too tight to fillet round a [`keyhole`] loop where one fits.
    pub(crate) keyholes: bool,
    /// Which side of its corners a path may be rounded on ([`blend::Line`]).
    pub(crate) line: blend::Line,
    /// Klipper's square-corner velocity, mm/s, on a Klipper machine (`None` elsewhere): its
    /// sharp corners are then turned as polygons placed for its look-ahead ([`klipper`]).
    pub(crate) klipper_scv_mm_s: Option<f64>,
}

/// A rewritten path: the new geometry, and what the feed of each new segment is made of.
#[derive(Debug, Clone, Default)]
pub(crate) struct Smoothed {
    /// New points after the start point (the last equals the original end).
    pub(crate) points: Vec<[f64; 3]>,
    /// Filament pushed from the path start to each point, mm.
    pub(crate) e: Vec<f64>,
    /// The speed terms of the segment ending at each point.
    pub(crate) steps: Vec<StepSpeed>,
    /// Segments whose curvature stays above `K_cr`.
    pub(crate) above_k_cr: u64,
    /// Measured largest distance to the original polyline, mm.
    pub(crate) deviation_mm: f64,
    /// Walk statistics (VTG eq. 28).
    pub(crate) stats: WalkStats,
    /// Corners turned round a keyhole loop.
    pub(crate) keyholes: u64,
}

/// A path to rewrite: its points, and what the original asks of each stretch.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SmoothPath<'a> {
    /// The polyline.
    pub(crate) pts: &'a [[f64; 3]],
    /// Filament pushed from the path start to each point, mm (from 0).
    pub(crate) e: &'a [f64],
    /// Feed of segment `i` (from `pts[i]` to `pts[i+1]`), mm/s.
    pub(crate) feed: &'a [f64],
    /// How the firmware's planner runs each original segment (empty when not known): the
    /// VTG eq. 29 feed cap never asks for less than the speed the machine had at the same place on
    /// the original. At that speed the sharp corner is a step in velocity and the rounded one a
    /// finite acceleration, so capping below it would only cost time (on a Klipper machine
    /// with a high square-corner velocity, VTG eq. 29's normal-jerk term would slow every corner
    /// down, and even at a classic-jerk corner the machine is back at speed within a few
    /// tenths of a millimetre on either side of the vertex).
    pub(crate) planned: &'a [Profile],
}

impl<'a> SmoothPath<'a> {
    /// Whether the arrays agree with each other.
    fn consistent(&self) -> bool {
        let n = self.pts.len();
        self.e.len() == n
            && self.feed.len() + 1 == n
            && (self.planned.is_empty() || self.planned.len() + 1 == n)
    }

    /// The piece from point `a` to point `b` (both included).
    fn piece(&self, a: usize, b: usize) -> Option<SmoothPath<'a>> {
        Some(SmoothPath {
            pts: self.pts.get(a..=b)?,
            e: self.e.get(a..=b)?,
            feed: self.feed.get(a..b)?,
            planned: if self.planned.is_empty() {
                &[]
            } else {
                self.planned.get(a..b)?
            },
        })
    }
}

/// Rewrites `path`; `None`: keep it.
///
/// Corners too sharp to be rounded within the tolerance in steps that each turn less than the
/// critical angle are kept as they are: the path is split there and each piece is fitted on its
/// own with its ends pinned (rounding such a corner would only trade one sharp turn for
/// several). Pieces without a sharp corner, and pieces that cannot be fitted within the
/// tolerance, keep their original points.
///
/// On the racing line, corners too tight for an inside fillet may be rounded by the wider
/// racing-line one, which the fit and walk do not always manage to follow in steps under δθ
/// (it then stays sharp): where that happened, the path is also rounded on the inside line
/// (with its hairpins and keyholes) and the one left with fewer sharp turns is kept.
pub(crate) fn smooth_path(path: &SmoothPath<'_>, s: &Settings) -> Option<Smoothed> {
    let corners = polygon_corners(path, s);
    if corners.is_empty() {
        return smooth_cut(path, s, &[]);
    }
    let pins: Vec<hairpin::Hairpin> = corners.iter().map(|c| c.pin.clone()).collect();
    let mut sub = hairpin::substitute(path.pts, path.e, path.feed, path.planned, &pins);
    // A polygon's sides are run as the firmware will: no ceiling below the legs' own peak
    // (the substitute's profiles are the original's speeds near the corner).
    for (&start, pin) in sub.starts.iter().zip(&pins) {
        let sides = pin.arc.len() - 1;
        for j in 0..sides {
            let leg = if 2 * j < sides { pin.at - 1 } else { pin.at };
            if let (Some(slot), Some(p)) = (sub.planned.get_mut(start + j), path.planned.get(leg)) {
                *slot = *p;
            }
        }
    }
    // The polygons are written as they are: the path is cut at their two ends.
    let cuts: Vec<usize> = sub
        .starts
        .iter()
        .zip(&pins)
        .flat_map(|(&k, p)| [k, k + p.arc.len() - 1])
        .collect();
    let replaced = SmoothPath {
        pts: &sub.pts,
        e: &sub.e,
        feed: &sub.feed,
        planned: &sub.planned,
    };
    let mut out = smooth_cut(&replaced, s, &cuts)?;
    for c in &corners {
        out.deviation_mm = out.deviation_mm.max(c.deviation_mm);
    }
    Some(out)
}

/// [`smooth_path`] without polygon corners, the path also cut at the points `forced` (whose
/// pieces are kept as they are unless they have a sharp corner).
fn smooth_cut(path: &SmoothPath<'_>, s: &Settings, forced: &[usize]) -> Option<Smoothed> {
    let (result, rescued) = smooth_on(path, s, forced);
    if !rescued {
        return result;
    }
    let cos_critical = crate::math::cos(s.critical_rad);
    let left = |r: &Option<Smoothed>| {
        r.as_ref().map_or(usize::MAX, |r| {
            crate::vtg::rewrite::sharp_turns(path.pts.iter().take(1).chain(&r.points), cos_critical)
        })
    };
    let left_wide = left(&result);
    if left_wide == 0 {
        return result;
    }
    let inside_line = Settings {
        line: blend::Line::Inside,
        ..*s
    };
    let (inside, _) = smooth_on(path, &inside_line, forced);
    if left(&inside) < left_wide {
        inside
    } else {
        result
    }
}

/// [`smooth_path`] on the line `s` asks for; and whether the racing line made a corner
/// roundable that the inside fillet could not round.
fn smooth_on(path: &SmoothPath<'_>, s: &Settings, forced: &[usize]) -> (Option<Smoothed>, bool) {
    let pts = path.pts;
    if pts.len() < 3 || !path.consistent() {
        return (None, false);
    }
    let mut c = Corners::classify(path, s);
    let arc = arc_lengths(pts);
    let pins = c.pin(path, &arc, s);
    let cuts = c.cuts(&pins, &arc, forced);
    let rescued = c.rescued;
    match smooth_pieces(path, s, &cuts, &c.sharp, &pins) {
        Some((out, changed)) => ((changed || !forced.is_empty()).then_some(out), rescued),
        None => (None, rescued),
    }
}

/// What each point of a path is as a corner; kept in one place because the hairpin, keyhole
/// and cut decisions all read (and the cuts clear) the same flags.
struct Corners {
    /// A turn above the critical angle.
    sharp: Vec<bool>,
    /// Can be rounded on its own, at no loss of speed.
    alone: Vec<bool>,
    /// A zero-length leg meets it.
    degenerate: Vec<bool>,
    /// Too tight to round within the tolerance (rather than not worth it).
    tight: Vec<bool>,
    /// Turned into a hairpin or keyhole.
    pinned: Vec<bool>,
    /// The racing line made a corner roundable that the inside fillet could not round.
    rescued: bool,
}

impl Corners {
    /// Each corner: sharp, and whether it can be rounded on its own.
    fn classify(path: &SmoothPath<'_>, s: &Settings) -> Self {
        let pts = path.pts;
        let cos_critical = crate::math::cos(s.critical_rad);
        let plan = |line| {
            blend::plan(
                pts,
                TUNING.blend_share * s.tolerance_mm,
                s.limits.critical_curvature(),
                line,
            )
        };
        let blends = plan(s.line);
        let inside = (s.line != blend::Line::Inside).then(|| plan(blend::Line::Inside));
        let n = pts.len();
        let mut c = Corners {
            sharp: vec![false; n],
            alone: vec![true; n],
            degenerate: vec![false; n],
            tight: vec![false; n],
            pinned: vec![false; n],
            rescued: false,
        };
        for i in 1..n - 1 {
            let a = sub(pts[i], pts[i - 1]);
            let b = sub(pts[i + 1], pts[i]);
            let (la, lb) = (norm(a), norm(b));
            if la <= 0.0 || lb <= 0.0 {
                c.degenerate[i] = true;
                continue;
            }
            let cos = (dot(a, b) / (la * lb)).clamp(-1.0, 1.0);
            if cos >= cos_critical {
                continue;
            }
            c.sharp[i] = true;
            c.tight[i] = !roundable(&blends[i], s);
            c.rescued |= !c.tight[i] && inside.as_ref().is_some_and(|b| !roundable(&b[i], s));
            c.alone[i] = !c.tight[i] && pays(blends[i].max_curvature, path.planned.get(i - 1), s);
        }
        c
    }

    /// The hairpins and keyholes of the path, in order: the corners that cannot be rounded
    /// alone but can as one turn (two across a short leg) or round a loop (one too tight).
    fn pin(&mut self, path: &SmoothPath<'_>, arc: &[f64], s: &Settings) -> Vec<hairpin::Hairpin> {
        let pts = path.pts;
        let n = pts.len();
        // Two sharp corners across a short leg, at least one of them too tight alone: a
        // hairpin, rounded as one turn if it can be.
        let mut pins: Vec<hairpin::Hairpin> = Vec::new();
        let mut i = 1;
        while i + 2 < n {
            if self.sharp[i] && self.sharp[i + 1] && !(self.alone[i] && self.alone[i + 1]) {
                if let Some(pin) = find_hairpin(pts, i, TUNING.blend_share * s.tolerance_mm, s) {
                    self.pinned[i] = true;
                    self.pinned[i + 1] = true;
                    pins.push(pin);
                    i += 2;
                    continue;
                }
            }
            i += 1;
        }
        // Single corners too tight to round: a keyhole loop, where one fits between the
        // neighbours and the machine runs round it at least as fast as through the corner.
        let loop_pays = |i: usize| pays(1.0 / min_hairpin_radius(s), path.planned.get(i - 1), s);
        for i in 1..n - 1 {
            if s.keyholes && self.tight[i] && !self.pinned[i] && loop_pays(i) {
                let found =
                    find_keyhole(pts, arc, i, &self.sharp, &self.pinned, &self.degenerate, s);
                if let Some(k) = found {
                    self.pinned[i] = true;
                    pins.push(k);
                }
            }
        }
        pins.sort_by_key(|p| p.at);
        pins
    }

    /// The points the path is cut at (its ends included): corners kept sharp (no longer
    /// counted as sharp), either side of a keyhole, and `forced`.
    fn cuts(&mut self, pins: &[hairpin::Hairpin], arc: &[f64], forced: &[usize]) -> Vec<usize> {
        let n = self.sharp.len();
        let mut cuts = vec![0usize];
        for i in 1..n - 1 {
            if self.degenerate[i] || (self.sharp[i] && !self.alone[i] && !self.pinned[i]) {
                cuts.push(i);
                self.sharp[i] = false;
            }
        }
        // A keyhole is fitted on its own, between the original points either side of the
        // stretch it replaces (on its straight legs): the rest of a long side need not be
        // fitted again.
        let spans: Vec<(f64, f64)> = pins.iter().map(|p| p.span(arc)).collect();
        let free = |j: usize| {
            j > 0
                && j + 1 < n
                && !self.sharp[j]
                && !self.pinned[j]
                && spans.iter().all(|&(u0, u1)| arc[j] <= u0 || arc[j] >= u1)
        };
        for (k, &(u0, u1)) in pins.iter().zip(&spans).filter(|(p, _)| p.corners == 1) {
            let before = (0..k.at).rev().find(|&j| arc[j] <= u0);
            let after = (k.at + 1..n).find(|&j| arc[j] >= u1);
            cuts.extend(before.into_iter().chain(after).filter(|&j| free(j)));
        }
        cuts.extend(forced.iter().filter(|&&j| j < n));
        cuts.push(n - 1);
        cuts.sort_unstable();
        cuts.dedup();
        cuts
    }
}

/// Each piece between two `cuts` smoothed on its own (or kept) and joined; and whether any was
/// rewritten. `None` when a cut falls outside the path.
fn smooth_pieces(
    path: &SmoothPath<'_>,
    s: &Settings,
    cuts: &[usize],
    sharp: &[bool],
    pins: &[hairpin::Hairpin],
) -> Option<(Smoothed, bool)> {
    let mut out = Smoothed::default();
    let mut changed = false;
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let piece = path.piece(a, b)?;
        let has_sharp = sharp.get(a + 1..b).is_some_and(|v| v.iter().any(|&x| x));
        let here: Vec<hairpin::Hairpin> = pins
            .iter()
            .filter(|p| p.at > a && p.at < b)
            .map(|p| hairpin::Hairpin {
                at: p.at - a,
                ..p.clone()
            })
            .collect();
        let keyholes = here.iter().filter(|p| p.corners == 1).count() as u64;
        let mut done =
            smooth_piece(&piece, s, has_sharp, &here).map(|p| Smoothed { keyholes, ..p });
        if done.is_none() && keyholes > 0 {
            // A loop the fit or the walk could not keep within the tolerance: the piece
            // again without keyholes, its tight corners kept sharp.
            let plain = Settings {
                keyholes: false,
                ..*s
            };
            done = smooth_cut(&piece, &plain, &[]);
        }
        match done {
            Some(p) => {
                changed = true;
                out.append(p);
            }
            None => out.keep(&piece),
        }
    }
    Some((out, changed))
}

impl Smoothed {
    /// Appends a rewritten piece.
    fn append(&mut self, p: Smoothed) {
        self.points.extend(p.points);
        self.e.extend(p.e);
        self.steps.extend(p.steps);
        self.above_k_cr += p.above_k_cr;
        self.deviation_mm = self.deviation_mm.max(p.deviation_mm);
        self.stats.steps += p.stats.steps;
        self.stats.fluctuation_sum += p.stats.fluctuation_sum;
        self.keyholes += p.keyholes;
    }

    /// Appends a piece kept as it was, its segments at their own feeds and planned peaks.
    fn keep(&mut self, piece: &SmoothPath<'_>) {
        self.points.extend(piece.pts.iter().skip(1).copied());
        self.e.extend(piece.e.iter().skip(1).copied());
        self.steps
            .extend(piece.feed.iter().enumerate().map(|(k, &f)| {
                let planned = piece.planned.get(k);
                StepSpeed {
                    programmed: f,
                    limit: f64::INFINITY,
                    floor: 0.0,
                    ceiling: planned.map_or(f64::INFINITY, |p| p.peak),
                    accel: planned.map_or(0.0, |p| p.acceleration),
                }
            }));
    }
}

/// The sharp corners of `path` to turn as polygons placed for Klipper's look-ahead
/// ([`klipper`]): on a Klipper machine, where the original's planned speeds are known, a polygon
/// fits within the tolerance and the legs' room (all of the leg where it ends the path, half
/// where it is shared, less a shortest step), and the firmware runs it no slower than
/// [`Settings::min_speed_share`] of its speed through the sharp corner.
fn polygon_corners(path: &SmoothPath<'_>, s: &Settings) -> Vec<klipper::Corner> {
    let mut out = Vec::new();
    let Some(scv) = s.klipper_scv_mm_s else {
        return out;
    };
    let pts = path.pts;
    let n = pts.len();
    if n < 3 || path.planned.is_empty() || !path.consistent() {
        return out;
    }
    let cos_critical = crate::math::cos(s.critical_rad);
    // Corners a fillet already rounds at no loss of speed keep the fillet: the fitted curve
    // rings less than a polygon of the largest turns.
    let blends = blend::plan(
        pts,
        TUNING.blend_share * s.tolerance_mm,
        s.limits.critical_curvature(),
        s.line,
    );
    let room = |from: usize, to: usize, end: bool| {
        let l = norm(sub(pts[to], pts[from]));
        (if end { TUNING.leg_share } else { 0.5 } * l - s.min_step_mm).max(0.0)
    };
    let free = Settings {
        min_speed_share: 1.0,
        ..*s
    };
    for i in 1..n - 1 {
        let (u, w) = (sub(pts[i], pts[i - 1]), sub(pts[i + 1], pts[i]));
        if !crate::vtg::rewrite::is_sharp(&u, &w, cos_critical) {
            continue;
        }
        let (before, after) = (&path.planned[i - 1], &path.planned[i]);
        if roundable(&blends[i], s) && pays(blends[i].max_curvature, Some(before), &free) {
            continue;
        }
        let accel = before.acceleration.min(after.acceleration);
        if accel.is_nan() || accel <= 0.0 {
            continue;
        }
        let bounds = klipper::Bounds {
            tolerance_mm: s.tolerance_mm - 0.001,
            max_turn_rad: TUNING.step_turn_share * s.critical_rad,
            min_step_mm: s.min_step_mm,
            room_mm: [room(i - 1, i, i == 1), room(i, i + 1, i + 2 == n)],
        };
        let fw = klipper::Firmware {
            accel_mm_s2: accel,
            junction_deviation_mm: crate::plan::junction::klipper_junction_deviation(scv, accel),
            feed_mm_s: [path.feed[i - 1], path.feed[i]],
            ends_mm_s: [before.entry, after.exit],
        };
        if let Some(c) = klipper::find(pts, i, &bounds, &fw)
            .filter(|c| c.slowest_mm_s >= s.min_speed_share * c.sharp_mm_s)
        {
            out.push(c);
        }
    }
    out
}

/// Whether a corner's blend can be walked in steps of at least the minimum step, each turning
/// less than the critical angle (a tighter blend would only trade one sharp turn for several).
fn roundable(b: &blend::Blend, s: &Settings) -> bool {
    b.extent_mm > 0.0 && b.max_curvature * s.min_step_mm <= TUNING.step_turn_share * s.critical_rad
}

/// Whether rounding a corner on a curve of the largest curvature `curvature` (a fillet's, or a
/// keyhole's loop) leaves the machine at least as fast through it, given how the
/// firmware ran the original move `before` that ends at the corner (unknown: assume it does).
///
/// A junction-deviation or Klipper planner takes a sharp corner as if it were an arc (Klipper's
/// of radius `jd sin(θ/2) / (1 − sin(θ/2))`, `jd = scv² (√2 − 1) / a`), and holds a real curve
/// of radius `r` to `√(a r)`. Where the square-corner velocity is high (Creality's K1 profiles
/// set 50–100 mm/s) that virtual arc is larger than any fillet the tolerance allows, and the
/// fillet would only slow the machine down: such a corner is kept, unless the settings let a
/// rounded corner run slower ([`Settings::min_speed_share`] of the sharp one's speed: the
/// dearer variants time may be spent on). (A classic-jerk planner has no such rule: the feed
/// written on the fillet is never below the original's speed.)
fn pays(curvature: f64, before: Option<&Profile>, s: &Settings) -> bool {
    let Some(p) = before.filter(|_| s.speed_share_matters()) else {
        return true;
    };
    let a = p.acceleration.min(s.max_normal_accel_mm_s2);
    let on_fillet = (a / curvature).sqrt();
    on_fillet >= s.min_speed_share * p.exit
}

impl Settings {
    /// Whether [`Settings::min_speed_share`] can change which corners are rounded: only where
    /// the firmware takes a sharp corner as a virtual arc that a fillet must keep up with (see
    /// `pays`); a classic-jerk planner's corners all pay already.
    pub(crate) fn speed_share_matters(&self) -> bool {
        self.classic_jerk_mm_s.is_none()
    }
}

/// One piece between kept corners, with its hairpins (`at` counted in the piece) as found with
/// the full blend share of the tolerance.
fn smooth_piece(
    path: &SmoothPath<'_>,
    s: &Settings,
    has_sharp: bool,
    pins: &[hairpin::Hairpin],
) -> Option<Smoothed> {
    if path.pts.len() < 3 || !has_sharp {
        return None;
    }
    let e0 = *path.e.first()?;
    let e: Vec<f64> = path.e.iter().map(|x| x - e0).collect();
    let from_zero = SmoothPath { e: &e, ..*path };
    for share in super::blend_shares() {
        let tol = share * s.tolerance_mm;
        let done = if pins.is_empty() {
            attempt(&from_zero, path.pts, s, tol)
        } else {
            with_hairpins(&from_zero, s, tol, pins, share < TUNING.blend_share)
        };
        if let Some(mut r) = done {
            for x in &mut r.e {
                *x += e0;
            }
            return Some(r);
        }
    }
    None
}

/// [`hairpin::find`] at corners `i`, `i + 1` of `pts` within `blend_tol`, for an arc the walk
/// can follow in steps of at least the minimum step each turning by less than its share of the
/// critical angle (with 5 % to spare), reaching along each long leg `Tuning::leg_share` of it
/// where the leg ends the path and half that where another corner shares it.
fn find_hairpin(
    pts: &[[f64; 3]],
    i: usize,
    blend_tol: f64,
    s: &Settings,
) -> Option<hairpin::Hairpin> {
    let n = pts.len();
    let room = |leg: usize, far_end: usize| {
        let l = norm(sub(pts.get(leg + 1)?, pts.get(leg)?));
        let shared = far_end != 0 && far_end + 1 != n;
        Some(TUNING.leg_share * l * if shared { 0.5 } else { 1.0 })
    };
    let min_radius = min_hairpin_radius(s);
    let rooms = [room(i.checked_sub(1)?, i - 1)?, room(i + 1, i + 2)?];
    hairpin::find(pts, i, blend_tol, min_radius, rooms)
}

/// [`keyhole::find`] at corner `i` of `pts` (arc lengths `arc`) within the blend share of the
/// tolerance, on a loop of the hairpins' smallest radius, with counter-turns of at most
/// `Tuning::kink_share` of the critical angle. The loop may reach along the path up to
/// `Tuning::leg_share` of the way to the path's ends and half the way to the nearest corner
/// that is sharp, already replaced or degenerate (which the piece may be cut at).
fn find_keyhole(
    pts: &[[f64; 3]],
    arc: &[f64],
    i: usize,
    sharp: &[bool],
    pinned: &[bool],
    degenerate: &[bool],
    s: &Settings,
) -> Option<hairpin::Hairpin> {
    let n = pts.len();
    let stop = |k: usize| k == 0 || k + 1 == n || sharp[k] || pinned[k] || degenerate[k];
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
    keyhole::find(
        pts,
        arc,
        i,
        TUNING.blend_share * s.tolerance_mm,
        min_hairpin_radius(s),
        TUNING.kink_share * s.critical_rad,
        room,
    )
}

/// The smallest radius of a loop the walk can follow in steps of at least the minimum step,
/// each turning by less than its share of the critical angle, with 5 % to spare.
fn min_hairpin_radius(s: &Settings) -> f64 {
    1.05 * s.min_step_mm / (TUNING.step_turn_share * s.critical_rad)
}

/// [`attempt`] on `path` with its hairpins `pins` replaced by their arcs, checked against the
/// original; with `again`, the arcs are found anew within the smaller `blend_tol`.
fn with_hairpins(
    path: &SmoothPath<'_>,
    s: &Settings,
    blend_tol: f64,
    pins: &[hairpin::Hairpin],
    again: bool,
) -> Option<Smoothed> {
    let pts = path.pts;
    let found: Vec<hairpin::Hairpin>;
    let pins = if again {
        found = pins
            .iter()
            .map(|p| match p.corners {
                2 => find_hairpin(pts, p.at, blend_tol, s),
                _ => Some(p.clone()),
            })
            .collect::<Option<_>>()?;
        &found
    } else {
        pins
    };
    let sub = hairpin::substitute(pts, path.e, path.feed, path.planned, pins);
    let replaced = SmoothPath {
        pts: &sub.pts,
        e: &sub.e,
        feed: &sub.feed,
        planned: &sub.planned,
    };
    attempt(&replaced, pts, s, blend_tol)
}

/// Blend, fit, walk `path` (filament from 0) with blends within `blend_tol`, and check the
/// result against the polyline `original` (the same path, or the one it stands for).
fn attempt(
    path: &SmoothPath<'_>,
    original: &[[f64; 3]],
    s: &Settings,
    blend_tol: f64,
) -> Option<Smoothed> {
    let Walked {
        samples: walked,
        mut points,
        deviation_mm: deviation,
        stats,
    } = walk_within(path, original, s, blend_tol)?;
    let total_e = *path.e.last()?;
    let mut out = Smoothed {
        deviation_mm: deviation,
        stats,
        ..Smoothed::default()
    };
    let o = Original {
        arc: arc_lengths(path.pts),
        path,
        s,
    };
    let k_cr = s.limits.critical_curvature();
    let (e, feed) = (path.e, path.feed);
    let mut seg = 0usize;
    let mut u_prev = 0.0;
    for x in walked.iter().skip(1) {
        // The original segment this parameter (an arc length of the original) falls in.
        while seg + 1 < feed.len() && o.arc.get(seg + 1).is_some_and(|&a| a <= x.u) {
            seg += 1;
        }
        let (a0, a1) = (o.arc.get(seg).copied()?, o.arc.get(seg + 1).copied()?);
        let t = if a1 > a0 {
            ((x.u - a0) / (a1 - a0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let (e0, e1) = (e.get(seg).copied()?, e.get(seg + 1).copied()?);
        let local = o.limits_at(seg);
        let mut step = StepSpeed {
            programmed: feed.get(seg).copied()?,
            limit: f64::INFINITY,
            floor: 0.0,
            ceiling: o.top(u_prev, x.u),
            accel: local.normal_accel_mm_s2,
        };
        if x.mean_kappa > k_cr {
            out.above_k_cr += 1;
            if s.limit_feed {
                step.limit = local.feed_limit(x.mean_kappa);
                step.floor = o.speed(u_prev).min(o.speed(x.u));
            }
        }
        u_prev = x.u;
        out.e.push(e0 + (e1 - e0) * t);
        out.steps.push(step);
    }
    points.remove(0);
    if let Some(last) = out.e.last_mut() {
        *last = total_e;
    }
    out.points = points;
    Some(out)
}

/// The blended, fitted and walked curve of `path` with its ends pinned to the original's,
/// its points, their deviation from `original` and the walk's statistics; `None` when the
/// fit or walk fails or the deviation exceeds the tolerance. Apart from [`attempt`] so the
/// geometry (VTG eq. 18–28) reads apart from the feeds given to it.
fn walk_within(
    path: &SmoothPath<'_>,
    original: &[[f64; 3]],
    s: &Settings,
    blend_tol: f64,
) -> Option<Walked> {
    let pts = path.pts;
    let tol = s.tolerance_mm;
    // Room for the 3-decimal rounding of written coordinates.
    let budget = tol - 0.001;
    let k_cr = s.limits.critical_curvature();
    let blends = blend::plan(pts, blend_tol, k_cr, s.line);
    let (data, params) = blend::samples(pts, &blends, TUNING.straight_spacing_mm);
    let f = fit(&data, &params, TUNING.fit_share * tol)?;
    let w = Walk {
        chord_tol_mm: TUNING.chord_share * tol,
        max_turn_rad: TUNING.step_turn_share * s.critical_rad,
        max_step_mm: 1e4,
        min_step_mm: s.min_step_mm,
        phi: 1.0,
        newton_tol_mm: 1e-7,
    };
    let mut stats = WalkStats::default();
    let walked = walk_curve(&f.curve, &w, &mut stats)?;
    let mut points: Vec<[f64; 3]> = walked.iter().map(|x| x.p).collect();
    // Pin the ends to the original ones exactly.
    if let (Some(first), Some(p0)) = (points.first_mut(), pts.first()) {
        *first = *p0;
    }
    if let (Some(last), Some(pn)) = (points.last_mut(), pts.last()) {
        *last = *pn;
    }
    // Both ways: the new path stays near the old, and the old is covered by the new.
    let deviation = both_ways(&points, original, tol / 10.0, budget);
    if deviation.is_nan() || deviation > budget {
        return None;
    }
    Some(Walked {
        samples: walked,
        points,
        deviation_mm: deviation,
        stats,
    })
}

/// What [`walk_within`] gives: the walk's samples, their points with the ends pinned, the
/// measured deviation (mm) and the walk's statistics.
struct Walked {
    samples: Vec<Sample>,
    points: Vec<[f64; 3]>,
    deviation_mm: f64,
    stats: WalkStats,
}

/// What the original asked at each arc length of a path: the planned speeds and the limits
/// that bound the feed of the new points laid over it.
struct Original<'p, 'a> {
    /// Arc length at each original point.
    arc: Vec<f64>,
    path: &'p SmoothPath<'a>,
    s: &'p Settings,
}

impl Original<'_, '_> {
    /// The original segment at arc length `u`.
    fn segment(&self, u: f64) -> usize {
        segment_at(&self.arc, u, self.path.feed.len())
    }

    /// The original's planned speed at arc length `u`.
    fn speed(&self, u: f64) -> f64 {
        let seg = self.segment(u);
        self.path
            .planned
            .get(seg)
            .map_or(0.0, |p| p.speed_at(u - self.arc[seg]))
    }

    /// The original's highest planned speed between arc lengths `u0 ≤ u1`.
    fn top(&self, u0: f64, u1: f64) -> f64 {
        (self.segment(u0)..=self.segment(u1))
            .map(|k| {
                self.path.planned.get(k).map_or(f64::INFINITY, |p| {
                    p.max_speed_between(u0 - self.arc[k], u1 - self.arc[k])
                })
            })
            .fold(0.0, f64::max)
    }

    /// The limits of original segment `seg`: `A_n` the acceleration the firmware ran it with.
    fn limits_at(&self, seg: usize) -> KinematicLimits {
        let s = self.s;
        let mut l = s.limits;
        if let Some(p) = self.path.planned.get(seg).filter(|p| p.acceleration > 0.0) {
            l.normal_accel_mm_s2 = p.acceleration.min(s.max_normal_accel_mm_s2);
            if let Some(f1) = s.jerk_per_accel_hz {
                l.normal_jerk_mm_s3 = l.normal_accel_mm_s2 * f1;
            }
        }
        l
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Turns over the critical angle of `settings()` (30°) along `start` then `points`.
    fn sharp_turns_from(start: [f64; 3], points: &[[f64; 3]]) -> usize {
        let cos = settings().critical_rad.cos();
        crate::vtg::rewrite::sharp_turns(std::iter::once(&start).chain(points), cos)
    }

    fn settings() -> Settings {
        Settings {
            tolerance_mm: 0.1,
            critical_rad: 30f64.to_radians(),
            limits: KinematicLimits {
                v_max_mm_s: 200.0,
                interpolation_period_s: 0.001,
                chord_tolerance_mm: 0.1,
                normal_accel_mm_s2: 1000.0,
                normal_jerk_mm_s3: 1e5,
                nozzle_radius_mm: 0.2,
            },
            limit_feed: true,
            max_normal_accel_mm_s2: 1000.0,
            jerk_per_accel_hz: None,
            min_step_mm: TUNING.klipper_min_step_mm,
            classic_jerk_mm_s: None,
            feed_cap_scale: 1.0,
            arcs: false,
            min_speed_share: 1.0,
            keyholes: true,
            line: blend::Line::Racing,
            klipper_scv_mm_s: None,
        }
    }

    /// A corner pays when the machine runs round the fillet at least as fast as it left the
    /// sharp corner, or at least the settings' share of that speed.
    #[test]
    fn a_dearer_variant_rounds_corners_down_to_its_share_of_the_sharp_speed() {
        let before = Profile {
            entry: 100.0,
            peak: 100.0,
            exit: 50.0,
            acceleration: 5000.0,
            ..Profile::default()
        };
        // √(1000 mm/s² × 1.6 mm) = 40 mm/s on the fillet: 80 % of the 50 mm/s corner
        // (the settings' 1000 mm/s² X/Y limit is below the 5000 the move used).
        let curvature = 1.0 / 1.6;
        let with = |min_speed_share| Settings {
            min_speed_share,
            ..settings()
        };
        assert!(!pays(curvature, Some(&before), &with(1.0)));
        assert!(pays(curvature, Some(&before), &with(0.79)));
        assert!(!pays(curvature, Some(&before), &with(0.81)));
        assert!(pays(curvature, Some(&before), &with(0.0)));
        // Where the sharp corner's speed is not known, rounding is assumed to pay.
        assert!(pays(curvature, None, &with(1.0)));
        // A classic-jerk planner has no virtual arc to compete with.
        let classic = Settings {
            classic_jerk_mm_s: Some(8.0),
            ..with(1.0)
        };
        assert!(pays(curvature, Some(&before), &classic));
    }

    /// A right angle between long legs is walked on the racing line: out past the first leg,
    /// round a circle about 2.4 times the inside fillet's, and back, within the tolerance.
    #[test]
    fn a_right_angle_is_walked_on_the_racing_line() {
        let pts = [[0.0, 0.0, 0.2], [10.0, 0.0, 0.2], [10.0, 10.0, 0.2]];
        let e = [0.0, 0.4, 0.8];
        let feed = [50.0, 50.0];
        let path = SmoothPath {
            pts: &pts,
            e: &e,
            feed: &feed,
            planned: &[],
        };
        // The tightest circle through three consecutive points, and how far the path strays
        // outside the first leg.
        let shape = |line| {
            let s = Settings { line, ..settings() };
            let r = smooth_path(&path, &s).expect("rounded");
            let mut all = vec![pts[0]];
            all.extend_from_slice(&r.points);
            assert!(both_ways(&all, &pts, 1e-3, 0.0) <= 0.1);
            assert_eq!(sharp_turns_from(pts[0], &r.points), 0);
            let tightest = all
                .windows(3)
                .filter_map(|w| crate::vtg::arcs::circle_through(&w[0], &w[1], &w[2]))
                .map(|(_, r)| r)
                .fold(f64::INFINITY, f64::min);
            let outside = all.iter().map(|p| -p[1]).fold(0.0, f64::max);
            (tightest, outside)
        };
        let (inside_r, inside_out) = shape(blend::Line::Inside);
        let (racing_r, racing_out) = shape(blend::Line::Racing);
        assert!(inside_out < 0.02, "{inside_out}");
        assert!(racing_out > 0.06, "{racing_out}");
        assert!(racing_r > 2.0 * inside_r, "{racing_r} vs {inside_r}");
    }

    #[test]
    fn square_loop_is_rounded() {
        let pts = [
            [121.557, 101.617, 0.2],
            [121.557, 101.557, 0.2],
            [128.443, 101.557, 0.2],
            [128.443, 108.443, 0.2],
            [121.557, 108.443, 0.2],
            [121.557, 101.617, 0.2],
        ];
        let mut e = vec![0.0];
        for w in pts.windows(2) {
            let l = crate::vec3::norm(crate::vec3::sub(w[1], w[0]));
            e.push(e.last().unwrap() + 0.03 * l);
        }
        let feed = vec![20.0; pts.len() - 1];
        let s = settings();
        let path = SmoothPath {
            pts: &pts,
            e: &e,
            feed: &feed,
            planned: &[],
        };
        let r = smooth_path(&path, &s).expect("smoothed");
        assert!(r.deviation_mm <= 0.1);
        // Filament is conserved and the end is the original end.
        assert!((r.e.last().unwrap() - e.last().unwrap()).abs() < 1e-12);
        assert_eq!(r.points.last(), pts.last());
        // The square's three roundable corners are rounded: fewer sharp turns than before
        // (the first corner, 0.06 mm from the start, is kept).
        let sharp = sharp_turns_from(pts[0], &r.points);
        assert!(sharp < 4, "{sharp}");
    }

    /// The tip of a thin wedge (136°, legs of 0.07 mm steps), too tight to fillet in Marlin's
    /// 0.06 mm steps: with keyholes it is turned round a loop, every turn of the new path is
    /// under the critical angle, and it stays within the tolerance with the filament kept;
    /// without, the tip is kept sharp.
    #[test]
    fn a_wedge_tip_is_turned_round_a_keyhole() {
        let half = 22f64.to_radians();
        let leg = |k: usize, side: f64| {
            let d = 0.07 * k as f64;
            [10.0 + d * half.cos(), 10.0 + side * d * half.sin(), 0.2]
        };
        let mut pts: Vec<[f64; 3]> = (1..=20).rev().map(|k| leg(k, 1.0)).collect();
        pts.push(leg(0, 1.0));
        pts.extend((1..=20).map(|k| leg(k, -1.0)));
        let e: Vec<f64> = (0..pts.len()).map(|k| 0.002 * k as f64).collect();
        let feed = vec![30.0; pts.len() - 1];
        let path = SmoothPath {
            pts: &pts,
            e: &e,
            feed: &feed,
            planned: &[],
        };
        let s = Settings {
            min_step_mm: TUNING.marlin_min_step_mm,
            ..settings()
        };
        let r = smooth_path(&path, &s).expect("keyhole");
        assert_eq!(r.keyholes, 1);
        assert_eq!(sharp_turns_from(pts[0], &r.points), 0);
        let mut all = vec![pts[0]];
        all.extend_from_slice(&r.points);
        let d = both_ways(&all, &pts, 1e-3, 0.0);
        assert!(d <= 0.1, "{d}");
        assert!((r.e.last().unwrap() - e.last().unwrap()).abs() < 1e-12);
        assert!(r.e.windows(2).all(|w| w[1] >= w[0]));
        assert_eq!(r.points.last(), pts.last());
        let plain = Settings {
            keyholes: false,
            ..s
        };
        let kept = smooth_path(&path, &plain).map_or(pts[1..].to_vec(), |r| r.points);
        assert_eq!(sharp_turns_from(pts[0], &kept), 1);
    }

    /// Infill turning back at the wall (a hairpin) is rounded with keyholes on or off: the
    /// variant without them (the closed loop's last resort) handles hairpins the same way.
    #[test]
    fn hairpins_are_rounded_with_or_without_keyholes() {
        // Lines 0.28 mm apart joined square to them: each 90° corner has too little of the
        // connector to be filleted alone in Marlin's steps.
        let pts = [
            [10.0, 0.0, 0.2],
            [0.0, 0.0, 0.2],
            [0.0, 0.28, 0.2],
            [10.0, 0.28, 0.2],
        ];
        let e = [0.0, 0.4, 0.4112, 0.8112];
        let feed = [40.0; 3];
        let path = SmoothPath {
            pts: &pts,
            e: &e,
            feed: &feed,
            planned: &[],
        };
        let on = Settings {
            min_step_mm: TUNING.marlin_min_step_mm,
            ..settings()
        };
        let off = Settings {
            keyholes: false,
            ..on
        };
        let a = smooth_path(&path, &on).expect("rounded");
        let b = smooth_path(&path, &off).expect("rounded");
        assert_eq!(a.points, b.points);
        assert_eq!((a.keyholes, b.keyholes), (0, 0));
        assert!(a.deviation_mm <= 0.1);
        // Round as one turn: no step of it turns by the critical angle, and none is empty.
        assert_eq!(sharp_turns_from(pts[0], &a.points), 0);
        assert!(a.points.windows(2).all(|w| w[0] != w[1]) && a.points[0] != pts[0]);
    }

    /// On a Klipper machine whose square-corner velocity takes sharp corners fast (the K1's
    /// 50 mm/s at 5000 mm/s²), every corner of a square costs time to round; the polygons placed
    /// for its look-ahead cost about 3.5 ms a corner through the real planner, where a fillet
    /// fitted and walked cost 5.6 ms and a circle on the racing line 4.5 ms. Bought with the
    /// time allowed, all 40 corners go.
    #[test]
    fn klipper_square_corners_are_bought_as_polygons() {
        let mut src = String::from(
            "SET_VELOCITY_LIMIT ACCEL=5000 ACCEL_TO_DECEL=2500 SQUARE_CORNER_VELOCITY=50\nM83\n",
        );
        src.push_str("G1 X60 Y50 F30000\nG1 Z0.2\nG1 F12000\n");
        for _ in 0..10 {
            for (x, y) in [(70.0, 50.0), (70.0, 70.0), (50.0, 70.0), (50.0, 50.0)] {
                let e = if x == 70.0 && y == 50.0 { 0.3 } else { 0.6 };
                src.push_str(&format!("G1 X{x} Y{y} E{e}\n"));
            }
        }
        src.push_str("G1 X60 Y50 E0.3\n");
        let options = crate::vtg::VtgOptions {
            dynamics: false,
            allow_slower_pct: 10.0,
            ..Default::default()
        };
        let r = crate::vtg::vtg(src.as_bytes(), &options).expect("vtg");
        assert_eq!(r.table1.n_turning.before, 40.0);
        assert_eq!(r.table1.n_turning.after, 0.0, "{:?}", r.table1.n_turning);
        assert!(r.max_deviation_mm <= 0.1, "{}", r.max_deviation_mm);
        let t = &r.table2.time_s;
        let per_corner_ms = (t.after - t.before) / 40.0 * 1e3;
        eprintln!("{per_corner_ms} ms a corner");
        assert!(
            per_corner_ms > 0.0 && per_corner_ms < 4.0,
            "{per_corner_ms}"
        );
    }

    /// On a classic-jerk machine the rewritten corners are no slower than the sharp ones and
    /// the ramps leave no junction stalled, with the real planner.
    #[test]
    fn classic_jerk_rectangle_is_not_slower_through_the_planner() {
        let mut src = String::from("M83\nM201 X1000 Y1000\nM204 P1250\nM205 X8 Y8\n");
        src.push_str("G1 X100 Y100 F6000\nG1 Z0.2\n");
        for _ in 0..10 {
            for (x, y) in [
                (120.0, 100.0),
                (120.0, 110.0),
                (100.0, 110.0),
                (100.0, 100.0),
            ] {
                src.push_str(&format!("G1 X{x} Y{y} E0.5 F3600\n"));
            }
        }
        let options = crate::vtg::VtgOptions {
            dynamics: false,
            ..Default::default()
        };
        let r = crate::vtg::vtg(src.as_bytes(), &options).expect("vtg");
        assert!(r.paths.rewritten > 0);
        assert!(
            r.table1.n_turning.change_pct <= -40.0,
            "{:?}",
            r.table1.n_turning
        );
        let t = &r.table2.time_s;
        assert!(t.after <= t.before * 1.01, "{t:?}");
    }
}
