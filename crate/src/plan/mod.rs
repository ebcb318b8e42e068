//! Firmware-faithful motion planning: per-move trapezoids with look-ahead over the whole file.
//!
//! The planner follows the structure every firmware (and PrusaSlicer's estimator) shares:
//! each move becomes a block with a cruise speed (the feed rate, clamped by per-axis maximum
//! feed rates), an acceleration (printing, travel or retraction, clamped by per-axis maximum
//! accelerations) and a maximum entry speed from the junction model; a reverse pass lowers entry
//! speeds so every block can brake in time, a forward pass lowers them so every block can be
//! reached, and each block's trapezoid follows. Memory is bounded: blocks are planned in a
//! window of [`REFRESH_THRESHOLD`] and all but the last [`KEEP_BLOCKS`] are final and handed to
//! the caller's sink, as PrusaSlicer's time estimator does.
//!
//! Klipper adds one step of its own (`toolhead.py`): a chain of moves that speeds up and slows
//! down again peaks no higher than if the whole chain accelerated and braked at
//! `accel_to_decel` (the minimum cruise ratio), so the window's cruise speeds and junctions are
//! capped by each chain's peak before the trapezoids are built.
//!
//! Arcs are split into straight segments as the firmware splits them: Prusa's firmware by chord
//! deviation and segment rate up to `arc_segment_mm`, upstream Marlin 2.1 into at least 72
//! segments a circle of 0.1 mm to `arc_segment_mm` ([`ArcRule`]), Klipper into pieces of
//! `arc_segment_mm` (its `[gcode_arcs] resolution`).

pub mod junction;
pub mod klipper_config;
pub mod limits;
pub mod profiles;
pub mod segments;
pub mod trapezoid;

use serde::Serialize;

use crate::machine::{axis, Move};
use crate::math::Bound;
use junction::Segment;
pub use klipper_config::{KlipperConfig, KlipperConfigError, KlipperVersion};
pub use limits::{ArcRule, FeedUnits, JunctionModel, Limit, LimitSource, Limits};
pub use profiles::MachineProfile;
pub use trapezoid::Profile;

/// Blocks kept un-finalised at the end of the window (they may still slow down for what follows).
pub const KEEP_BLOCKS: usize = 64;
/// Window size at which the planner recalculates and finalises blocks.
pub const REFRESH_THRESHOLD: usize = KEEP_BLOCKS * 4;
/// Klipper: most blocks a window holds while it waits for a second peak to finalise up to.
pub const KLIPPER_MAX_WINDOW: usize = REFRESH_THRESHOLD * 16;
/// Most straight segments one arc is split into.
pub const MAX_ARC_SEGMENTS: usize = 100_000;

/// What the planner needs of a move: its X, Y, Z, E displacement, its arc if it is one, its
/// feed rate. (A [`Move`] carries every axis at both ends; this is what crosses to the timing
/// side, so it is kept small.)
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// 1-based source line.
    pub line: u32,
    /// Displacement X, Y, Z, E, mm.
    pub delta: [f64; 4],
    /// The arc, for `G2`/`G3`.
    pub arc: Option<crate::machine::Arc>,
    /// Requested feed rate, mm/s.
    pub feed_mm_s: f64,
    /// Time of a move of the rotary axes alone at its feed rate, s (0 otherwise).
    pub rotary_time_s: f64,
}

impl From<&Move> for Motion {
    #[inline]
    fn from(m: &Move) -> Self {
        let delta = [
            m.to[axis::X] - m.from[axis::X],
            m.to[axis::Y] - m.from[axis::Y],
            m.to[axis::Z] - m.from[axis::Z],
            m.to[axis::E] - m.from[axis::E],
        ];
        let arc = m.kind.arc().copied();
        let rotary_time_s = if arc.is_none() && delta.iter().all(|v| v.abs() < 1e-12) {
            m.nominal_time()
        } else {
            0.0
        };
        Motion {
            line: m.line,
            delta,
            arc,
            feed_mm_s: m.feed_mm_s,
            rotary_time_s,
        }
    }
}

/// What a move does, which decides its acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MoveClass {
    /// Moves the tool and extrudes.
    Print,
    /// Moves the tool without extruding.
    Travel,
    /// Moves only the extruder (retraction, recovery, priming).
    Retract,
}

/// A planned move, final: what the machine does, phase by phase.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PlannedMove {
    /// 1-based source line.
    pub line: u32,
    /// Caller's tag given with the move (feature and layer indices, for example).
    pub tag: u64,
    /// Kind of move.
    pub class: MoveClass,
    /// Displacement per axis X, Y, Z, E, mm.
    pub delta: [f64; 4],
    /// Path length the speeds refer to (XYZ, or E for extruder-only moves), mm.
    pub distance: f64,
    /// Speed profile along the path.
    pub profile: Profile,
    /// Time at which the move starts, s from the start of the file.
    pub start_s: f64,
}

impl PlannedMove {
    /// Duration, s.
    pub fn duration(&self) -> f64 {
        self.profile.duration()
    }

    /// The fraction of the path speed that axis `i` (0..4 = X, Y, Z, E) moves at.
    pub fn axis_share(&self, i: usize) -> f64 {
        if self.distance > 0.0 {
            self.delta[i].abs() / self.distance
        } else {
            0.0
        }
    }
}

/// Largest chord deviation of arc segments, mm (Marlin 2's `MAX_ARC_DEVIATION`).
pub const MAX_ARC_DEVIATION_MM: f64 = 0.02;
/// Shortest arc segment, mm (Marlin 2's `MIN_ARC_SEGMENT_MM`).
pub const MIN_ARC_SEGMENT_MM: f64 = 0.1;
/// Segments per second the firmware aims for at least (Marlin 2's `ARC_SEGMENTS_PER_SEC`).
pub const ARC_SEGMENTS_PER_SEC: f64 = 50.0;
/// Fewest segments of a full circle in upstream Marlin 2.1 (`MIN_CIRCLE_SEGMENTS`).
pub const MIN_CIRCLE_SEGMENTS: f64 = 72.0;

