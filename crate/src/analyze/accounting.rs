//! Bookkeeping in two halves. The read side ([`Accounts`]) counts what the file says as lines
//! are read: moves, distances, filament, features, layers. The timing side ([`Timing`]) owns
//! the planner and the energy model and learns each move's time when the look-ahead finalises
//! it, some moves later; the two talk only through [`TimeMsg`]s, so the timing side can run on
//! its own thread natively (see `analyze`). Each move carries a sequence number, its feature
//! slot and its layers; temperature and fan events wait for the time at which they happen.

use std::collections::{HashMap, VecDeque};

use super::layered::LayeredMetrics;
use super::report::{Bounds, FanEvent, FeatureSummary, TemperatureEvent};
use super::toolpath::{MetricsAccumulator, MoveTrace, PathEnd, DEFAULT_CRITICAL_ANGLE_DEG};
use crate::energy::Accumulator;
use crate::energy::Material;
use crate::gcode::{feature_kind, FeatureKind};
use crate::machine::{Heater, Move};
use crate::math::Bound;
use crate::plan::segments::SegmentCounter;
use crate::plan::{Limits, Motion, PlannedMove, Planner, Profile};
use crate::read::{LayerTracker, NO_LAYER};

/// Feature slot of travel moves.
pub const TRAVEL: u32 = u32::MAX;

/// Totals that do not depend on timing.
#[derive(Debug, Default)]
pub struct Totals {
    pub moves: u64,
    pub extruding_moves: u64,
    pub distance_mm: f64,
    pub extrude_distance_mm: f64,
    pub travel_distance_mm: f64,
    pub retractions: u64,
    pub lines: u64,
    pub bounds: Option<Bounds>,
    pub dwell_s: f64,
    pub homing_count: u64,
}

/// An event waiting for its time.
#[derive(Debug, Clone, Copy)]
pub enum Pending {
    Temperature {
        line: u32,
        heater: Heater,
        target_c: f64,
        wait: bool,
    },
    Fan {
        line: u32,
        index: u16,
        speed: f64,
    },
}

/// Everything the analysis accumulates.
#[derive(Debug)]
pub struct Accounts {
    pub totals: Totals,
    pub features: Vec<FeatureSummary>,
    feature_names: HashMap<String, usize>,
    /// The feature extruding moves belong to, as slot and whether it is infill.
    current_feature: Option<(u32, bool)>,
    pub travel: FeatureSummary,
    /// Material named in the file's comments, if any.
    pub material: Option<Material>,
    /// Toolpath metrics of the VTG paper (VTG eq. 24–26, 31), unless the timing side takes
    /// them (see [`Self::toolpath_on_timing_side`]).
    pub toolpath: MetricsAccumulator,
    toolpath_here: bool,
    /// Where the last move ended, for each move's [`MoveTrace`].
    path_end: PathEnd,
    moves_read: u64,
    /// The last point put into the bounds, while moves keep extruding.
    bounded: Option<[f64; 3]>,
}

impl Accounts {
    pub fn new() -> Self {
        Self {
            totals: Totals::default(),
            features: Vec::new(),
            feature_names: HashMap::new(),
            current_feature: None,
            travel: summary("travel", None),
            material: None,
            toolpath: MetricsAccumulator::new(DEFAULT_CRITICAL_ANGLE_DEG),
            toolpath_here: true,
            path_end: PathEnd::default(),
            moves_read: 0,
            bounded: None,
        }
    }

    /// Leaves the toolpath metrics to the timing side, which takes them from each move's
    /// [`MoveTrace`] (see [`Timing::with_toolpath_metrics`]); [`Self::merge`] takes them back.
    pub fn toolpath_on_timing_side(&mut self) {
        self.toolpath_here = false;
    }

    /// A comment that is not a marker (learns the material).
    pub fn comment(&mut self, comment: &[u8]) {
        if self.material.is_none() {
            self.material = Material::from_comment(comment);
        }
    }

    /// The slicer names the feature that follows.
    pub fn feature(&mut self, name: &str) {
        self.set_feature(name);
    }

    /// Makes `name` the current feature; returns its slot and whether it is infill.
    fn set_feature(&mut self, name: &str) -> (u32, bool) {
        let i = self.feature_index(name);
        let infill = matches!(
            self.features[i].kind,
            Some(FeatureKind::SparseInfill | FeatureKind::SolidInfill)
        );
        let current = (u32::try_from(i).unwrap_or(TRAVEL - 1), infill);
        self.current_feature = Some(current);
        current
    }

