//! Building the trajectory ([`super::trajectory`]) one timed move at a time, in file order:
//! from an extracted path's moves, or as the planner times each move of a file read once
//! (the file's moves are never all held: a 34 MB file's take 370 MB). The segments go to an
//! [`Emit`]: a list ([`Kept`]) or a running simulation ([`super::stream::Stream`]).

use std::collections::VecDeque;

use super::trajectory::{geometry, Clock, Segment};
use crate::error::Error;
use crate::machine::{axis, MoveKind};
use crate::path::{MoveSink, MoveTiming, PathFeature, PathMove, PrintPath, Walked};
use crate::plan::{Limits, MachineProfile, PlannedMove, Profile};

/// Where the timeline's segments go, in time order: each with its layer by counting (the
/// segment's own `layer` is its layer by marker until the file says which it uses).
pub(super) trait Emit {
    fn emit(&mut self, seg: Segment, counted: u32);
    /// The file's machine, once, before the first segment.
    fn machine(&mut self, _profile: &MachineProfile) {}
    /// Whether it takes no more segments (the walk may stop reading).
    fn finished(&self) -> bool {
        false
    }
}

/// The segments on the layers `keep` accepts, in a list.
pub(super) struct Kept<K> {
    out: Vec<Segment>,
    counted: Vec<u32>,
    keep: K,
}

impl<K: Fn(u32) -> bool> Kept<K> {
    pub(super) fn new(keep: K, capacity: usize) -> Self {
        Kept {
            out: Vec::with_capacity(capacity),
            counted: Vec::with_capacity(capacity),
            keep,
        }
    }

    /// The kept segments, each on its layer by marker (`by_markers`) or by counting.
    pub(super) fn finish(self, by_markers: bool) -> Vec<Segment> {
        let Kept {
            mut out,
            counted,
            keep,
        } = self;
        if !by_markers {
            for (s, &layer) in out.iter_mut().zip(&counted) {
                s.layer = layer;
            }
        }
        out.retain(|s| keep(s.layer));
        out
    }
}

impl<K: Fn(u32) -> bool> Emit for Kept<K> {
    fn emit(&mut self, seg: Segment, counted: u32) {
        if (self.keep)(seg.layer) || (self.keep)(counted) {
            self.out.push(seg);
            self.counted.push(counted);
        }
    }
}

/// The segments of `path`'s moves on the layers `keep` accepts, with room for `capacity`;
/// `None` where a move has no timing.
pub(super) fn from_path(
    path: &PrintPath,
    keep: impl Fn(u32) -> bool,
    capacity: usize,
) -> Option<Vec<Segment>> {
    let mut timeline = Timeline::new(Kept::new(keep, capacity));
    timeline.latch(&path.print_limits);
    for m in &path.moves {
        if !timeline.place(m, m.timing, (m.layer, m.layer)) {
            return None;
        }
    }
    Some(timeline.emit.finish(true))
}

/// The segments of `input` on the layers `keep` accepts, with room for `capacity`, built as
/// the planner times each move (`None` where a move has no timing), and what the walk learnt.
pub(super) fn kept_of_file(
    input: &[u8],
    options: &crate::analyze::AnalyzeOptions,
    keep: impl Fn(u32) -> bool,
    capacity: usize,
) -> Result<(Option<Vec<Segment>>, Walked), Error> {
    let (kept, timed, walked) = walked_into(Kept::new(keep, capacity), |sink| {
        crate::path::walk_piped(input, options, sink)
    })?;
    let by_markers = matches!(walked.layer_source, crate::read::LayerSource::Markers(_));
    Ok((timed.then(|| kept.finish(by_markers)), walked))
}

/// `input` read and planned once, its segments emitted into `emit` as the planner times each
/// move. The emitter, whether every move was timed, and what the walk learnt.
pub(super) fn of_file<E: Emit>(
    input: &[u8],
    options: &crate::analyze::AnalyzeOptions,
    emit: E,
) -> Result<(E, bool, Walked), Error> {
    walked_into(emit, |sink| crate::path::walk(input, options, true, sink))
}