/// Number of straight segments an arc is split into, as Prusa's Marlin 2 does
/// ([`ArcRule::ChordDeviation`]): segments
/// short enough to keep the chord within [`MAX_ARC_DEVIATION_MM`] and to run at least
/// [`ARC_SEGMENTS_PER_SEC`] at the feed rate, but between [`MIN_ARC_SEGMENT_MM`] and the
/// machine's `arc_segment_mm`.
pub fn arc_segments(radius: f64, planar_length: f64, feed_mm_s: f64, max_segment_mm: f64) -> usize {
    let max = max_segment_mm.at_least(MIN_ARC_SEGMENT_MM);
    let seg = (8.0 * radius * MAX_ARC_DEVIATION_MM)
        .sqrt()
        .at_most(feed_mm_s / ARC_SEGMENTS_PER_SEC)
        .clamp(MIN_ARC_SEGMENT_MM, max);
    segment_count(planar_length / seg + 0.8)
}

/// A segment count from its real-valued estimate: at least 1, at most [`MAX_ARC_SEGMENTS`]
/// (also for an infinite or NaN estimate).
fn segment_count(n: f64) -> usize {
    if n.is_finite() {
        (n as usize).clamp(1, MAX_ARC_SEGMENTS)
    } else {
        MAX_ARC_SEGMENTS
    }
}

/// Number of straight segments upstream Marlin 2.1's `plan_arc` cuts an arc of `radius` and
/// `planar_length` into, with `MAX_ARC_SEGMENT_MM` `max_segment_mm` ([`ArcRule::CircleSegments`]):
/// `max(⌊l / max⌋, ⌈72 · sweep / 2π⌉)` segments, unless that makes them longer than the
/// maximum (then `⌈l / max⌉`) or shorter than [`MIN_ARC_SEGMENT_MM`] (then `⌊l / 0.1⌋`, at
/// least 1). A hairpin of radius 0.225 mm (half a circle, 0.71 mm) is 7 chords of 25.7°.
pub fn marlin_arc_segments(radius: f64, planar_length: f64, max_segment_mm: f64) -> usize {
    let max = max_segment_mm.at_least(MIN_ARC_SEGMENT_MM);
    let portion = planar_length / (radius * std::f64::consts::TAU);
    let min_segments = (MIN_CIRCLE_SEGMENTS * portion).ceil();
    let nominal = (planar_length / max).floor().max(min_segments);
    let nominal_mm = planar_length / nominal;
    let n = if nominal_mm > max {
        (planar_length / max).ceil()
    } else if nominal_mm < MIN_ARC_SEGMENT_MM {
        (planar_length / MIN_ARC_SEGMENT_MM).floor().max(1.0)
    } else {
        nominal
    };
    segment_count(n)
}

/// How a firmware cuts arcs: its junction model (Klipper's `[gcode_arcs]` has a rule of its
/// own), the Marlin-family rule, and the longest segment, mm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArcCutting {
    /// The planner's junction model.
    pub model: JunctionModel,
    /// The Marlin-family rule (not read under Klipper).
    pub rule: ArcRule,
    /// The longest segment (Marlin's `MAX_ARC_SEGMENT_MM`, Klipper's `resolution`), mm.
    pub max_segment_mm: f64,
}

impl ArcCutting {
    /// The cutting the planner applies under `limits` with junction model `model`.
    pub fn of(model: JunctionModel, limits: &Limits) -> Self {
        ArcCutting {
            model,
            rule: limits.arc_rule,
            max_segment_mm: limits.arc_segment_mm.value,
        }
    }

    /// Number of straight segments an arc of `radius` is cut into: Klipper's `[gcode_arcs]`
    /// makes pieces of `resolution` (`max_segment_mm`, 1 mm unless set) along the helix
    /// (`rise`: along its axis), `floor(length / resolution)` of them; a Marlin-family firmware
    /// by its [`ArcRule`], by the planar length.
    pub fn segments(
        &self,
        radius: f64,
        (planar_length, rise): (f64, f64),
        feed_mm_s: f64,
    ) -> usize {
        match (self.model, self.rule) {
            (JunctionModel::Klipper, _) => {
                let length = planar_length.hypot(rise);
                segment_count((length / self.max_segment_mm.at_least(1e-3)).floor())
            }
            (_, ArcRule::ChordDeviation) => {
                arc_segments(radius, planar_length, feed_mm_s, self.max_segment_mm)
            }
            (_, ArcRule::CircleSegments) => {
                marlin_arc_segments(radius, planar_length, self.max_segment_mm)
            }
        }
    }
}

#[derive(Debug, Clone)]
struct Block {
    line: u32,
    tag: u64,
    class: MoveClass,
    delta: [f64; 4],
    distance: f64,
    acceleration: f64,
    entry: f64,
    cruise: f64,
    exit: f64,
    max_entry: f64,
    /// Speed the block may end at if nothing follows it.
    safe: f64,
    /// Klipper: how much the squared speed may change over the block at the "smoothed"
    /// acceleration `accel_to_decel` = accel (1 − minimum_cruise_ratio), mm²/s² (0 otherwise).
    smooth_delta_v2: f64,
    /// Klipper: the highest squared junction speed a chain of blocks smoothed that way can
    /// reach at the block's start, mm²/s².
    max_smoothed_v2: f64,
    nominal_length: bool,
    recalculate: bool,
    /// The entry speed is the exit speed of an already finalised block and may not change.
    entry_fixed: bool,
}

impl Block {
    /// The block's speed profile between the given junction speeds, cruising at most at
    /// `cruise`. Only finalised blocks need it, so the look-ahead passes work on speeds alone.
    fn profile(&self, entry: f64, cruise: f64, exit: f64) -> Profile {
        // Marlin's safe-speed rule can put a junction above this block's nominal speed (a slow
        // extrusion followed by a travel): the firmware runs the block at its nominal rate and
        // the next one starts faster (the stepper's braking phase, clamped to the final rate,
        // would begin after a plateau that already covers the whole block), as PrusaSlicer's
        // estimator also times it. Raising the block's cruise to its exit instead would run a
        // 1.4 mm/s perimeter at the travel's 8 mm/s.
        Profile::new(
            self.distance,
            entry,
            cruise,
            exit.at_most(cruise),
            self.acceleration,
        )
    }
}

/// The streaming planner.
#[derive(Debug, Clone)]
pub struct Planner {
    limits: Limits,
    model: JunctionModel,
    blocks: Vec<Block>,
    /// Profiles of the blocks being finalised (kept to reuse its allocation).
    profiles: Vec<Profile>,
    /// Klipper's cruise speed² of each block in the window (reused likewise).
    cruise_v2: Vec<f64>,
    prev: Option<Segment>,
    elapsed_s: f64,
    finalized: u64,
}

