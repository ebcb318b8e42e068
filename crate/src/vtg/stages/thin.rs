//! The segment budget of Algorithm 1's step `L_i`: after the walk, steps are joined where the
//! tolerance and the turn still allow it, so that each written segment lasts at least the
//! firmware's minimum segment time at its feed.
//!
//! VTG Algorithm 1 leaves `L_i` open, and the walk ([`super::resample`]) picks the longest step
//! whose chord sags at most `chord_share` of the tolerance and turns at most a share of δθ: a
//! CAM interpolator's choice, made for a servo controller that takes a point every
//! interpolation period. A printer's firmware is not such a controller. Marlin keeps 16 blocks
//! in its planner buffer (`BLOCK_BUFFER_SIZE`) and, when the buffer runs low, slows every
//! block shorter than `min_segment_time` (`M205 B`, 20 ms by default); serial and SD
//! streaming bound the lines it can read per second. A step of `L_i = v · t_min` is the
//! shortest that keeps the buffer full at feed `v`. So the walked points are thinned: from
//! each kept point the next segment runs to the furthest walked point such that
//!
//! - the chord stays within the deviation budget of the original polyline both ways (the
//!   walk only used `chord_share` of it on gentle curves),
//! - the turns at both of its ends stay at most the walk's largest turn per step (a joined
//!   step never becomes a sharp corner), and
//! - the segment is still shorter than `v · t_min` (past that, joining only moves the path
//!   further from the curve for nothing the firmware needs).
//!
//! The path as a whole is checked again by the caller, as the walk was.

use crate::vec3::{dot, norm, sub};
use crate::vtg::deviation::{deviation_from_segments, point_segment, Segment};

/// What the thinning may do.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Thin {
    /// Largest distance between a joined segment and the original polyline, either way, mm.
    pub(crate) budget_mm: f64,
    /// Largest turn at a kept point, rad (the walk's own largest turn per step).
    pub(crate) max_turn_rad: f64,
    /// The firmware's minimum segment time, s (0: join only where the tolerance allows, as far
    /// as [`MAX_JOINED`] steps).
    pub(crate) min_segment_s: f64,
    /// Sampling step of the deviation check, mm.
    pub(crate) step_mm: f64,
}

/// Most walked steps joined into one segment: bounds the work per segment.
const MAX_JOINED: usize = 64;

/// The original a walk followed: its polyline, the arc length at each of its points, the
/// feed of each of its segments (mm/s), and the segments prepared for the deviation checks
/// (`crate::vtg::deviation::Segments` of `pts`: every join is checked against a stretch of
/// them, a few dozen joins a kept point).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Followed<'a> {
    pub(crate) pts: &'a [[f64; 3]],
    pub(crate) arc: &'a [f64],
    pub(crate) feed: &'a [f64],
    pub(crate) segments: &'a [Segment],
}

impl Followed<'_> {
    /// The index of the original segment at arc length `u`.
    fn segment(&self, u: f64) -> usize {
        let i = self.arc.partition_point(|&a| a <= u);
        i.saturating_sub(1).min(self.feed.len().saturating_sub(1))
    }

    /// The shortest segment the firmware runs without slowing at arc length `u`, mm.
    fn min_length(&self, u: f64, t: &Thin) -> f64 {
        self.feed
            .get(self.segment(u))
            .map_or(0.0, |v| v * t.min_segment_s)
    }

    /// Whether the chord `a`–`b` (at arc lengths `ua < ub`) stays within `t.budget_mm` of the
    /// original between them, both ways.
    fn covers(&self, a: &[f64; 3], b: &[f64; 3], ua: f64, ub: f64, t: &Thin) -> bool {
        let lo = self.segment(ua).saturating_sub(1);
        let hi = (self.segment(ub) + 3).min(self.pts.len());
        let Some(window) = self.segments.get(lo..hi.saturating_sub(1)) else {
            return false;
        };
        if window.is_empty() {
            return false;
        }
        let inner = self
            .pts
            .iter()
            .zip(self.arc)
            .skip(lo)
            .take(hi - lo)
            .filter(|(_, &u)| u > ua && u < ub);
        for (p, _) in inner {
            if point_segment(p, a, b) > t.budget_mm {
                return false;
            }
        }
        deviation_from_segments(&[*a, *b], window, t.step_mm, t.budget_mm) <= t.budget_mm
    }
}

/// The turn between directions `d0` and `d1`, rad (0 where either is degenerate).
fn turn(d0: [f64; 3], d1: [f64; 3]) -> f64 {
    let (n0, n1) = (norm(d0), norm(d1));
    if n0 > 0.0 && n1 > 0.0 {
        crate::math::acos((dot(d0, d1) / (n0 * n1)).clamp(-1.0, 1.0))
    } else {
        0.0
    }
}

