//! How a smoothed path is written: the feed of each new segment (VTG eq. 29's cap, scaled, no
//! lower than the original ran there and, if asked, no higher), and on a classic-jerk firmware
//! the ramps that let the feed rise again without a stall at the junction.

use crate::vec3::{lerp, norm, sub};
use crate::vtg::smooth::{Settings, Smoothed};
use crate::vtg::tuning::TUNING;

/// The speed terms of one new segment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct StepSpeed {
    /// The original's programmed feed there, mm/s.
    pub(crate) programmed: f64,
    /// The speed VTG eq. 29 allows for the segment's curvature, mm/s (infinite below `K_cr`).
    pub(crate) limit: f64,
    /// The speed VTG eq. 29 allows for the mean curvature of the stretch the segment stands
    /// for, mm/s: `limit`, but for a segment that joins walked steps (`Way::stretch`).
    pub(crate) stretch_limit: f64,
    /// The original's planned speed over the stretch the segment replaces, mm/s: the feed is
    /// never lowered below it.
    pub(crate) floor: f64,
    /// The original's highest planned speed over that stretch, mm/s (infinite when unknown).
    pub(crate) ceiling: f64,
    /// The acceleration the firmware used there, mm/s² (0: unknown).
    pub(crate) accel: f64,
}

/// One way of writing a smoothed path's feeds ([`Smoothed::feeds`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Way {
    /// The VTG eq. 29 speeds' scale (`None`: no caps).
    pub(crate) scale: Option<f64>,
    /// No faster than the original went over the same stretch.
    pub(crate) ceiling: bool,
    /// A segment that joins walked steps capped for the mean curvature of the stretch it
    /// stands for, not for the tightest of its steps ([`StepSpeed::stretch_limit`]): the
    /// firmware runs it as one straight block that turns only at its ends, and a long
    /// straight joined to the first step of a fillet otherwise runs at the fillet's speed
    /// all its length (the thesis teardrop's 27 mm side at its tip's 12 mm/s).
    pub(crate) stretch: bool,
}

/// A rewritten path as it is written: points, filament and feed of each segment.
#[derive(Debug, Clone, Default, PartialEq)]
pub(crate) struct Written {
    /// Points after the start point.
    pub(crate) points: Vec<[f64; 3]>,
    /// Filament pushed from the path start to each point, mm.
    pub(crate) e: Vec<f64>,
    /// Feed of the segment ending at each point, mm/s.
    pub(crate) feed_mm_s: Vec<f64>,
    /// Segments written with a lowered feed.
    pub(crate) lowered: u64,
}

impl Smoothed {
    /// The path as written `way`: the VTG eq. 29 speeds scaled by its scale (`None`: no caps,
    /// the firmware's own cornering sets the speed), from `start` on; with its ceiling, no
    /// faster than the original went over the same stretch either (rounded corners let the machine
    /// carry more speed into each leg, so it peaks higher on it: faster, but dearer in motor
    /// energy). On a classic-jerk firmware rising feeds are ramped: such a planner counts a
    /// rise of the feed from one block to the next as jerk against the new block's full speed,
    /// so the segment where it rises is cut into pieces that each rise by a share of the jerk.
    pub(crate) fn written(&self, way: Way, start: [f64; 3], s: &Settings) -> Written {
        self.written_at(self.feeds(way), start, s)
    }

    /// The feed of each step as [`Smoothed::written`] sets it, before any ramp, and how many
    /// are lowered: all that sets one writing apart from another of the same path.
    pub(crate) fn feeds(&self, way: Way) -> Feeds {
        let mut feeds = Feeds {
            feed_mm_s: Vec::with_capacity(self.steps.len()),
            lowered: 0,
        };
        for st in &self.steps {
            let mut cap = f64::INFINITY;
            if let Some(k) = way.scale {
                let limit = if way.stretch {
                    st.stretch_limit
                } else {
                    st.limit
                };
                cap = (limit * k).max(st.floor);
            }
            if way.ceiling {
                cap = cap.min(st.ceiling);
            }
            let v = if cap < st.programmed * 0.99 {
                feeds.lowered += 1;
                cap.max(1.0)
            } else {
                st.programmed
            };
            feeds.feed_mm_s.push(v);
        }
        feeds
    }

    /// The path written with `feeds` ([`Smoothed::feeds`]), from `start` on.
    pub(crate) fn written_at(&self, feeds: Feeds, start: [f64; 3], s: &Settings) -> Written {
        let mut out = Written {
            points: self.points.clone(),
            e: self.e.clone(),
            feed_mm_s: feeds.feed_mm_s,
            lowered: feeds.lowered,
        };
        if let (Some(jerk), Some(first)) = (s.classic_jerk_mm_s, self.steps.first()) {
            let accel: Vec<f64> = self.steps.iter().map(|st| st.accel).collect();
            ramp_up(&mut out, start, first.programmed, jerk, &accel);
        }
        join_collinear(&mut out, start);
        out
    }
}