impl Planner {
    /// A planner at rest with these limits and junction model.
    pub fn new(limits: Limits, model: JunctionModel) -> Self {
        Self {
            limits,
            model,
            blocks: Vec::with_capacity(REFRESH_THRESHOLD + 1),
            profiles: Vec::with_capacity(REFRESH_THRESHOLD + 1),
            cruise_v2: Vec::with_capacity(REFRESH_THRESHOLD + 1),
            prev: None,
            elapsed_s: 0.0,
            finalized: 0,
        }
    }

    /// The limits in force.
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The limits, for commands that change them. New values apply to moves pushed after.
    pub fn limits_mut(&mut self) -> &mut Limits {
        &mut self.limits
    }

    /// The junction model.
    pub fn model(&self) -> JunctionModel {
        self.model
    }

    /// Time of all finalised moves and dwells, s.
    pub fn elapsed_s(&self) -> f64 {
        self.elapsed_s
    }

    /// Number of moves finalised so far.
    pub fn finalized(&self) -> u64 {
        self.finalized
    }

    /// Number of moves pushed so far (finalised or not).
    pub fn pushed(&self) -> u64 {
        self.finalized + self.blocks.len() as u64
    }

    /// Plans a motion; finalised moves go to `sink`.
    pub fn push(&mut self, m: &Motion, tag: u64, sink: &mut impl FnMut(&PlannedMove)) {
        match m.arc {
            Some(arc) => {
                let (p0, p1, h) = arc.plane.axes();
                let n = ArcCutting::of(self.model, &self.limits).segments(
                    arc.radius,
                    (arc.planar_length(), m.delta[h]),
                    m.feed_mm_s,
                );
                let mut prev = [0.0f64; 4];
                for k in 1..=n {
                    let t = k as f64 / n as f64;
                    let mut cur = [0.0f64; 4];
                    // Klipper ends the last piece on the target, which an end point a little
                    // off the arc's circle (rounded in the file) does not lie on.
                    let p = match self.model {
                        JunctionModel::Klipper if k == n => [m.delta[p0], m.delta[p1]],
                        _ => arc.offset_at(t),
                    };
                    cur[p0] = p[0];
                    cur[p1] = p[1];
                    cur[h] = m.delta[h] * t;
                    cur[3] = m.delta[3] * t;
                    let d = [
                        cur[0] - prev[0],
                        cur[1] - prev[1],
                        cur[2] - prev[2],
                        cur[3] - prev[3],
                    ];
                    self.push_segment(m.line, tag, d, m.feed_mm_s, sink);
                    prev = cur;
                }
            }
            None => {
                if m.delta.iter().all(|v| v.abs() < 1e-12) {
                    // Rotary-only moves: timed at the feed rate over their angle, no dynamics.
                    if m.rotary_time_s > 0.0 {
                        self.dwell(m.rotary_time_s, sink);
                    }
                    return;
                }
                self.push_segment(m.line, tag, m.delta, m.feed_mm_s, sink);
            }
        }
    }

    fn push_segment(
        &mut self,
        line: u32,
        tag: u64,
        delta: [f64; 4],
        feed: f64,
        sink: &mut impl FnMut(&PlannedMove),
    ) {
        let l = &self.limits;
        let Some((distance, class)) = distance_and_class(&delta) else {
            return;
        };
        let inv_distance = 1.0 / distance;
        let (cruise, axis_feedrate, acceleration, toolhead_accel) =
            self.speed_and_accel(class, feed, &delta, distance, inv_distance);
        let unit = if class == MoveClass::Retract {
            [0.0; 3]
        } else {
            [
                delta[0] * inv_distance,
                delta[1] * inv_distance,
                delta[2] * inv_distance,
            ]
        };
        let safe = match self.model {
            JunctionModel::ClassicJerk => junction::safe_speed(&axis_feedrate, cruise, l),
            JunctionModel::JunctionDeviation => junction::MINIMUM_PLANNER_SPEED.at_most(cruise),
            // Klipper starts from and stops at rest.
            JunctionModel::Klipper => 0.0,
        };
        let scv = l.square_corner_velocity.value;
        let curr = Segment {
            axis_feedrate,
            cruise,
            safe,
            unit,
            distance,
            acceleration,
            klipper_jd: junction::klipper_junction_deviation(scv, toolhead_accel),
        };
        let vmax_junction = match (&self.prev, self.model) {
            (None, _) => safe,
            (Some(prev), JunctionModel::ClassicJerk) => junction::classic_jerk(prev, &curr, l),
            (Some(prev), JunctionModel::JunctionDeviation) => {
                junction::junction_deviation(prev, &curr, l)
            }
            (Some(prev), JunctionModel::Klipper) => junction::klipper(prev, &curr, l),
        };
        let v_allowable = trapezoid::max_allowable_speed(-acceleration, safe, distance);
        let (smooth_delta_v2, max_smoothed_v2) = match self.model {
            JunctionModel::Klipper => {
                self.klipper_smoothing(distance, acceleration, toolhead_accel, vmax_junction)
            }
            _ => (0.0, 0.0),
        };
        let block = Block {
            line,
            tag,
            class,
            delta,
            distance,
            acceleration,
            entry: vmax_junction.at_most(v_allowable),
            cruise,
            exit: safe,
            max_entry: vmax_junction,
            safe,
            smooth_delta_v2,
            max_smoothed_v2,
            nominal_length: cruise <= v_allowable,
            recalculate: true,
            entry_fixed: false,
        };
        self.prev = Some(curr);
        self.blocks.push(block);
        if self.blocks.len() > REFRESH_THRESHOLD {
            self.plan_window(KEEP_BLOCKS, sink);
        }
    }

    /// A move's cruise speed, per-axis speeds at it, acceleration, and the toolhead's
    /// acceleration it was queued with (Klipper's junction deviation and smoothing use it;
    /// Marlin's models have no other).
    #[inline]
    fn speed_and_accel(
        &self,
        class: MoveClass,
        feed: f64,
        delta: &[f64; 4],
        distance: f64,
        inv_distance: f64,
    ) -> (f64, [f64; 4], f64, f64) {
        let l = &self.limits;
        if self.model == JunctionModel::Klipper {
            return klipper_speed_and_accel(l, class, feed, delta, distance);
        }
        let (cruise, axis_feedrate) = cruise_speed(l, class, feed, delta, inv_distance);
        let acceleration = self.acceleration(class, delta, distance, inv_distance);
        (cruise, axis_feedrate, acceleration, acceleration)
    }