    fn feature_index(&mut self, name: &str) -> usize {
        if let Some(&i) = self.feature_names.get(name) {
            return i;
        }
        self.feature_names
            .insert(name.to_string(), self.features.len());
        self.features.push(summary(name, Some(name)));
        self.features.len() - 1
    }

    /// A move was read, in `layers` (by marker, by count); returns the message that times it.
    pub fn read_move(&mut self, m: &Move, layers: (u32, u32)) -> TimeMsg {
        let extruding = m.is_extruding();
        account_move(m, extruding, &mut self.totals, &mut self.bounded);
        let (slot, infill) = if extruding {
            match self.current_feature {
                Some(current) => current,
                None => self.set_feature("unmarked"),
            }
        } else {
            (TRAVEL, false)
        };
        let trace = MoveTrace {
            extruding,
            infill,
            joins: self.path_end.step(&m.from, &m.to),
        };
        let s = self.slot(slot);
        s.moves += 1;
        s.distance_mm += m.length_mm;
        s.filament_mm += m.extrusion();
        self.moves_read += 1;
        let motion = Motion::from(m);
        if self.toolpath_here {
            self.toolpath
                .push_chord(chord(&motion.delta), m.kind.arc(), slot, trace);
        }
        if motion.arc.is_none() && motion.rotary_time_s == 0.0 {
            TimeMsg::Move {
                delta: motion.delta,
                feed_mm_s: motion.feed_mm_s,
                line: motion.line,
                slot,
                layers,
                trace,
            }
        } else {
            TimeMsg::Motion {
                m: Box::new(motion),
                slot,
                layers,
                trace,
            }
        }
    }

    /// A dwell, charged to the layer it is in.
    pub fn dwell(&mut self, secs: f64, layers: (u32, u32)) -> TimeMsg {
        self.totals.dwell_s += secs.at_least(0.0);
        TimeMsg::Dwell { secs, layers }
    }

    /// A heater target, to be timed.
    pub fn temperature(&self, line: u32, heater: Heater, target_c: f64, wait: bool) -> TimeMsg {
        TimeMsg::Event {
            before: self.moves_read,
            event: Pending::Temperature {
                line,
                heater,
                target_c,
                wait,
            },
        }
    }

    /// A fan speed, to be timed.
    pub fn fan(&self, line: u32, index: u16, speed: f64) -> TimeMsg {
        TimeMsg::Event {
            before: self.moves_read,
            event: Pending::Fan { line, index, speed },
        }
    }

    /// Adds the timing side's per-feature and per-layer times and energies, and gives its
    /// energy model the material the file names.
    pub fn merge(&mut self, timing: &mut TimeBook, layers: &mut LayerTracker) {
        if let Some(t) = timing.toolpath.take() {
            self.toolpath = t;
        }
        if let Some(m) = self.material {
            timing.energy.set_material_from_file(m);
        }
        for (i, (t, e)) in timing.feature_time.iter().enumerate() {
            if let Some(f) = self.features.get_mut(i) {
                f.time_s += t;
                f.energy_j += e;
            }
        }
        self.travel.time_s += timing.travel_time.0;
        self.travel.energy_j += timing.travel_time.1;
        for (i, (t, e)) in timing.layer_time[0].iter().enumerate() {
            layers.add_time_energy((i as u32, NO_LAYER), *t, *e);
        }
        for (i, (t, e)) in timing.layer_time[1].iter().enumerate() {
            layers.add_time_energy((NO_LAYER, i as u32), *t, *e);
        }
    }

    fn slot(&mut self, slot: u32) -> &mut FeatureSummary {
        match self.features.get_mut(slot as usize) {
            Some(f) if slot != TRAVEL => f,
            _ => &mut self.travel,
        }
    }
}