/// The indices of `points` (walked at arc lengths `u` along `original`) to keep; the first
/// and last are always kept.
pub(crate) fn thin(
    points: &[[f64; 3]],
    u: &[f64],
    original: &Followed<'_>,
    t: &Thin,
) -> Vec<usize> {
    let n = points.len();
    let mut keep = Vec::with_capacity(n);
    if n == 0 || u.len() != n {
        return (0..n).collect();
    }
    keep.push(0);
    let mut a = 0usize;
    let mut incoming: Option<[f64; 3]> = None;
    while a + 1 < n {
        let floor = original.min_length(u[a], t);
        let mut best = a + 1;
        let mut j = a + 2;
        while j < n && j - a <= MAX_JOINED {
            if t.min_segment_s > 0.0 && norm(sub(points[best], points[a])) >= floor {
                break;
            }
            if !joinable(points, u, original, t, incoming, a, j) {
                break;
            }
            best = j;
            j += 1;
        }
        keep.push(best);
        incoming = Some(sub(points[best], points[a]));
        a = best;
    }
    keep
}

/// Whether the walked points `a` to `j` may be written as one segment.
fn joinable(
    points: &[[f64; 3]],
    u: &[f64],
    original: &Followed<'_>,
    t: &Thin,
    incoming: Option<[f64; 3]>,
    a: usize,
    j: usize,
) -> bool {
    let chord = sub(points[j], points[a]);
    if let Some(d) = incoming {
        // No sharper than the walk's own turn at `a` or the walk's limit.
        let own = turn(d, sub(points[a + 1], points[a]));
        if turn(d, chord) > t.max_turn_rad.max(own) {
            return false;
        }
    }
    if let Some(next) = points.get(j + 1) {
        let own = turn(sub(points[j], points[j - 1]), sub(*next, points[j]));
        if turn(chord, sub(*next, points[j])) > t.max_turn_rad.max(own) {
            return false;
        }
    }
    original.covers(&points[a], &points[j], u[a], u[j], t)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A circle of radius `r` walked in `n` equal steps, and its arc lengths.
    fn circle(r: f64, n: usize, turn: f64) -> (Vec<[f64; 3]>, Vec<f64>) {
        let pts: Vec<[f64; 3]> = (0..=n)
            .map(|i| {
                let a = turn * i as f64 / n as f64;
                [r * a.cos(), r * a.sin(), 0.2]
            })
            .collect();
        let arc = (0..=n).map(|i| r * turn * i as f64 / n as f64).collect();
        (pts, arc)
    }

    fn thin_settings(min_segment_s: f64) -> Thin {
        Thin {
            budget_mm: 0.05,
            max_turn_rad: 27f64.to_radians(),
            min_segment_s,
            step_mm: 0.005,
        }
    }

    /// [`thin`] of `fine` (walked at `u`) along the original `orig` (arc lengths `arc`)
    /// printed at 50 mm/s throughout.
    fn thin_at_50(
        fine: &[[f64; 3]],
        u: &[f64],
        (orig, arc): (&[[f64; 3]], &[f64]),
        t: &Thin,
    ) -> Vec<usize> {
        let feed = vec![50.0; orig.len() - 1];
        let segments = crate::vtg::deviation::Segments::new(orig);
        let o = Followed {
            pts: orig,
            arc,
            feed: &feed,
            segments: &segments.0,
        };
        thin(fine, u, &o, t)
    }

    #[test]
    fn a_finely_walked_gentle_curve_is_joined_within_the_budget_and_turn() {
        // A 20 mm radius quarter circle in 400 steps of 0.08 mm, the original a 1000-gon.
        let (fine, u) = circle(20.0, 400, std::f64::consts::FRAC_PI_2);
        let (orig, arc) = circle(20.0, 1000, std::f64::consts::FRAC_PI_2);
        let t = thin_settings(0.02);
        let keep = thin_at_50(&fine, &u, (&orig, &arc), &t);
        let kept: Vec<[f64; 3]> = keep.iter().map(|&i| fine[i]).collect();
        assert_eq!(kept.first(), fine.first());
        assert_eq!(kept.last(), fine.last());
        assert!(
            kept.len() * 4 < fine.len(),
            "{} of {}",
            kept.len(),
            fine.len()
        );
        // Measured: within the budget both ways, and no sharp turn.
        let dev = crate::vtg::deviation::both_ways(&kept, &orig, 0.001, 0.0);
        assert!(dev <= t.budget_mm + 0.001, "{dev}");
        for w in kept.windows(3) {
            assert!(turn(sub(w[1], w[0]), sub(w[2], w[1])) <= t.max_turn_rad + 1e-9);
        }
        // Segments reach the minimum segment time (50 mm/s × 20 ms = 1 mm) but for the last.
        let short = kept
            .windows(2)
            .filter(|w| norm(sub(w[1], w[0])) < 1.0 - 1e-9)
            .count();
        assert!(short <= 1, "{short} segments under 1 mm");
    }

    #[test]
    fn a_tight_fillet_keeps_its_steps() {
        // A 0.3 mm radius quarter circle walked in 4 steps of 22.5°: joining any two would
        // turn 45° and sag further than the budget allows.
        let (fine, u) = circle(0.3, 4, std::f64::consts::FRAC_PI_2);
        let (orig, arc) = circle(0.3, 400, std::f64::consts::FRAC_PI_2);
        let keep = thin_at_50(&fine, &u, (&orig, &arc), &thin_settings(0.02));
        assert_eq!(keep, (0..fine.len()).collect::<Vec<_>>());
    }
}