    /// Acceleration of a move (Marlin's models): by kind of move, then every axis within its
    /// limit.
    #[inline]
    fn acceleration(
        &self,
        class: MoveClass,
        delta: &[f64; 4],
        distance: f64,
        inv_distance: f64,
    ) -> f64 {
        let l = &self.limits;
        let mut acceleration = match class {
            MoveClass::Print => l.acceleration.value,
            MoveClass::Travel => l.travel_acceleration.value,
            MoveClass::Retract => l.retract_acceleration.value,
        };
        for (d, max) in delta.iter().zip(&l.max_acceleration) {
            let (d, max) = (d.abs(), max.value);
            if d > 1e-12 && max > 0.0 && acceleration * d * inv_distance > max {
                acceleration = max * distance / d;
            }
        }
        acceleration.at_least(1e-3)
    }

    /// Klipper's `smooth_delta_v2` and `max_smoothed_v2` of a move of `distance` at
    /// `acceleration` (its own, after the Z and extruder limits), queued while the toolhead's
    /// `max_accel` was `toolhead_accel`, whose junction allows `vmax_junction`. The smoothed
    /// rate is the toolhead's (`max_accel_to_decel`, or `max_accel` × (1 − ratio)), capped by
    /// the move's own acceleration (`Move.limit_speed`): a Z hop or a retraction is smoothed at
    /// its own lower rate, not at a fraction of it.
    #[inline]
    fn klipper_smoothing(
        &self,
        distance: f64,
        acceleration: f64,
        toolhead_accel: f64,
        vmax_junction: f64,
    ) -> (f64, f64) {
        let l = &self.limits;
        let pseudo = if l.accel_to_decel.value > 0.0 {
            l.accel_to_decel.value.at_most(toolhead_accel)
        } else {
            toolhead_accel * (1.0 - l.minimum_cruise_ratio.value.clamp(0.0, 0.99))
        };
        let accel_to_decel = pseudo.at_most(acceleration);
        // Klipper's `max_smoothed_v2`: the junction limit, and no more than the chain
        // of blocks before could reach accelerating at their smoothed rate.
        let reach = match (&self.prev, self.blocks.last()) {
            (Some(_), Some(p)) => p.max_smoothed_v2 + p.smooth_delta_v2,
            _ => 0.0,
        };
        (
            2.0 * distance * accel_to_decel,
            (vmax_junction * vmax_junction).at_most(reach),
        )
    }

    /// A dwell (`G4`) or any wait: every queued move completes first, then time passes.
    pub fn dwell(&mut self, secs: f64, sink: &mut impl FnMut(&PlannedMove)) {
        self.flush(sink);
        self.elapsed_s += secs.at_least(0.0);
    }

    /// Finalises every queued move (end of file, or a command that waits for motion to end).
    pub fn flush(&mut self, sink: &mut impl FnMut(&PlannedMove)) {
        self.plan_window(0, sink);
        self.prev = None;
    }

    /// Look-ahead over the window, then finalises all but `keep` blocks.
    fn plan_window(&mut self, keep: usize, sink: &mut impl FnMut(&PlannedMove)) {
        // A plain vector (the kept tail moves to the front after each window, a few kilobytes)
        // so the passes below run over one contiguous slice.
        let blocks = &mut self.blocks[..];
        let n = blocks.len();
        if n == 0 {
            return;
        }
        reverse_pass(blocks);
        forward_pass(blocks);
        set_exits(blocks);
        // The profiles first, in a loop of their own: they are independent of each other, and
        // their divisions overlap there instead of waiting, block by block, between sink calls.
        self.profiles.clear();
        let finalize = if self.model == JunctionModel::Klipper {
            self.klipper_profiles(keep)
        } else {
            let finalize = n.saturating_sub(keep);
            self.profiles.extend(
                self.blocks[..finalize]
                    .iter()
                    .map(|b| b.profile(b.entry, b.cruise, b.exit)),
            );
            finalize
        };
        for (b, &profile) in self.blocks.drain(..finalize).zip(&self.profiles) {
            let pm = PlannedMove {
                line: b.line,
                tag: b.tag,
                class: b.class,
                delta: b.delta,
                distance: b.distance,
                profile,
                start_s: self.elapsed_s,
            };
            self.elapsed_s += profile.duration();
            self.finalized += 1;
            sink(&pm);
        }
        // The machine is already committed to the last finalised block's exit speed: the next
        // block must start at exactly that speed, whatever later look-ahead would allow (as in
        // Marlin, where a block's entry is frozen once the block before it is executing).
        // Later moves only relax constraints, so it can still brake to what follows.
        if finalize > 0 {
            if let Some(first) = self.blocks.first_mut() {
                first.entry_fixed = true;
            }
        }
    }
}

/// The length of a move (along XYZ, or along E for an extrude-only move) and its class;
/// `None` for a move that goes nowhere.
#[inline]
fn distance_and_class(delta: &[f64; 4]) -> Option<(f64, MoveClass)> {
    let xyz = (delta[0] * delta[0] + delta[1] * delta[1] + delta[2] * delta[2]).sqrt();
    let (distance, class) = if xyz > 1e-9 {
        (
            xyz,
            if delta[3] > 1e-12 {
                MoveClass::Print
            } else {
                MoveClass::Travel
            },
        )
    } else {
        (delta[3].abs(), MoveClass::Retract)
    };
    (distance > 1e-12).then_some((distance, class))
}

/// Cruise speed of a move and the speed of each axis at it: the feed rate (at least the
/// minimum), then every axis within its limit.
#[inline]
fn cruise_speed(
    l: &Limits,
    class: MoveClass,
    feed: f64,
    delta: &[f64; 4],
    inv_distance: f64,
) -> (f64, [f64; 4]) {
    let min_feed = match class {
        MoveClass::Travel => l.min_travel_feedrate.value,
        _ => l.min_feedrate.value,
    };
    let mut cruise = feed
        .at_least(min_feed)
        .at_least(crate::machine::MIN_FEED_MM_S);
    let mut axis_feedrate = [0.0; 4];
    let mut factor: f64 = 1.0;
    for i in 0..4 {
        axis_feedrate[i] = cruise * delta[i] * inv_distance;
        let max = l.max_feedrate[i].value;
        if max > 0.0 && axis_feedrate[i].abs() > max {
            factor = factor.at_most(max / axis_feedrate[i].abs());
        }
    }
    // The floor holds after the limits too: an `M203 Y1e-322` would otherwise make a move last
    // for ever (the factor stays at most 1: the cruise is at least the floor).
    factor = factor.at_least(crate::machine::MIN_FEED_MM_S / cruise);
    cruise *= factor;
    for v in &mut axis_feedrate {
        *v *= factor;
    }
    (cruise, axis_feedrate)
}