/// The feeds of one writing of a smoothed path, before any ramp ([`Smoothed::feeds`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Feeds {
    /// Feed of each step, mm/s.
    pub(crate) feed_mm_s: Vec<f64>,
    /// Steps written with a lowered feed.
    pub(crate) lowered: u64,
}

/// Largest turn between two segments joined as one, rad: well under the 0.001 mm rounding of
/// written coordinates over the shortest step.
const COLLINEAR_RAD: f64 = 1e-4;

/// Joins consecutive segments that run in one direction at one feed: the pieces a path was
/// cut into (at keyholes, polygons, retries) meet on straights, and the firmware gains nothing
/// from a junction that does not turn (the segment budget, [`crate::vtg::firmware`]). The
/// filament is cumulative, so the joined segment keeps its end's.
fn join_collinear(out: &mut Written, start: [f64; 3]) {
    let n = out.points.len();
    if n < 2 || out.e.len() != n || out.feed_mm_s.len() != n {
        return;
    }
    let mut keep = Vec::with_capacity(n);
    let mut from = start;
    for i in 0..n - 1 {
        let (a, b, c) = (from, out.points[i], out.points[i + 1]);
        let (d0, d1) = (sub(b, a), sub(c, b));
        let (n0, n1) = (norm(d0), norm(d1));
        let same_feed = (out.feed_mm_s[i] - out.feed_mm_s[i + 1]).abs() <= 1e-9;
        let cos = if n0 > 0.0 && n1 > 0.0 {
            crate::vec3::dot(d0, d1) / (n0 * n1)
        } else {
            -1.0
        };
        // Filament per mm equal too: the joined segment spreads it evenly.
        let e0 = out.e[i] - if i == 0 { 0.0 } else { out.e[i - 1] };
        let e1 = out.e[i + 1] - out.e[i];
        let even = n0 > 0.0 && n1 > 0.0 && (e0 / n0 - e1 / n1).abs() <= 1e-3 * (e0 / n0).abs();
        // Only at one height: a climbing path keeps the Z of every point (see `thinned`).
        let level = d0[2] == 0.0 && d1[2] == 0.0;
        let joined = level && same_feed && even && cos >= COLLINEAR_RAD.cos();
        if !joined {
            from = b;
        }
        keep.push(!joined);
    }
    keep.push(true);
    let mut k = keep.iter();
    out.points.retain(|_| k.next() == Some(&true));
    let mut k = keep.iter();
    out.e.retain(|_| k.next() == Some(&true));
    let mut k = keep.iter();
    out.feed_mm_s.retain(|_| k.next() == Some(&true));
}