/// What the read side tells the timing side, in file order.
///
/// Straight moves, nearly every message, travel by value in a form that keeps the message at
/// 64 bytes (one cache line; a whole [`Motion`] would double it, and every message is written
/// by one thread and read by the other). Arcs and rotary-only moves, rare, carry their
/// [`Motion`] boxed. Moves are numbered on each side by counting them, so no sequence number
/// travels.
#[derive(Debug, Clone)]
pub enum TimeMsg {
    /// A straight move (no arc, no rotary-only time): its X, Y, Z, E displacement, feed rate
    /// and source line, with its feature slot and layers (marker count, Z count).
    Move {
        delta: [f64; 4],
        feed_mm_s: f64,
        line: u32,
        slot: u32,
        layers: (u32, u32),
        trace: MoveTrace,
    },
    /// Any other move, with its feature slot and layers.
    Motion {
        m: Box<Motion>,
        slot: u32,
        layers: (u32, u32),
        trace: MoveTrace,
    },
    /// A dwell: the queue drains, then time passes.
    Dwell { secs: f64, layers: (u32, u32) },
    /// The firmware finishes every queued move (heater wait).
    Flush,
    /// New limits from a command in the file.
    Limits(Box<Limits>),
    /// An event that happens before move number `before`.
    Event { before: u64, event: Pending },
}

/// The timing side: the planner, and the book its finalised moves are written into.
#[derive(Debug)]
pub struct Timing {
    pub planner: Planner,
    pub book: TimeBook,
    /// Moves received so far: the next move's sequence number.
    moves: u64,
}

/// Times, energies and timed events, as planned moves are finalised.
#[derive(Debug)]
pub struct TimeBook {
    pub energy: Accumulator,
    /// (time, energy) per feature slot.
    pub(super) feature_time: Vec<(f64, f64)>,
    pub(super) travel_time: (f64, f64),
    /// (time, energy) per layer: by markers, by Z.
    pub(super) layer_time: [Vec<(f64, f64)>; 2],
    /// (sequence, slot, layers) of moves not yet finalised.
    tags: VecDeque<(u64, u32, (u32, u32))>,
    pending: VecDeque<(u64, Pending)>,
    pub temperatures: Vec<TemperatureEvent>,
    pub fans: Vec<FanEvent>,
    /// The toolpath metrics, when the timing side takes them.
    pub toolpath: Option<MetricsAccumulator>,
    /// Every timed move's line and start, when kept ([`Timing::keeping_starts`]), and the tag
    /// of the move recorded last.
    pub starts: Option<(MoveStarts, Option<u64>)>,
    /// The planned blocks counted against a minimum segment time, when asked
    /// ([`Timing::counting_segments`]).
    pub segments: Option<SegmentCounter>,
    /// The file's and its layers' trajectory metrics, when asked
    /// ([`Timing::keeping_layer_metrics`]).
    pub layered: Option<LayeredMetrics>,
    /// Every timed move, when kept ([`Timing::keeping_timed_moves`]), and the tag of the move
    /// recorded last.
    pub timed: Option<(Vec<TimedMove>, Option<u64>)>,
}

/// One timed move as the planner ran it: its line, start and end (s from the start of the
/// file) and its speed profile. An arc's firmware segments are one move: the first one's
/// start, the last one's end and profile.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimedMove {
    /// 1-based line.
    pub line: u32,
    /// Start, s.
    pub start_s: f64,
    /// End, s.
    pub end_s: f64,
    /// Speed profile (an arc's last segment's).
    pub profile: Profile,
}

/// The line and planned start (s) of every timed move, in file order, an arc's firmware
/// segments counted once at the first: the clock a file's time estimates are written from.
pub type MoveStarts = Vec<(u32, f64)>;

fn add(v: &mut Vec<(f64, f64)>, i: u32, t: f64, e: f64) {
    if i == NO_LAYER || i == TRAVEL {
        return;
    }
    let i = i as usize;
    if v.len() <= i {
        v.resize(i + 1, (0.0, 0.0));
    }
    v[i].0 += t;
    v[i].1 += e;
}

impl Timing {
    pub fn new(planner: Planner, energy: Accumulator) -> Self {
        Self {
            planner,
            book: TimeBook::new(energy),
            moves: 0,
        }
    }

    /// Takes the toolpath metrics from the moves' [`MoveTrace`]s, for a read side that leaves
    /// them here ([`Accounts::toolpath_on_timing_side`]). In the browser the read side is the
    /// slower half of `analyze` (it also encodes every move for the other worker), so they
    /// ride with the planner there.
    pub fn with_toolpath_metrics(mut self) -> Self {
        self.book.toolpath = Some(MetricsAccumulator::new(DEFAULT_CRITICAL_ANGLE_DEG));
        self
    }