/// Klipper's cruise speed, per-axis speeds, acceleration and the toolhead's acceleration of a
/// move (`toolhead.py` `Move`, then the kinematics' and the extruder's `check_move`):
/// `max_velocity` caps the speed along the path, not each axis; a move with Z is held to
/// `max_z_velocity` and `max_z_accel` along Z; a move that retracts, or extrudes without moving
/// X or Y (a wipe, an extrude-only move, a Z move with E), is also held to
/// `max_extrude_only_velocity` and `max_extrude_only_accel` along E. Extrude-only moves run at
/// their feed rate with only the extruder's limits.
#[inline]
fn klipper_speed_and_accel(
    l: &Limits,
    class: MoveClass,
    feed: f64,
    delta: &[f64; 4],
    distance: f64,
) -> (f64, [f64; 4], f64, f64) {
    let feed = feed
        .at_least(match class {
            MoveClass::Travel => l.min_travel_feedrate.value,
            _ => l.min_feedrate.value,
        })
        .at_least(crate::machine::MIN_FEED_MM_S);
    let positive = |v: f64| if v > 0.0 { v } else { f64::INFINITY };
    let (mut cruise, mut acceleration, toolhead_accel) = match class {
        MoveClass::Print => (feed, l.acceleration.value, l.acceleration.value),
        MoveClass::Travel => (
            feed,
            l.travel_acceleration.value,
            l.travel_acceleration.value,
        ),
        MoveClass::Retract => (feed, l.retract_acceleration.value, l.acceleration.value),
    };
    if class != MoveClass::Retract {
        // `max_velocity`, kept in the X and Y slots.
        cruise = cruise
            .at_most(positive(l.max_feedrate[0].value))
            .at_most(positive(l.max_feedrate[1].value));
    }
    let mut limit = |axis: usize, ratio: f64| {
        cruise = cruise.at_most(positive(l.max_feedrate[axis].value) * ratio);
        acceleration = acceleration.at_most(positive(l.max_acceleration[axis].value) * ratio);
    };
    if class != MoveClass::Retract && delta[2] != 0.0 {
        limit(2, distance / delta[2].abs());
    }
    let e = delta[3];
    let no_xy = class == MoveClass::Retract || (delta[0] == 0.0 && delta[1] == 0.0);
    if e != 0.0 && (no_xy || e < 0.0) {
        limit(3, distance / e.abs());
    }
    let acceleration = acceleration.at_least(1e-3);
    // As in `cruise_speed`: the feed floor holds after the limits too.
    let cruise = cruise.at_least(crate::machine::MIN_FEED_MM_S);
    let inv_distance = 1.0 / distance;
    let axis_feedrate = delta.map(|d| cruise * d * inv_distance);
    (
        cruise,
        axis_feedrate,
        acceleration,
        toolhead_accel.at_least(1e-3),
    )
}

/// Reverse pass of the look-ahead: every block must be able to brake to the next block's
/// entry speed.
fn reverse_pass(blocks: &mut [Block]) {
    let n = blocks.len();
    for i in (0..n - 1).rev() {
        let (head, tail) = blocks.split_at_mut(i + 1);
        let (b, next) = (&mut head[i], &tail[0]);
        if b.entry_fixed {
            continue;
        }
        if b.entry != b.max_entry || next.recalculate {
            // A block of nominal length reaches any junction speed within itself.
            let entry = if b.nominal_length {
                b.max_entry
            } else {
                b.max_entry.at_most(trapezoid::max_allowable_speed(
                    -b.acceleration,
                    next.entry,
                    b.distance,
                ))
            };
            if entry != b.entry {
                b.entry = entry;
                b.recalculate = true;
            }
        }
    }
}

/// Forward pass of the look-ahead: every block must be reachable from the previous block's
/// entry speed.
fn forward_pass(blocks: &mut [Block]) {
    for i in 1..blocks.len() {
        let (head, tail) = blocks.split_at_mut(i);
        let (p, b) = (&head[i - 1], &mut tail[0]);
        // Marlin and PrusaSlicer skip this check after a block of "nominal length", but they
        // set that flag from the block's safe speed, not the minimum planner speed, so the
        // shortcut can let a block start faster than the previous one can reach: a jump in
        // speed. Checking every block keeps the speed continuous (proptest in
        // tests/fuzz_regressions.rs); print times move by well under 0.1 %.
        if p.entry < b.entry {
            let entry = b.entry.at_most(trapezoid::max_allowable_speed(
                -p.acceleration,
                p.entry,
                p.distance,
            ));
            if entry != b.entry {
                b.entry = entry;
                b.recalculate = true;
            }
        }
    }
}

/// Exit speeds: each block exits at the next block's entry speed (the last one at its safe
/// speed until something follows it).
fn set_exits(blocks: &mut [Block]) {
    let n = blocks.len();
    for i in 0..n - 1 {
        let (head, tail) = blocks.split_at_mut(i + 1);
        let (b, next) = (&mut head[i], &tail[0]);
        if b.recalculate || next.recalculate {
            b.exit = next.entry;
            b.recalculate = false;
        }
    }
    if let Some(last) = blocks.last_mut() {
        last.exit = last.safe;
        last.recalculate = false;
    }
}

