//! One extrusion path through the VTG pipeline: sample, fit (within tolerance), walk the curve
//! with Algorithm 1, spread the path's filament over the new points, cap the feed where the
//! curvature is above `K_cr`, and check the result against the original polyline.
//!
//! The tolerance is shared: the fit may use `FIT_SHARE` of it and the chords of the walk the
//! rest. If the measured deviation still exceeds the tolerance, the corner zones are halved and
//! the path tried again; a path that cannot be rounded within the tolerance is kept as it was.

use super::bspline::{dot, norm, sub};
use super::deviation::polyline_deviation;
use super::fit::{fit, sample};
use super::kinematics::KinematicLimits;
use super::resample::{walk, Walk, WalkStats};

/// Share of the tolerance the fit may use.
const FIT_SHARE: f64 = 0.6;
/// Share of the tolerance the walk's chords may use.
const CHORD_SHARE: f64 = 0.3;
/// Corner zone half-width per unit `1/sin(θ/2)`, in tolerances (first attempt).
const ZONE_TOLERANCES: f64 = 2.5;
/// Attempts, each with half the zone of the previous one.
const ATTEMPTS: usize = 3;
/// Shortest interpolation step, mm (see [`Walk::min_step_mm`]).
const MIN_STEP_MM: f64 = 0.03;
/// Longest gap between data points on straight runs, mm.
const STRAIGHT_SPACING_MM: f64 = 3.0;

/// Settings for [`smooth_path`].
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    /// Tolerance, mm.
    pub tolerance_mm: f64,
    /// Critical angle δθ, rad.
    pub critical_rad: f64,
    /// Kinematic limits (eq. 29–30).
    pub limits: KinematicLimits,
    /// Lower the feed where the curvature exceeds what the limits allow at the programmed feed.
    pub limit_feed: bool,
}

/// A rewritten path.
#[derive(Debug, Clone, Default)]
pub struct Smoothed {
    /// New points after the start point (the last equals the original end).
    pub points: Vec<[f64; 3]>,
    /// Filament pushed from the path start to each point, mm.
    pub e: Vec<f64>,
    /// Feed of the segment ending at each point, mm/s.
    pub feed_mm_s: Vec<f64>,
    /// Segments whose feed was lowered.
    pub lowered: u64,
    /// Segments whose curvature stays above `K_cr`.
    pub above_k_cr: u64,
    /// Measured largest distance to the original polyline, mm.
    pub deviation_mm: f64,
    /// Walk statistics (eq. 28).
    pub stats: WalkStats,
}

/// Rewrites the polyline `pts` whose cumulative filament at each vertex is `e` (from 0) and
/// whose segment `i` (from `pts[i]` to `pts[i+1]`) runs at `feed[i]` mm/s. `None`: keep it.
///
/// Corners too sharp to be rounded within the tolerance in steps that each turn less than the
/// critical angle are kept as they are: the path is split there and each piece is fitted on its
/// own with its ends pinned (rounding such a corner would only trade one sharp turn for
/// several). Pieces without a sharp corner, and pieces that cannot be fitted within the
/// tolerance, keep their original points.
pub fn smooth_path(pts: &[[f64; 3]], e: &[f64], feed: &[f64], s: &Settings) -> Option<Smoothed> {
    if pts.len() < 3 || e.len() != pts.len() || feed.len() + 1 != pts.len() {
        return None;
    }
    let cos_critical = crate::math::cos(s.critical_rad);
    let mut cuts = vec![0usize];
    let mut sharp = vec![false; pts.len()];
    for i in 1..pts.len() - 1 {
        let a = sub(&pts[i], &pts[i - 1]);
        let b = sub(&pts[i + 1], &pts[i]);
        let (la, lb) = (norm(&a), norm(&b));
        if la <= 0.0 || lb <= 0.0 {
            cuts.push(i);
            continue;
        }
        let cos = (dot(&a, &b) / (la * lb)).clamp(-1.0, 1.0);
        if cos >= cos_critical {
            continue;
        }
        sharp[i] = true;
        if !roundable(cos, la.min(lb), s) {
            cuts.push(i);
            sharp[i] = false;
        }
    }
    cuts.push(pts.len() - 1);
    let mut out = Smoothed::default();
    let mut changed = false;
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        let piece = smooth_piece(
            pts.get(a..=b)?,
            e.get(a..=b)?,
            feed.get(a..b)?,
            s,
            sharp.get(a + 1..b).is_some_and(|v| v.iter().any(|&x| x)),
        );
        match piece {
            Some(p) => {
                changed = true;
                out.points.extend(p.points);
                out.e.extend(p.e);
                out.feed_mm_s.extend(p.feed_mm_s);
                out.lowered += p.lowered;
                out.above_k_cr += p.above_k_cr;
                out.deviation_mm = out.deviation_mm.max(p.deviation_mm);
                out.stats.steps += p.stats.steps;
                out.stats.fluctuation_sum += p.stats.fluctuation_sum;
            }
            None => {
                out.points.extend(pts.get(a + 1..=b)?.iter().copied());
                out.e.extend(e.get(a + 1..=b)?.iter().copied());
                out.feed_mm_s.extend(feed.get(a..b)?.iter().copied());
            }
        }
    }
    changed.then_some(out)
}