/// Splits segments where the written feed rises by more than a classic-jerk planner takes
/// without slowing down.
///
/// Such a planner (Marlin's and Prusa firmware's classic jerk, and the slicers' estimators that
/// copy it) compares the *nominal* speeds of the two blocks at a junction: where the feed falls,
/// the previous block's speed is scaled down to the junction speed first, but where it rises, the
/// new block's full feed counts against the old one's, and a rise from 30 to 80 mm/s against a 7
/// mm/s jerk limit brings the junction down to 4 mm/s. Lowering the feed on a curve (VTG eq. 29)
/// would cost a near-stop wherever the feed rises again. So a segment whose feed rises by more than
/// the limit is cut into collinear pieces whose feeds rise by `Tuning::ramp_jerk_share` of it at a
/// time, each as long as the machine needs to accelerate through it at `accel[i]` (segment `i`'s
/// acceleration): the speed profile is the one it would have had anyway, and no junction is
/// penalised. The pieces lie on the segment and share its filament by length.
fn ramp_up(out: &mut Written, start: [f64; 3], start_feed: f64, jerk: f64, accel: &[f64]) {
    let rise = TUNING.ramp_jerk_share * jerk;
    if rise <= 0.0
        || accel.len() != out.points.len()
        || out.feed_mm_s.windows(2).all(|w| w[1] <= w[0] + jerk)
    {
        return;
    }
    let n = out.points.len();
    let mut points = Vec::with_capacity(n + 16);
    let mut e = Vec::with_capacity(n + 16);
    let mut feeds = Vec::with_capacity(n + 16);
    let (mut from, mut e_from, mut now) = (start, 0.0, start_feed);
    // `e` of the first point is the filament up to it from the piece's start.
    let segments = out.points.iter().zip(&out.e).zip(&out.feed_mm_s).zip(accel);
    for (i, (((&to, &e_to), &target), &a)) in segments.enumerate() {
        let len = norm(sub(to, from));
        let mut done = 0.0;
        if i > 0 && target > now + jerk && len > 0.0 && a > 0.0 {
            loop {
                let next = (now + rise).min(target);
                let piece = ((next * next - now * now) / (2.0 * a)).max(TUNING.min_ramp_piece_mm);
                if next >= target || done + piece >= len - TUNING.min_ramp_piece_mm {
                    break;
                }
                done += piece;
                let t = done / len;
                points.push(lerp(from, to, t));
                e.push(e_from + (e_to - e_from) * t);
                feeds.push(next);
                now = next;
            }
        }
        // The rest of the segment: at its own feed if the ramp got there, else still ramping.
        let last = if target > now + jerk && i > 0 {
            (now + rise).min(target)
        } else {
            target
        };
        points.push(to);
        e.push(e_to);
        feeds.push(last);
        now = last;
        from = to;
        e_from = e_to;
    }
    out.points = points;
    out.e = e;
    out.feed_mm_s = feeds;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A joined segment's feed: its tightest step's VTG eq. 29 speed as it is, its stretch's
    /// with `stretch`; either scaled, and neither below the original's speed there.
    #[test]
    fn stretch_caps_a_joined_segment_for_its_stretch() {
        let step = StepSpeed {
            programmed: 50.0,
            limit: 10.0,
            stretch_limit: 30.0,
            floor: 12.0,
            ceiling: f64::INFINITY,
            accel: 1000.0,
        };
        let smoothed = Smoothed {
            steps: vec![step],
            ..Smoothed::default()
        };
        let way = |scale, stretch| Way {
            scale,
            ceiling: false,
            stretch,
        };
        let feed = |w| smoothed.feeds(w).feed_mm_s[0];
        assert_eq!(feed(way(Some(1.0), false)), 12.0);
        assert_eq!(feed(way(Some(1.0), true)), 30.0);
        assert_eq!(feed(way(Some(1.5), true)), 45.0);
        assert_eq!(feed(way(None, true)), 50.0);
        assert_eq!(smoothed.feeds(way(Some(1.0), true)).lowered, 1);
    }

    #[test]
    fn ramp_rises_within_the_jerk_and_keeps_geometry_and_filament() {
        // A slow 1 mm stretch, then 20 mm at 60 mm/s: the rise from 10 to 60 mm/s is split
        // into pieces rising by 0.7 · 8 mm/s, each as long as 1000 mm/s² needs.
        let mut out = Written {
            points: vec![[1.0, 0.0, 0.2], [21.0, 0.0, 0.2]],
            e: vec![0.05, 1.05],
            feed_mm_s: vec![10.0, 60.0],
            lowered: 0,
        };
        ramp_up(&mut out, [0.0, 0.0, 0.2], 10.0, 8.0, &[1000.0; 2]);
        let n = out.points.len();
        assert!(n > 8, "{n}");
        assert_eq!(out.e.len(), n);
        assert_eq!(out.feed_mm_s.len(), n);
        // The original points stay, with their filament; the new ones lie on the segment.
        assert_eq!(out.points[0], [1.0, 0.0, 0.2]);
        assert_eq!(out.points[n - 1], [21.0, 0.0, 0.2]);
        assert_eq!((out.e[0], out.e[n - 1]), (0.05, 1.05));
        let mut prev = 10.0;
        for (i, (p, e)) in out.points.iter().zip(&out.e).enumerate() {
            assert!(p[1] == 0.0 && p[2] == 0.2 && p[0] >= 1.0 && p[0] <= 21.0);
            // Filament in proportion to the distance along the segment.
            assert!((e - (0.05 + (p[0] - 1.0) * 0.05)).abs() < 1e-12, "{i}: {e}");
            let f = out.feed_mm_s[i];
            assert!(f <= prev + 0.7 * 8.0 + 1e-9, "{i}: {prev} -> {f}");
            prev = f;
        }
        assert_eq!(out.feed_mm_s[n - 1], 60.0);
        // Each piece is as long as accelerating from its predecessor's feed to its own takes.
        let piece = |i: usize| out.points[i][0] - out.points[i - 1][0];
        let (f0, f1) = (out.feed_mm_s[1], out.feed_mm_s[2]);
        assert!((piece(2) - (f1 * f1 - f0 * f0) / 2000.0).abs() < 1e-9);
        // Falling feeds need nothing.
        let mut down = Written {
            points: vec![[1.0, 0.0, 0.2], [2.0, 0.0, 0.2]],
            e: vec![0.05, 0.1],
            feed_mm_s: vec![60.0, 10.0],
            lowered: 0,
        };
        ramp_up(&mut down, [0.0, 0.0, 0.2], 60.0, 8.0, &[1000.0; 2]);
        assert_eq!(down.points.len(), 2);
    }
}