impl Planner {
    /// Klipper's look-ahead (`toolhead.py`, `LookAheadQueue.flush`) on top of the junction
    /// speeds of the passes above: a chain of blocks that speeds up and slows down again peaks
    /// no higher than if the whole chain accelerated and braked at `accel_to_decel` =
    /// accel (1 − minimum_cruise_ratio), so short zig-zags and finely cut curves do not reach
    /// full speed only to brake at once. Each block's cruise is capped by its chain's peak
    /// (and a braking block by the speeds it brakes through), and each junction by the
    /// cruise of both blocks.
    ///
    /// Blocks are final as Klipper's lazy flush makes them: up to the chain of the last peak
    /// but one (a later move can still raise what follows it). All but `keep` blocks would
    /// cut the smoothing of a chain of short pieces (an arc cut at 0.1 mm brakes over far
    /// more than the 64 blocks kept), and every block before a full flush (`keep` 0). A window
    /// without two peaks waits for more moves, up to [`KLIPPER_MAX_WINDOW`] blocks. Profiles of
    /// the blocks finalised go to `self.profiles`; returns how many.
    fn klipper_profiles(&mut self, keep: usize) -> usize {
        let blocks = &mut self.blocks[..];
        let caps = &mut self.cruise_v2;
        let n = blocks.len();
        let lazy = klipper_cruise_v2(blocks, self.limits.accel_to_decel.value > 0.0, caps);
        let finalize = match lazy {
            _ if keep == 0 => n,
            Some(count) => count,
            None if n > KLIPPER_MAX_WINDOW => n - keep,
            None => 0,
        };
        let cap = |i: usize| caps.get(i).copied().unwrap_or(f64::INFINITY).sqrt();
        // Speed at the start of block i: its junction, within the cruise of both blocks (the
        // first block keeps an entry the machine is already committed to).
        let junction = |blocks: &[Block], i: usize| match (i.checked_sub(1), blocks.get(i)) {
            (_, None) => 0.0,
            (None, Some(b)) if b.entry_fixed => b.entry,
            (None, Some(b)) => b.entry.at_most(cap(0)),
            (Some(p), Some(b)) => b.entry.at_most(cap(p)).at_most(cap(i)),
        };
        for i in 0..finalize {
            let entry = junction(blocks, i);
            let exit = if i + 1 < n {
                junction(blocks, i + 1)
            } else {
                blocks[i].exit.at_most(cap(i))
            };
            let cruise = cap(i)
                .at_most(blocks[i].cruise)
                .at_least(entry)
                .at_least(exit);
            self.profiles.push(blocks[i].profile(entry, cruise, exit));
        }
        // The first block left in the queue starts where the last finalised one ended.
        if finalize > 0 && finalize < n {
            let entry = junction(blocks, finalize);
            blocks[finalize].entry = entry;
        }
        finalize
    }
}