/// Whether a corner turning by `acos(cos)` between legs at least `leg` long can be rounded
/// within the fit's share of the tolerance by a circle whose walk needs steps of at least the
/// minimum step, each turning less than the critical angle.
fn roundable(cos: f64, leg: f64, s: &Settings) -> bool {
    let half = 0.5 * crate::math::acos(cos);
    // Circular fillet of radius r: the arc's midpoint lies r(1/cos(θ/2) − 1) inside the corner,
    // its ends r·tan(θ/2) from it.
    let sec = 1.0 / libm::cos(half).max(1e-9);
    let r_max = FIT_SHARE * s.tolerance_mm / (sec - 1.0).max(1e-12);
    let r_min = 1.2 * MIN_STEP_MM / (0.9 * s.critical_rad);
    r_min <= r_max && r_min * libm::tan(half) <= 0.45 * leg
}

/// One piece between kept corners.
fn smooth_piece(
    pts: &[[f64; 3]],
    e: &[f64],
    feed: &[f64],
    s: &Settings,
    has_sharp: bool,
) -> Option<Smoothed> {
    if pts.len() < 3 || !has_sharp {
        return None;
    }
    let e0 = *e.first()?;
    let e: Vec<f64> = e.iter().map(|x| x - e0).collect();
    let mut arc = Vec::with_capacity(pts.len());
    let mut acc = 0.0;
    arc.push(0.0);
    for w in pts.windows(2) {
        acc += norm(&sub(&w[1], &w[0]));
        arc.push(acc);
    }
    let k_cr = s.limits.critical_curvature();
    let tol = s.tolerance_mm;
    // Room for the 3-decimal rounding of written coordinates.
    let budget = tol - 0.001;
    let mut zone = ZONE_TOLERANCES * tol;
    for _ in 0..ATTEMPTS {
        if let Some(mut r) = attempt(pts, &arc, &e, feed, s, zone, k_cr, budget) {
            for x in &mut r.e {
                *x += e0;
            }
            return Some(r);
        }
        zone *= 0.5;
    }
    None
}

#[allow(clippy::too_many_arguments)]
fn attempt(
    pts: &[[f64; 3]],
    arc: &[f64],
    e: &[f64],
    feed: &[f64],
    s: &Settings,
    zone: f64,
    k_cr: f64,
    budget: f64,
) -> Option<Smoothed> {
    let tol = s.tolerance_mm;
    let (data, params) = sample(pts, zone, STRAIGHT_SPACING_MM);
    let f = fit(&data, &params, FIT_SHARE * tol)?;
    let w = Walk {
        chord_tol_mm: CHORD_SHARE * tol,
        max_turn_rad: 0.9 * s.critical_rad,
        max_step_mm: 1e4,
        min_step_mm: MIN_STEP_MM,
        phi: 1.0,
        newton_tol_mm: 1e-7,
    };
    let mut stats = WalkStats::default();
    let walked = walk(&f.curve, &w, &mut stats)?;
    let mut points: Vec<[f64; 3]> = walked.iter().map(|x| x.p).collect();
    // Pin the ends to the original ones exactly.
    if let (Some(first), Some(p0)) = (points.first_mut(), pts.first()) {
        *first = *p0;
    }
    if let (Some(last), Some(pn)) = (points.last_mut(), pts.last()) {
        *last = *pn;
    }
    // Both ways: the new path stays near the old, and the old is covered by the new.
    let deviation = polyline_deviation(&points, pts, tol / 10.0, budget).max(polyline_deviation(
        pts,
        &points,
        tol / 10.0,
        budget,
    ));
    if deviation.is_nan() || deviation > budget {
        return None;
    }
    let total_e = *e.last()?;
    let mut out = Smoothed {
        deviation_mm: deviation,
        stats,
        ..Smoothed::default()
    };
    let mut seg = 0usize;
    for x in walked.iter().skip(1) {
        // The original segment this parameter (an arc length of the original) falls in.
        while seg + 1 < feed.len() && arc.get(seg + 1).is_some_and(|&a| a <= x.u) {
            seg += 1;
        }
        let (a0, a1) = (arc.get(seg).copied()?, arc.get(seg + 1).copied()?);
        let t = if a1 > a0 {
            ((x.u - a0) / (a1 - a0)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let (e0, e1) = (e.get(seg).copied()?, e.get(seg + 1).copied()?);
        let programmed = feed.get(seg).copied()?;
        let mut v = programmed;
        if x.mean_kappa > k_cr {
            out.above_k_cr += 1;
            if s.limit_feed {
                let cap = s.limits.feed_limit(x.mean_kappa);
                if cap < v * 0.99 {
                    v = cap.max(1.0);
                    out.lowered += 1;
                }
            }
        }
        out.e.push(e0 + (e1 - e0) * t);
        out.feed_mm_s.push(v);
    }
    points.remove(0);
    if let Some(last) = out.e.last_mut() {
        *last = total_e;
    }
    out.points = points;
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

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
        }
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
            let l = super::super::bspline::norm(&super::super::bspline::sub(&w[1], &w[0]));
            e.push(e.last().unwrap() + 0.03 * l);
        }
        let feed = vec![20.0; pts.len() - 1];
        let s = settings();
        let r = smooth_path(&pts, &e, &feed, &s).expect("smoothed");
        assert!(r.deviation_mm <= 0.1);
        // Filament is conserved and the end is the original end.
        assert!((r.e.last().unwrap() - e.last().unwrap()).abs() < 1e-12);
        assert_eq!(r.points.last(), pts.last());
        // The square's three roundable corners are rounded: fewer sharp turns than before
        // (the first corner, 0.06 mm from the start, is kept).
        let mut all = vec![pts[0]];
        all.extend(r.points.iter().copied());
        let sharp = all
            .windows(3)
            .filter(|w| {
                let (a, b) = (sub(&w[1], &w[0]), sub(&w[2], &w[1]));
                dot(&a, &b) / (norm(&a) * norm(&b)) < 30f64.to_radians().cos()
            })
            .count();
        assert!(sharp < 4, "{sharp}");
    }
}