    /// Keeps every timed move's line and start ([`MoveStarts`], `capacity` expected): the
    /// file's clock, so that refreshing its estimates needs no planning pass of its own.
    pub fn keeping_starts(mut self, capacity: usize) -> Self {
        self.book.starts = Some((Vec::with_capacity(capacity), None));
        self
    }

    /// Takes the file's and its layers' trajectory metrics at `critical_angle_deg`
    /// ([`LayeredMetrics`]) from the moves' [`MoveTrace`]s.
    pub fn keeping_layer_metrics(mut self, critical_angle_deg: f64) -> Self {
        self.book.layered = Some(LayeredMetrics::new(critical_angle_deg));
        self
    }

    /// Keeps every timed move ([`TimedMove`], `capacity` expected): what a path read without
    /// planning takes its timing from ([`crate::path::PrintPath::set_timing`]).
    pub fn keeping_timed_moves(mut self, capacity: usize) -> Self {
        self.book.timed = Some((Vec::with_capacity(capacity), None));
        self
    }

    /// Counts the planned blocks against `min_segment_s` ([`SegmentCounter::timed`]).
    pub fn counting_segments(mut self, min_segment_s: f64) -> Self {
        self.book.segments = Some(SegmentCounter::new(min_segment_s));
        self
    }

    /// Handles one message from the read side.
    pub fn handle(&mut self, msg: TimeMsg) {
        let Timing {
            planner,
            book,
            moves,
        } = self;
        match msg {
            TimeMsg::Move {
                delta,
                feed_mm_s,
                line,
                slot,
                layers,
                trace,
            } => {
                if let Some(t) = &mut book.toolpath {
                    t.push_chord(chord(&delta), None, slot, trace);
                }
                if let Some(l) = &mut book.layered {
                    l.push_chord(chord(&delta), None, slot, (trace, layers));
                }
                let seq = *moves;
                *moves += 1;
                book.tags.push_back((seq, slot, layers));
                let m = Motion {
                    line,
                    delta,
                    arc: None,
                    feed_mm_s,
                    rotary_time_s: 0.0,
                };
                planner.push(&m, seq, &mut |pm| book.planned(pm));
            }
            TimeMsg::Motion {
                m,
                slot,
                layers,
                trace,
            } => {
                if let Some(t) = &mut book.toolpath {
                    t.push_chord(chord(&m.delta), m.arc.as_ref(), slot, trace);
                }
                if let Some(l) = &mut book.layered {
                    l.push_chord(chord(&m.delta), m.arc.as_ref(), slot, (trace, layers));
                }
                let seq = *moves;
                *moves += 1;
                book.tags.push_back((seq, slot, layers));
                planner.push(&m, seq, &mut |pm| book.planned(pm));
            }
            TimeMsg::Dwell { secs, layers } => {
                planner.flush(&mut |pm| book.planned(pm));
                book.stamp_until(u64::MAX, planner.elapsed_s());
                planner.dwell(secs, &mut |pm| book.planned(pm));
                let joules = book.energy.dwell(secs);
                add(&mut book.layer_time[0], layers.0, secs, joules);
                add(&mut book.layer_time[1], layers.1, secs, joules);
            }
            TimeMsg::Flush => planner.flush(&mut |pm| book.planned(pm)),
            TimeMsg::Limits(l) => *planner.limits_mut() = *l,
            TimeMsg::Event { before, event } => book.pending.push_back((before, event)),
        }
    }

    /// End of file: every move is final and every event timed.
    pub fn finish(&mut self) {
        self.handle(TimeMsg::Flush);
        self.book.stamp_until(u64::MAX, self.planner.elapsed_s());
    }
}

impl TimeBook {
    /// An empty book.
    pub fn new(energy: Accumulator) -> Self {
        TimeBook {
            energy,
            feature_time: Vec::new(),
            travel_time: (0.0, 0.0),
            layer_time: [Vec::new(), Vec::new()],
            tags: VecDeque::new(),
            pending: VecDeque::new(),
            temperatures: Vec::new(),
            fans: Vec::new(),
            toolpath: None,
            starts: None,
            segments: None,
            layered: None,
            timed: None,
        }
    }