/// [`of_file`] with the file's moves walked by `walk` (on one thread or two).
fn walked_into<E: Emit>(
    emit: E,
    walk: impl FnOnce(&mut Streamed<E>) -> Result<Walked, Error>,
) -> Result<(E, bool, Walked), Error> {
    let mut sink = Streamed {
        timeline: Timeline::new(emit),
        limits: None,
        latched: false,
        waiting: VecDeque::new(),
        early: Vec::new(),
        untimed: false,
    };
    let walked = walk(&mut sink)?;
    while let Some(w) = sink.waiting.pop_front() {
        sink.done(w);
    }
    if !sink.latched {
        // No extruding move: the limits of the whole file's end are the ones in force.
        sink.latch(&walked.print_limits);
    }
    Ok((sink.timeline.emit, !sink.untimed, walked))
}

/// The lower of the X and Y feed limits, mm/s: an arc's direction turns, so both bound it.
fn xy_feed_limit(limits: &Limits) -> f64 {
    let f = &limits.max_feedrate;
    f[axis::X].value.min(f[axis::Y].value)
}

/// The trajectory built one timed move at a time, in file order.
struct Timeline<E> {
    emit: E,
    /// The last segment on the timeline: an arc starts at its exit speed.
    last: Option<Segment>,
    /// End of the last segment on our timeline.
    cursor: f64,
    /// End of the last move on the planner's timeline.
    planned_end: f64,
    /// [`xy_feed_limit`] of the limits in force when printing (arcs' feed cap).
    xy_feed_limit: f64,
    /// The limits in force when printing, which time homing moves ([`Timeline::homing`]).
    print_limits: Option<Limits>,
}

impl<E: Emit> Timeline<E> {
    fn new(emit: E) -> Self {
        Timeline {
            emit,
            last: None,
            cursor: 0.0,
            planned_end: 0.0,
            xy_feed_limit: f64::NAN,
            print_limits: None,
        }
    }

    /// The limits in force when printing are `limits`.
    fn latch(&mut self, limits: &Limits) {
        self.xy_feed_limit = xy_feed_limit(limits);
        self.print_limits = Some(limits.clone());
    }

    /// Move `m` on layers `layers`, timed `t` by the planner; a homing move the planner leaves
    /// untimed (`G28` on Klipper, `crate::read::At::untimed_homing`) as [`Timeline::homing`]
    /// times it. `false` for any other move without timing.
    fn place(&mut self, m: &PathMove, t: Option<MoveTiming>, layers: (u32, u32)) -> bool {
        match t {
            Some(t) => self.push(m, t, layers),
            None if matches!(m.kind, MoveKind::Home) => {
                if let Some(profile) = self.homing(m) {
                    self.put(m, self.cursor, profile, layers);
                }
            }
            None => return false,
        }
        true
    }

    /// A homing move the planner leaves untimed, as the simulation runs it: from rest to rest
    /// at the file's feed and the printing travel acceleration, each within the axes' own
    /// limits along the move. Klipper homes at each stepper's `homing_speed`, which no file
    /// tells; the toolhead does stop before and after (the planner empties its look-ahead),
    /// and the head does travel to the switch, so a file that homes mid-print or at its end is
    /// simulated with the move rather than refused (the planner's clock, which does not count
    /// it, is left as it is). `None` where the printing limits are not known yet.
    fn homing(&self, m: &PathMove) -> Option<Profile> {
        let l = self.print_limits.as_ref()?;
        let (mut feed, mut accel) = (m.feed_mm_s, l.travel_acceleration.value);
        for i in [axis::X, axis::Y, axis::Z] {
            let share = (m.to[i] - m.from[i]).abs() / m.length_mm;
            if share > 0.0 {
                feed = feed.min(l.max_feedrate[i].value / share);
                accel = accel.min(l.max_acceleration[i].value / share);
            }
        }
        Some(Profile::new(m.length_mm, 0.0, feed, 0.0, accel))
    }