/// Klipper's cruise speed² of every block in the window (`LookAheadQueue.flush`), from the
/// junction speeds of the look-ahead passes: scanning back from the end, a block that can
/// speed up at the smoothed rate sets the peak of its chain, `(smoothed start² + smoothed
/// reach²) / 2`; the braking blocks after it are held to that peak and to the entry speeds
/// they brake through. Blocks still braking at the window's start (their peak is in an
/// earlier window) only brake.
fn klipper_cruise_v2(blocks: &[Block], legacy: bool, out: &mut Vec<f64>) -> Option<usize> {
    out.clear();
    out.resize(blocks.len(), f64::INFINITY);
    let last = blocks.last()?;
    // Klipper's lazy flush count: the blocks up to the chain of the last peak but one.
    let mut lazy = None;
    let mut peaks = 0;
    let sq = |v: f64| v * v;
    let mut next_smoothed_v2 = sq(last.exit);
    let mut peak_v2 = 0.0f64;
    // Braking blocks waiting for their chain's peak: i + 1 ..= end.
    let mut delayed_end: Option<usize> = None;
    let hold = |out: &mut Vec<f64>, from: usize, to: usize, mut cruise_v2: f64| {
        for k in from..=to {
            if let (Some(o), Some(b)) = (out.get_mut(k), blocks.get(k)) {
                cruise_v2 = cruise_v2.at_most(sq(b.entry));
                *o = cruise_v2;
            }
        }
    };
    for (i, b) in blocks.iter().enumerate().rev() {
        let reach_smoothed_v2 = next_smoothed_v2 + b.smooth_delta_v2;
        let smoothed_v2 = b.max_smoothed_v2.at_most(reach_smoothed_v2);
        if smoothed_v2 < reach_smoothed_v2 {
            if smoothed_v2 + b.smooth_delta_v2 > next_smoothed_v2 || delayed_end.is_some() {
                peaks += 1;
                if peaks == 2 {
                    lazy = Some(delayed_end.unwrap_or(i) + 1);
                }
                // Older Klipper caps a chain's peak by the cruise of the block that sets
                // it; current Klipper only each block's own cruise.
                peak_v2 = (smoothed_v2 + reach_smoothed_v2) * 0.5;
                if legacy {
                    peak_v2 = peak_v2.at_most(sq(b.cruise));
                }
            }
            let reach_v2 = sq(b.exit) + 2.0 * b.distance * b.acceleration;
            let cruise_v2 = ((sq(b.entry) + reach_v2) * 0.5)
                .at_most(sq(b.cruise))
                .at_most(peak_v2);
            if let Some(o) = out.get_mut(i) {
                *o = cruise_v2;
            }
            if let Some(end) = delayed_end.take() {
                // Older Klipper holds the braking blocks to the chain's peak; current Klipper
                // carries this block's own cruise forward to them.
                let held = if legacy { peak_v2 } else { cruise_v2 };
                hold(out, i + 1, end, held);
            }
        } else {
            delayed_end.get_or_insert(i);
        }
        next_smoothed_v2 = smoothed_v2;
    }
    if let Some(end) = delayed_end {
        hold(out, 0, end, f64::INFINITY);
    }
    lazy
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::error::Warnings;
    use crate::gcode::parse_line;
    use crate::machine::{Event, Machine};

    /// Test limits: 1000 mm/s and 1000 mm/s² on every move, jerk 10 mm/s.
    fn test_limits() -> Limits {
        let mut limits = MachineProfile::preset("prusa-mk3s").expect("preset").limits;
        limits.max_feedrate = [Limit::profile(1000.0); 4];
        limits.max_acceleration = [Limit::profile(100_000.0); 4];
        limits.acceleration = Limit::profile(1000.0);
        limits.travel_acceleration = Limit::profile(1000.0);
        limits.max_jerk = [Limit::profile(10.0); 4];
        limits
    }

    fn plan(src: &str, model: JunctionModel) -> Vec<PlannedMove> {
        plan_on(test_limits(), src, model)
    }

    fn plan_on(limits: Limits, src: &str, model: JunctionModel) -> Vec<PlannedMove> {
        let mut planner = Planner::new(limits, model);
        let mut machine = Machine::default();
        let mut w = Warnings::default();
        let mut out = Vec::new();
        for (i, l) in src.lines().enumerate() {
            if let Some(Event::Move(m)) =
                machine.apply(i as u32 + 1, &parse_line(l.as_bytes()).expect(l), &mut w)
            {
                planner.push(&Motion::from(&m), 0, &mut |p| out.push(*p));
            }
        }
        planner.flush(&mut |p| out.push(*p));
        out
    }

    /// Moves planned on the `voron-klipper` profile (per-axis limits 3000 mm/s² for X and Y,
    /// 350 for Z) after `M204 S20000`, with `model`: the accelerations used.
    fn accelerations_after_m204(model: JunctionModel) -> Vec<f64> {
        let limits = MachineProfile::preset("voron-klipper")
            .expect("preset")
            .limits;
        let mut planner = Planner::new(limits, model);
        let (mut machine, mut w, mut out) = (Machine::default(), Warnings::default(), Vec::new());
        let src = "M204 S20000\nG1 X100 Y50 F12000\nG1 Z10 F600\n";
        for (i, l) in src.lines().enumerate() {
            let line = parse_line(l.as_bytes()).expect(l);
            planner
                .limits_mut()
                .apply_command(&line, FeedUnits::PerMinute);
            if let Some(Event::Move(m)) = machine.apply(i as u32 + 1, &line, &mut w) {
                planner.push(&Motion::from(&m), 0, &mut |p| out.push(*p));
            }
        }
        planner.flush(&mut |p| out.push(*p));
        out.iter().map(|p| p.profile.acceleration).collect()
    }

    #[test]
    fn klipper_smooths_a_chain_of_moves_as_one_move() {
        // Klipper's minimum cruise ratio 0.5 (accel_to_decel = 500 mm/s² at 1000): a 20 mm
        // move from rest to rest peaks at v² = 20 mm × 500 mm/s² (100 mm/s): 5 mm speeding up,
        // 10 mm at 100 mm/s, 5 mm braking, 0.3 s. Cut into collinear pieces it is the same
        // chain and takes the same time; the pieces' own speeds used to peak at 141 mm/s.
        let limits = |ratio: f64| Limits {
            minimum_cruise_ratio: Limit::profile(ratio),
            ..test_limits()
        };
        let time_at = |ratio: f64, src: &str| -> f64 {
            plan_on(limits(ratio), src, JunctionModel::Klipper)
                .iter()
                .map(|p| p.profile.duration())
                .sum()
        };
        let time = |src: &str| time_at(0.5, src);
        let whole = time("G1 X20 F60000");
        let pieces = time("G1 X10 F60000\nG1 X20");
        let quarters = time("G1 X5 F60000\nG1 X10\nG1 X15\nG1 X20");
        for t in [whole, pieces, quarters] {
            assert!((t - 0.3).abs() < 1e-3, "{whole} {pieces} {quarters}");
        }
        // Older Klipper's absolute max_accel_to_decel of 500 mm/s² is the same chain.
        let rate = Limits {
            accel_to_decel: Limit::profile(500.0),
            ..limits(0.0)
        };
        let t: f64 = plan_on(rate, "G1 X10 F60000\nG1 X20", JunctionModel::Klipper)
            .iter()
            .map(|p| p.profile.duration())
            .sum();
        assert!((t - 0.3).abs() < 1e-3, "{t}");
        // Without either it is a triangle: 2 √(20 mm / 1000 mm/s²) = 0.283 s.
        let t = time_at(0.0, "G1 X10 F60000\nG1 X20");
        assert!((t - 2.0 * (0.02f64).sqrt()).abs() < 1e-3, "{t}");
        // Speeds stay continuous from piece to piece.
        let p = plan_on(
            limits(0.5),
            "G1 X5 F60000\nG1 X10\nG1 X15\nG1 X20",
            JunctionModel::Klipper,
        );
        for w in p.windows(2) {
            assert!(
                (w[0].profile.exit - w[1].profile.entry).abs() < 1e-9,
                "{p:?}"
            );
        }
        assert!(p.iter().all(|m| m.profile.peak <= 100.0 + 1e-3), "{p:?}");
    }

    #[test]
    fn klipper_caps_the_path_speed_and_holds_wipes_to_the_extruder_limits() {
        // Klipper's max_velocity is the speed along the path: a diagonal runs at 100 mm/s, not
        // at 100 mm/s on each axis (141 along it). A move retracting 1 mm over 1 mm (a wipe)
        // is held to the extrude-only 10 mm/s and 500 mm/s² along E, so along the path too.
        let cfg = "[printer]\nmax_velocity: 100\nmax_accel: 1000\n\
                   [extruder]\nmax_extrude_only_velocity: 10\nmax_extrude_only_accel: 500\n";
        let limits = KlipperConfig::parse_text(cfg)
            .expect("config")
            .limits(&test_limits(), KlipperVersion::Current);
        let src = "M83\nG1 X500 Y500 F60000\nG1 X501 E-1 F6000\nG1 X600 E5";
        let p = plan_on(limits, src, JunctionModel::Klipper);
        assert!(
            (p[0].profile.peak - 100.0).abs() < 1e-9,
            "{:?}",
            p[0].profile
        );
        assert!(p[1].profile.peak <= 10.0 + 1e-9, "{:?}", p[1].profile);
        assert_eq!(p[1].profile.acceleration, 500.0);
        // Printing moves keep the toolhead's acceleration, whatever the extruder's.
        assert_eq!(p[2].profile.acceleration, 1000.0);
    }

    #[test]
    fn klipper_accelerates_as_m204_says_whatever_the_per_axis_limits() {
        // Klipper: M204 sets the toolhead's max_accel; X and Y have no limit of their own, Z
        // keeps max_z_accel (350 mm/s² along Z: 350 along a pure Z move).
        let a = accelerations_after_m204(JunctionModel::Klipper);
        assert_eq!(a.len(), 2);
        assert!((a[0] - 20_000.0).abs() < 1e-6, "{a:?}");
        assert!((a[1] - 350.0).abs() < 1e-6, "{a:?}");
        // Marlin 2 caps each axis by M201 (here the profile's 3000 mm/s²): the X component of
        // the move, 100/111.8 of it, reaches 3000 first.
        let m = accelerations_after_m204(JunctionModel::JunctionDeviation);
        assert!(
            (m[0] - 3000.0 * 50f64.hypot(100.0) / 100.0).abs() < 1e-6,
            "{m:?}"
        );
    }

    #[test]
    fn a_lone_move_is_a_trapezoid_from_and_to_the_safe_speed() {
        // Classic jerk: a single X move starts and ends at the X jerk (10 mm/s).
        let p = plan("G1 X100 F3000", JunctionModel::ClassicJerk);
        assert_eq!(p.len(), 1);
        let pr = p[0].profile;
        assert!((pr.entry - 10.0).abs() < 1e-9 && (pr.exit - 10.0).abs() < 1e-9);
        assert!((pr.peak - 50.0).abs() < 1e-9);
        let ramp = (50.0f64 * 50.0 - 100.0) / 2000.0;
        let expected = 2.0 * (40.0 / 1000.0) + (100.0 - 2.0 * ramp) / 50.0;
        assert!(
            (p[0].duration() - expected).abs() < 1e-9,
            "{} vs {expected}",
            p[0].duration()
        );
    }

    #[test]
    fn a_square_slows_at_each_corner_by_the_model() {
        let src = "G1 X10 F6000\nG1 Y10\nG1 X0\nG1 Y0";
        for model in [
            JunctionModel::ClassicJerk,
            JunctionModel::JunctionDeviation,
            JunctionModel::Klipper,
        ] {
            let p = plan(src, model);
            assert_eq!(p.len(), 4);
            for w in p.windows(2) {
                assert!(
                    (w[0].profile.exit - w[1].profile.entry).abs() < 1e-9,
                    "{model:?}: speeds continuous"
                );
                assert!(
                    w[1].profile.entry < 20.0,
                    "{model:?}: corner at {}",
                    w[1].profile.entry
                );
            }
            let total: f64 = p.iter().map(PlannedMove::duration).sum();
            assert!(total > 40.0 / 100.0, "{model:?}: slower than nominal");
        }
    }

    #[test]
    fn a_slow_move_before_a_travel_runs_at_its_own_feed() {
        // 10 mm at 1.5 mm/s (below the 10 mm/s jerk), then a fast travel: the junction is the
        // travel's safe speed, 10 mm/s, but the slow move still takes 10 / 1.5 s, and the
        // travel starts at the junction speed.
        let src = "M83\nG1 X10 E1 F90\nG1 X60 F6000";
        let p = plan(src, JunctionModel::ClassicJerk);
        assert_eq!(p.len(), 2);
        let slow = &p[0];
        assert!(slow.profile.peak <= 1.5 + 1e-9, "{:?}", slow.profile);
        assert!(
            (slow.duration() - 10.0 / 1.5).abs() < 0.01,
            "{}",
            slow.duration()
        );
        assert!(p[1].profile.entry > 1.5, "{:?}", p[1].profile);
    }

    #[test]
    fn straight_collinear_segments_do_not_slow_down() {
        let src = "G1 X10 F6000\nG1 X20\nG1 X30\nG1 X40";
        let p = plan(src, JunctionModel::ClassicJerk);
        assert!(
            (p[1].profile.entry - 100.0).abs() < 1e-9 && (p[2].profile.entry - 100.0).abs() < 1e-9
        );
    }

    #[test]
    fn arcs_are_split_like_marlin_2() {
        // A full circle of radius 10 (62.83 mm). At 10 mm/s the 50-segments-per-second rule
        // gives 0.2 mm segments: 62.83 / 0.2 + 0.8 -> 314 segments.
        let p = plan(
            "G1 X10 Y0 F600\nG2 X10 Y0 I-10 J0",
            JunctionModel::JunctionDeviation,
        );
        assert_eq!(p.len(), 1 + 314);
        let len: f64 = p[1..].iter().map(|m| m.distance).sum();
        // Chords are a little shorter than the arc.
        assert!(len < 20.0 * std::f64::consts::PI && len > 0.999 * 20.0 * std::f64::consts::PI);
        // At 100 mm/s the chord-deviation rule wins: sqrt(8 r 0.02) = 1.265 mm, under the 2 mm cap.
        let seg = (8.0f64 * 10.0 * 0.02).sqrt();
        assert_eq!(
            arc_segments(10.0, 62.83, 100.0, 2.0),
            (62.83 / seg + 0.8) as usize
        );
        // The machine's maximum segment length caps it, 0.1 mm floors it.
        assert_eq!(arc_segments(1000.0, 100.0, 1000.0, 1.0), 100);
        assert_eq!(arc_segments(0.001, 1.0, 0.01, 1.0), 10);
    }

    #[test]
    fn arcs_are_split_like_upstream_marlin_2_1() {
        use std::f64::consts::{PI, TAU};
        // Marlin 2.1's plan_arc with its shipped defaults, worked by hand:
        // a 0.225 mm hairpin (half a circle, 0.707 mm): ⌈72 / 2⌉ = 36 segments of 0.02 mm are
        // under the 0.1 mm minimum, so ⌊0.707 / 0.1⌋ = 7.
        assert_eq!(marlin_arc_segments(0.225, 0.225 * PI, 1.0), 7);
        // A full circle of radius 10 (62.83 mm): max(⌊62.83⌋, 72) = 72 of 0.87 mm.
        assert_eq!(marlin_arc_segments(10.0, 10.0 * TAU, 1.0), 72);
        // A quarter of radius 100 (157.08 mm): ⌊157.08⌋ = 157 segments are 1.0005 mm, over the
        // maximum, so ⌈157.08⌉ = 158.
        assert_eq!(marlin_arc_segments(100.0, 50.0 * PI, 1.0), 158);
        // A tiny quarter (0.079 mm): one segment.
        assert_eq!(marlin_arc_segments(0.05, 0.025 * PI, 1.0), 1);
        // The planner cuts a file's arcs by the rule in its limits.
        let limits = Limits {
            arc_rule: ArcRule::CircleSegments,
            ..test_limits()
        };
        let p = plan_on(
            limits,
            "G1 X10 Y0 F600\nG2 X10 Y0 I-10 J0",
            JunctionModel::JunctionDeviation,
        );
        assert_eq!(p.len(), 1 + 72);
    }

    #[test]
    fn long_files_stream_with_bounded_memory() {
        let mut src = String::from("G1 F6000\n");
        for i in 0..5000 {
            src += &format!("G1 X{} Y{}\n", i % 7, i % 3);
        }
        let p = plan(&src, JunctionModel::ClassicJerk);
        assert!(p.len() > 4000);
        let mut t = 0.0;
        for m in &p {
            assert!((m.start_s - t).abs() < 1e-6);
            t += m.duration();
        }
    }
}