    fn planned(&mut self, pm: &PlannedMove) {
        if let Some((starts, last)) = &mut self.starts {
            if *last != Some(pm.tag) {
                *last = Some(pm.tag);
                starts.push((pm.line, pm.start_s));
            }
        }
        if let Some(segments) = &mut self.segments {
            segments.timed(pm);
        }
        if let Some((timed, last)) = &mut self.timed {
            let end_s = pm.start_s + pm.duration();
            match timed.last_mut() {
                Some(t) if *last == Some(pm.tag) => (t.end_s, t.profile) = (end_s, pm.profile),
                _ => timed.push(TimedMove {
                    line: pm.line,
                    start_s: pm.start_s,
                    end_s,
                    profile: pm.profile,
                }),
            }
            *last = Some(pm.tag);
        }
        let joules = self.energy.planned(pm);
        self.stamp_until(pm.tag, pm.start_s);
        while self.tags.front().is_some_and(|t| t.0 < pm.tag) {
            self.tags.pop_front();
        }
        let Some(&(_, slot, layers)) = self.tags.front() else {
            return;
        };
        let d = pm.duration();
        if slot == TRAVEL {
            self.travel_time.0 += d;
            self.travel_time.1 += joules;
        } else {
            add(&mut self.feature_time, slot, d, joules);
        }
        add(&mut self.layer_time[0], layers.0, d, joules);
        add(&mut self.layer_time[1], layers.1, d, joules);
    }

    /// Stamps events that come before move `seq` with `time_s`.
    fn stamp_until(&mut self, seq: u64, time_s: f64) {
        while let Some(&(before, event)) = self.pending.front() {
            if before > seq {
                break;
            }
            self.pending.pop_front();
            match event {
                Pending::Temperature {
                    line,
                    heater,
                    target_c,
                    wait,
                } => {
                    self.temperatures.push(TemperatureEvent {
                        line,
                        time_s,
                        heater,
                        target_c,
                        wait,
                    });
                }
                Pending::Fan { line, index, speed } => self.fans.push(FanEvent {
                    line,
                    time_s,
                    index,
                    speed,
                }),
            }
        }
    }
}

fn summary(name: &str, kind_of: Option<&str>) -> FeatureSummary {
    FeatureSummary {
        name: name.to_string(),
        kind: kind_of.map(feature_kind),
        moves: 0,
        distance_mm: 0.0,
        filament_mm: 0.0,
        time_s: 0.0,
        energy_j: 0.0,
    }
}

/// `bounded`: the last point put into the bounds while moves keep extruding.
fn account_move(m: &Move, extruding: bool, totals: &mut Totals, bounded: &mut Option<[f64; 3]>) {
    totals.moves += 1;
    totals.distance_mm += m.length_mm;
    if extruding {
        totals.extruding_moves += 1;
        totals.extrude_distance_mm += m.length_mm;
        let b = totals.bounds.get_or_insert(Bounds {
            min: [f64::INFINITY; 3],
            max: [f64::NEG_INFINITY; 3],
        });
        let mut include = |p: &[f64; 3]| {
            for ((lo, hi), v) in b.min.iter_mut().zip(b.max.iter_mut()).zip(p) {
                *lo = lo.at_most(*v);
                *hi = hi.at_least(*v);
            }
        };
        let from = [m.from[0], m.from[1], m.from[2]];
        let to = [m.to[0], m.to[1], m.to[2]];
        // A move starts where the one before ended: if that one extruded, its end is the last
        // point bounded, and bounding the same point (same bits) again changes nothing.
        let same_bits =
            |a: &[f64; 3], b: &[f64; 3]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        if !bounded.is_some_and(|p| same_bits(&p, &from)) {
            include(&from);
        }
        include(&to);
        *bounded = Some(to);
    } else {
        *bounded = None;
        totals.travel_distance_mm += m.length_mm;
        if m.extrusion() < -1e-12 {
            totals.retractions += 1;
        }
    }
}

/// A move's XYZ chord from its XYZE displacement.
#[inline]
fn chord(delta: &[f64; 4]) -> [f64; 3] {
    [delta[0], delta[1], delta[2]]
}

#[cfg(test)]
mod tests {
    use super::TimeMsg;

    #[test]
    fn messages_fit_a_cache_line() {
        assert!(std::mem::size_of::<TimeMsg>() <= 64);
    }
}