    /// Move `m`, timed `t`, on layers `layers` (by marker, by counting).
    fn push(&mut self, m: &PathMove, t: MoveTiming, layers: (u32, u32)) {
        if !t.duration_s.is_finite() || !t.start_s.is_finite() {
            return;
        }
        let cursor = self.cursor;
        let (start, profile) = if matches!(m.kind, MoveKind::Arc(_)) {
            // The planner times an arc as straight firmware segments; the simulation follows the
            // true arc with one trapezoid, starting where the previous move ended.
            let entry = self
                .last
                .as_ref()
                .filter(|s| (s.end_s() - cursor).abs() < 1e-12)
                .map_or(0.0, |s| s.profile.exit);
            // The requested feed within the machine's X/Y speed limits.
            let axis_max = self.xy_feed_limit;
            let feed = if axis_max > 0.0 {
                m.feed_mm_s.min(axis_max)
            } else {
                m.feed_mm_s
            };
            let cruise = feed.max(t.profile.peak);
            let a = t.profile.acceleration;
            (
                cursor,
                Profile::new(m.length_mm, entry, cruise, t.profile.exit, a),
            )
        } else {
            let gap = (t.start_s - self.planned_end).max(0.0);
            (cursor + gap, t.profile)
        };
        self.planned_end = self.planned_end.max(t.start_s + t.duration_s);
        self.put(m, start, profile, layers);
    }

    /// Move `m` on the timeline from `start`, run as `profile`.
    fn put(&mut self, m: &PathMove, start: f64, profile: Profile, layers: (u32, u32)) {
        let duration = profile.duration();
        if !(duration.is_finite() && duration > 0.0) {
            return;
        }
        let seg = Segment {
            start_s: start,
            duration_s: duration,
            profile,
            from: [m.from[axis::X], m.from[axis::Y]],
            to: [m.to[axis::X], m.to[axis::Y]],
            geometry: geometry(m),
            layer: layers.0,
            extruding: m.is_extruding(),
            clock: Clock::default(),
        };
        self.cursor = seg.end_s();
        self.last = Some(seg);
        self.emit.emit(seg, layers.1);
    }
}

/// A move read, waiting for the planner's last word on its timing.
type Waiting = (usize, PathMove, Option<MoveTiming>, (u32, u32));

/// The [`MoveSink`] of [`of_file`]: each move goes on the timeline once the planner has timed
/// it and moved past it (an arc is timed in several calls). Until the first extruding move,
/// whose limits cap the arcs' feeds, timed moves wait in `early`.
struct Streamed<E> {
    timeline: Timeline<E>,
    /// The limits in force now (the walk tells them before the first move).
    limits: Option<Limits>,
    /// Whether the printing limits are known (the first extruding move was read).
    latched: bool,
    waiting: VecDeque<Waiting>,
    early: Vec<Waiting>,
    /// Whether a move was left without timing.
    untimed: bool,
}

impl<E: Emit> Streamed<E> {
    /// Move `w`'s timing is final.
    fn done(&mut self, w: Waiting) {
        if !self.latched {
            self.early.push(w);
            return;
        }
        if !self.timeline.place(&w.1, w.2, w.3) {
            self.untimed = true;
        }
    }

    /// The printing limits are known: `limits` cap the arcs' feeds and time homing moves.
    fn latch(&mut self, limits: &Limits) {
        self.latched = true;
        self.timeline.latch(limits);
        for w in std::mem::take(&mut self.early) {
            self.done(w);
        }
    }
}

impl<E: Emit> MoveSink for Streamed<E> {
    fn moved(&mut self, index: usize, m: PathMove, layers: (u32, u32), _: &[PathFeature]) {
        if !self.latched && m.is_extruding() {
            if let Some(limits) = self.limits.take() {
                self.latch(&limits);
                self.limits = Some(limits);
            }
        }
        self.waiting.push_back((index, m, None, layers));
    }

    fn timed(&mut self, pm: &PlannedMove) {
        let tag = pm.tag as usize;
        while self.waiting.front().is_some_and(|w| w.0 < tag) {
            if let Some(w) = self.waiting.pop_front() {
                self.done(w);
            }
        }
        if let Some(w) = self.waiting.front_mut().filter(|w| w.0 == tag) {
            let end = pm.start_s + pm.duration();
            let start_s = w.2.map_or(pm.start_s, |t| t.start_s);
            w.2 = Some(MoveTiming {
                start_s,
                duration_s: end - start_s,
                profile: pm.profile,
            });
        }
    }

    fn limits(&mut self, limits: &Limits) {
        self.limits = Some(limits.clone());
    }

    fn machine(&mut self, profile: &MachineProfile) {
        self.timeline.emit.machine(profile);
    }

    fn finished(&self) -> bool {
        self.timeline.emit.finished()
    }
}
