//! The simulation fed its trajectory one segment at a time, in time order.
//!
//! [`super::simulate::run`] feeds it a list; [`super::timeline::of_file`], with [`Simulating`],
//! each move as the planner times it, so that a file's whole trajectory (190 MB for a 34 MB file)
//! is never held. A step is taken as soon as the segments known decide it: the command at a
//! time `t` depends only on the first segment ending after `t`, so every step before the end
//! of the last segment pushed can be taken. [`Stream::finish`] takes the rest.

use std::collections::VecDeque;

use super::axis::Axes;
use super::parameters::MachineDynamics;
use super::simulate::{
    budget, cancelled, peak_between, step_axes, steps_to_end, still, table_acceleration, too_long,
    Jumps, LayerSums, Outcome, SegmentSums, Settings,
};
use super::split::{Half, HalfRun};
use super::timeline::Emit;
use super::trajectory::{Bounds, Clock, Command, Segment};
use super::welch::Welch;
use crate::error::Error;
use crate::path::NO_LAYER;
use crate::plan::MachineProfile;
use crate::progress::Progress;

/// Most steps [`Stream::run_within`] takes at once.
const RUN: usize = 64;

/// The samples of a run of [`Stream::run_within`], kept with the stream so that a run does not
/// clear them first: the deviation (mm), X, Y (mm) and time of each step, and the table's
/// acceleration where the spectrum samples it.
struct RunBuffer {
    devs: [f64; RUN],
    ats: [[f64; 3]; RUN],
    sampled: [bool; RUN],
    accs: [[f64; 2]; RUN],
}

impl Default for RunBuffer {
    fn default() -> Self {
        RunBuffer {
            devs: [0.0; RUN],
            ats: [[0.0; 3]; RUN],
            sampled: [false; RUN],
            accs: [[0.0; 2]; RUN],
        }
    }
}

/// The shortest gap between two segments that is a rest rather than rounding, s
/// ([`Stream::on_grid`]).
const GAP_S: f64 = 1e-6;

/// Steps between two progress callbacks.
const PROGRESS_STEPS: u64 = 1 << 20;

/// Where a step falls: the layers of its segment (by marker, by counting) and whether it
/// extrudes.
#[derive(Clone, Copy)]
struct Here {
    layer: u32,
    counted: u32,
    extruding: bool,
}

/// A deviation sample (mm) of a move: at step `k`, X, Y (mm) and time (s), and where.
#[derive(Clone, Copy)]
struct Sample {
    dev: f64,
    k: u64,
    at: [f64; 3],
    here: Here,
}

/// The stretch of a timeline a run steps through ([`super::split`]): all of it, or one half.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(super) struct Steps {
    /// The step the run starts from, the machine at rest.
    pub from: u64,
    /// The step the run stops at, where it stops before the end.
    pub until: Option<u64>,
    /// Steps up to this one are taken but not counted (the second half's warm-up).
    pub counted_after: u64,
}

/// One run of both axes, fed its segments in time order.
pub struct Stream<'w> {
    axes: Axes,
    settings: Settings,
    /// The spectrum's estimator (`None`: a deviation-only run, which samples no acceleration:
    /// the deviation does not depend on the samples).
    welch: Option<&'w mut Welch>,
    out: Outcome,
    /// Per-layer sums by the layer each segment has by counting, where the file's layers are
    /// not yet known to come from its markers and their count is known only at the end (`None`:
    /// the segments' own layers are final, the sums' count fixed).
    counted: Option<Vec<LayerSums>>,
    /// The segments from the one before the cursor's on, each with its counted layer; `base`
    /// is the index of the first.
    window: VecDeque<(Segment, u32)>,
    base: usize,
    /// Segments pushed.
    pushed: usize,
    /// The cursor: the segment the last command fell in, or the next one.
    j: usize,
    /// Where the first segment starts.
    first_from: [f64; 2],
    /// End of the last segment pushed, s.
    end_s: f64,
    /// The last command.
    prev: Command,
    /// Table velocity (m/s) at the last acceleration sample, and steps since.
    last_v: [f64; 2],
    since: u64,
    /// Steps taken or skipped.
    k: u64,
    /// The jumps of the commanded velocity within the period being stepped.
    jumps: Jumps,
    /// The deviation of the step before the last and the last sample, where both were in
    /// moves: the crest between samples is found from three in a row ([`peak_between`]).
    before: Option<f64>,
    last: Option<Sample>,
    /// Motion time pushed, s (what the run costs: rests are skipped).
    motion_s: f64,
    /// The step budget of the most segments the run can have: an upper bound of the final one.
    most_steps: f64,
    /// Steps to the end when known up front (progress is reported only then).
    total: Option<u64>,
    next_progress: u64,
    /// The stretch stepped through, and whether `prev` is set for its first step.
    steps: Steps,
    primed: bool,
    buffer: Option<Box<RunBuffer>>,
    /// The last segment pushed, on the run's clock ([`Stream::on_grid`]), and its end on the
    /// timeline it came from.
    last_pushed: Option<Segment>,
    timeline_end_s: f64,
    /// Whether steps may be taken in runs ([`Stream::run_within`]); tests take them one by one
    /// too, to check that both give the same bits.
    runs: bool,
}

#[cfg(test)]
thread_local! {
    /// Streams made on this thread step one step at a time (no [`Stream::run_within`]).
    static STEPWISE: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
}

/// Whether streams take steps in runs: always, but in tests that ask otherwise.
fn in_runs() -> bool {
    #[cfg(test)]
    return !STEPWISE.with(|s| s.get());
    #[cfg(not(test))]
    true
}

impl<'w> Stream<'w> {
    /// A run of `machine` at `settings` with at most `max_segments` segments. `layers`: the
    /// per-layer sums' count, or `None` to grow them to the layers met and keep sums by counted
    /// layer too (see [`Stream::finish_layers`]). `total`: the steps to the end, when known.
    pub fn new(
        machine: &MachineDynamics,
        settings: Settings,
        welch: Option<&'w mut Welch>,
        (layers, max_segments, total): (Option<usize>, usize, Option<u64>),
    ) -> Self {
        let ts = settings.ts;
        Stream {
            axes: Axes::new([machine.x, machine.y], ts, settings.bucket_m),
            settings,
            welch,
            out: Outcome::new(layers.unwrap_or(0)),
            counted: layers.is_none().then(Vec::new),
            window: VecDeque::new(),
            base: 0,
            pushed: 0,
            j: 0,
            first_from: [0.0; 2],
            end_s: 0.0,
            prev: Command::default(),
            last_v: [0.0; 2],
            since: 0,
            k: 0,
            jumps: Jumps::default(),
            before: None,
            last: None,
            motion_s: 0.0,
            most_steps: budget(max_segments),
            total,
            next_progress: PROGRESS_STEPS,
            steps: Steps::default(),
            primed: true,
            buffer: Some(Box::default()),
            last_pushed: None,
            timeline_end_s: 0.0,
            runs: in_runs(),
        }
    }

    /// The run stepping through `steps` only (a half of a split run, [`super::split`]).
    pub(super) fn stepping(mut self, steps: Steps) -> Self {
        self.k = steps.from;
        self.primed = steps.from == 0;
        self.steps = steps;
        self
    }

    /// Whether the run has reached the step it stops at.
    fn stopped(&self) -> bool {
        self.steps.until.is_some_and(|u| self.k >= u)
    }

    /// The next segment on the timeline (`counted`: its layer by counting), and every step its
    /// end decides.
    pub fn push(
        &mut self,
        seg: Segment,
        counted: u32,
        progress: Progress<'_>,
    ) -> Result<(), Error> {
        let seg = self.on_grid(seg);
        self.motion_s += seg.duration_s;
        // Motion beyond the largest budget the run can have: refused now, as the whole list's
        // run would refuse it before its first step.
        if self.motion_s / self.settings.ts > self.most_steps {
            return Err(too_long());
        }
        if self.pushed == 0 {
            self.first_from = seg.from;
        }
        self.end_s = seg.end_s();
        if self.stopped() {
            // A first half done: the rest counts toward the budget only.
            self.pushed += 1;
            return Ok(());
        }
        self.make_room(seg.layer, counted);
        self.window.push_back((seg, counted));
        self.pushed += 1;
        if self.pushed == 1 && self.primed {
            self.prev = self.at(0).0;
        }
        if !self.primed {
            self.drop_before_start();
        }
        self.advance(None, self.end_s, progress)
    }

    /// `seg` on the run's clock. Where the table is at rest as it starts (after a dwell or a
    /// retract, at a lift, from a full stop), it sets off on the next whole step, and
    /// the segments after it until the next rest are timed from that step by their own
    /// durations ([`Clock`]). The same moves after a rest are then sampled at the same instants
    /// of their motion, to the bit, wherever they fall in the print: a layer a rewrite keeps
    /// as it was rings as it did in the original once the ringing carried into it has died
    /// away, where before it rang a few tens of nanometres higher or lower as the 1 ms
    /// samples happened to fall (which decided the closed loop's peak by chance). Physically
    /// the hold is a rest under one step longer, through which the free response goes on.
    fn on_grid(&mut self, mut seg: Segment) -> Segment {
        let ts = self.settings.ts;
        // Zero where the timeline put the segment straight after the last one: a gap under
        // a microsecond is the planner's absolute clock rounding (at 25 000 s, a few ps), not
        // a rest, and would move every sample after it by as much.
        let gap = seg.start_s - self.timeline_end_s;
        let gap = if gap > GAP_S { gap } else { 0.0 };
        self.timeline_end_s = seg.end_s();
        let (last_clock, last_duration_s, last_exit) = match self.last_pushed {
            Some(l) => (l.clock, l.duration_s, l.command(l.duration_s).vel),
            None => (Clock::default(), 0.0, [0.0; 2]),
        };
        let previous_end =
            last_clock.from_step as f64 * ts + (last_clock.after_s + last_duration_s);
        let rest_step = (previous_end + gap) / ts;
        // At rest between the two: a dwell or a move the timeline does not hold (a gap), a
        // full stop, or a segment that starts still (a lift; from zero speed).
        let at_rest = gap > 0.0 || last_exit == [0.0; 2] || seg.command(0.0).vel == [0.0; 2];
        let clock = if at_rest && rest_step.is_finite() && rest_step < 1e15 {
            Clock {
                from_step: rest_step.ceil().max(0.0) as u64,
                after_s: 0.0,
            }
        } else {
            Clock {
                after_s: last_clock.after_s + last_duration_s + gap,
                ..last_clock
            }
        };
        seg.start_s = clock.from_step as f64 * ts + clock.after_s;
        seg.clock = clock;
        self.last_pushed = Some(seg);
        seg
    }

    /// The run's outcome once every segment is pushed: the checks a whole list's run makes
    /// first, then the steps to the end.
    pub fn finish(
        mut self,
        progress: Progress<'_>,
    ) -> Result<(Outcome, Option<Vec<LayerSums>>), Error> {
        let ts = self.settings.ts;
        // A first half that stopped has read only part of the file: the second half, which
        // reads it all, checks the whole run's budget.
        if !self.stopped() {
            let (total, budget) = steps_to_end(self.motion_s, self.pushed, self.end_s, ts)?;
            self.most_steps = budget;
            self.advance(Some(total), f64::INFINITY, progress)?;
        }
        self.out.simulated_s = self.out.steps as f64 * ts;
        Ok((self.out, self.counted))
    }

    /// The segment of index `i`, if in the window.
    fn get(&self, i: usize) -> Option<&(Segment, u32)> {
        i.checked_sub(self.base).and_then(|w| self.window.get(w))
    }

    /// Command at step `k` (non-decreasing between calls) and what the segment it is in says
    /// of where it is.
    #[inline]
    fn at(&mut self, k: u64) -> (Command, Option<Here>) {
        self.seek(k as f64 * self.settings.ts);
        self.trim();
        self.command_at(k)
    }

    /// The cursor moved to the segment `t` falls in, or the next one.
    #[inline]
    fn seek(&mut self, t: f64) {
        while self.j < self.pushed && self.get(self.j).is_some_and(|s| s.0.end_s() <= t) {
            self.j += 1;
        }
    }

    /// Only the segment before the cursor's is needed again: the ones before it dropped.
    #[inline]
    fn trim(&mut self) {
        while self.base + 1 < self.j {
            self.window.pop_front();
            self.base += 1;
        }
    }

    /// The command at step `k`, the cursor at its time ([`Stream::seek`]).
    #[inline]
    fn command_at(&self, k: u64) -> (Command, Option<Here>) {
        let t = k as f64 * self.settings.ts;
        match self.get(self.j) {
            Some((s, counted)) if t >= s.start_s => {
                let here = Here {
                    layer: s.layer,
                    counted: *counted,
                    extruding: s.extruding,
                };
                (s.command(s.clock.tau(k, self.settings.ts)), Some(here))
            }
            _ => {
                let pos = match self.j.checked_sub(1).and_then(|i| self.get(i)) {
                    Some((prev, _)) => prev.to,
                    None => self.first_from,
                };
                (Command { pos, vel: [0.0; 2] }, None)
            }
        }
    }

    /// The command at step `k1`, and the jumps of the commanded velocity in the period before
    /// it: where a segment starts, from the velocity the one before it ended at (a
    /// rest between two moves is reached and left smoothly: the planner stops before it).
    /// Most periods have none: the cursor stays in a segment that started before `t0`.
    #[inline]
    fn step_to(&mut self, k1: u64) -> (Command, Option<Here>) {
        let ts = self.settings.ts;
        let (t0, t1) = (k1.saturating_sub(1) as f64 * ts, k1 as f64 * ts);
        let from = self.j;
        self.seek(t1);
        self.jumps.clear();
        let starts_within = |s: &(Segment, u32)| s.0.start_s > t0;
        if self.j != from || self.get(from).is_some_and(starts_within) {
            for i in from..=self.j {
                let Some((s, _)) = self.get(i).filter(|s| starts_within(s)) else {
                    continue;
                };
                if s.start_s > t1 {
                    break;
                }
                let after = s.command(0.0).vel;
                let before = match i.checked_sub(1).and_then(|p| self.get(p)) {
                    Some((p, _)) => p.command(p.duration_s).vel,
                    None => [0.0; 2],
                };
                let dv = [after[0] - before[0], after[1] - before[1]];
                self.jumps.push(s.clock.tau(k1, ts) / ts, dv);
            }
        }
        self.trim();
        self.command_at(k1)
    }

    /// Steps while `k < total` (when given) and their time is before `horizon`.
    fn advance(
        &mut self,
        total: Option<u64>,
        horizon: f64,
        progress: Progress<'_>,
    ) -> Result<(), Error> {
        let ts = self.settings.ts;
        while total.is_none_or(|n| self.k < n) && !self.stopped() {
            let t1 = (self.k + 1) as f64 * ts;
            if t1 >= horizon {
                break;
            }
            if !self.primed {
                // A half started later: the command its first step starts from, now that the
                // segments around it are known.
                self.prev = self.at(self.k).0;
                self.primed = true;
            }
            if !self.run_within(total, horizon) {
                let (next, here) = self.step_to(self.k + 1);
                if !self.step(next, here, t1)? {
                    break;
                }
            }
            if self.out.steps as f64 > 2.0 * self.most_steps {
                // Rests that never settle (an undamped mode excited): still bounded.
                return Err(too_long());
            }
            if let Some(n) = self.total.filter(|_| self.k >= self.next_progress) {
                self.next_progress = self.k + PROGRESS_STEPS;
                if !progress(self.k as f64 / n.max(1) as f64) {
                    return Err(cancelled());
                }
            }
        }
        Ok(())
    }

    /// Up to [`RUN`] steps inside the cursor's segment at once, where nothing but the step
    /// changes between them: no segment starts or ends within them, both axes step as one modal
    /// pair in the buckets they are in ([`PairRun`]), and whether they are counted stays the
    /// same. The steps are taken first and their samples recorded after, each accumulator
    /// seeing the same samples in the same order as [`Stream::step`] would give them: the same
    /// bits, the stepping a loop of its own whose state stays in registers. `false` where no
    /// step could be taken so.
    #[inline]
    fn run_within(&mut self, total: Option<u64>, horizon: f64) -> bool {
        if !self.runs {
            return false;
        }
        let ts = self.settings.ts;
        let Some(&(seg, counted)) = self.get(self.j) else {
            return false;
        };
        if seg.start_s > self.k as f64 * ts {
            return false;
        }
        let counting = self.k >= self.steps.counted_after;
        let mut last = total
            .unwrap_or(u64::MAX)
            .min(self.steps.until.unwrap_or(u64::MAX));
        if !counting {
            last = last.min(self.steps.counted_after);
        }
        let Some(mut run) = self.axes.pair_run() else {
            return false;
        };
        let end = seg.end_s();
        let k0 = self.k;
        // Taken out while the run records its samples, which borrows the stream.
        let mut buffer = self.buffer.take().unwrap_or_default();
        let RunBuffer {
            devs,
            ats,
            sampled,
            accs,
        } = &mut *buffer;
        let (mut since, mut last_v) = (self.since, self.last_v);
        let decimation = (self.welch.is_some() && counting).then_some(self.settings.decimation);
        let mut n = 0;
        let mut prev = self.prev;
        while n < RUN && k0 + (n as u64) < last {
            let k1 = k0 + n as u64 + 1;
            // Signed: the same value, converted in one instruction ([`Clock::tau`]).
            let t1 = (k1 as i64) as f64 * ts;
            if !(t1 < end && t1 < horizon && run.in_buckets(prev.pos.map(|p| p * 1e-3))) {
                break;
            }
            let next = seg.command(seg.clock.tau(k1, ts));
            let v0 = prev.vel.map(|v| v * 1e-3);
            let change: [f64; 2] = core::array::from_fn(|ax| next.vel[ax] - prev.vel[ax]);
            run.step(v0, change.map(|c| c * 1e-3 / ts));
            let [dx, dy] = run.table();
            // Squared here, the root taken for the whole run after it ([`Stream::record_run`]).
            devs[n] = dx * dx + dy * dy;
            ats[n] = [next.pos[0], next.pos[1], t1];
            since += 1;
            if decimation.is_some_and(|d| since >= d) {
                let dt = since as f64 * ts;
                let table = run.table_velocity();
                accs[n] = table_acceleration(&next, table, &mut last_v, dt);
                sampled[n] = true;
                since = 0;
            } else {
                sampled[n] = false;
            }
            prev = next;
            n += 1;
        }
        self.axes.end_run(run.done());
        if n > 0 {
            for d in &mut buffer.devs[..n] {
                *d = d.sqrt() * 1e3;
            }
            self.record_run(n, &buffer, (prev, since, last_v), (seg, counted, counting));
        }
        self.buffer = Some(buffer);
        n > 0
    }

    /// The `n` steps [`Stream::run_within`] took in segment `seg` (`counted`: its layer by
    /// counting), their samples in `buffer`, recorded; `prev`, `since` and `last_v` as the
    /// last step left them.
    #[inline]
    fn record_run(
        &mut self,
        n: usize,
        buffer: &RunBuffer,
        (prev, since, last_v): (Command, u64, [f64; 2]),
        (seg, counted, counting): (Segment, u32, bool),
    ) {
        let RunBuffer {
            devs,
            ats,
            sampled,
            accs,
        } = buffer;
        let k0 = self.k;
        (self.k, self.prev, self.since, self.last_v) = (k0 + n as u64, prev, since, last_v);
        self.out.steps += if counting { n as u64 } else { 0 };
        let here = Here {
            layer: seg.layer,
            counted,
            extruding: seg.extruding,
        };
        let sample = |i: usize| Sample {
            dev: devs[i],
            k: k0 + 1 + i as u64,
            at: ats[i],
            here,
        };
        // The first two samples' crests look back at samples before the run.
        let head = n.min(2);
        for i in 0..head {
            if counting {
                self.sums(here).add(devs[i], ats[i]);
            }
            self.crest(Some(sample(i)));
            if sampled[i] {
                self.sample_acceleration(&accs[i], here.layer, counted);
            }
        }
        if n > head {
            self.record_rest(head..n, (devs, ats), (sampled, accs), (here, k0, counting));
            (self.before, self.last) = (Some(devs[n - 2]), Some(sample(n - 1)));
        }
    }

    /// The accumulators of the samples of a segment `here`.
    #[inline]
    fn sums(&mut self, here: Here) -> SegmentSums<'_> {
        let counted = (self.counted.as_mut()).and_then(|c| c.get_mut(here.counted as usize));
        self.out.segment_sums(here.layer, here.extruding, counted)
    }

    /// Samples `range` (from the third on) of a run of [`Stream::run_within`], with their
    /// crests (the sample before each, between its neighbours: [`Stream::crest`]) and
    /// acceleration samples, each as [`Stream::step`] records it.
    #[inline]
    fn record_rest(
        &mut self,
        range: std::ops::Range<usize>,
        (devs, ats): (&[f64; RUN], &[[f64; 3]; RUN]),
        (sampled, accs): (&[bool; RUN], &[[f64; 2]; RUN]),
        (here, k0, counting): (Here, u64, bool),
    ) {
        let counted_after = self.steps.counted_after.max(1);
        let crest_counts = |i: usize| k0 + i as u64 >= counted_after;
        (self.sums(here)).record((devs, ats), range.clone(), counting, crest_counts);
        // The spectrum's and the layers' acceleration sums are apart from the deviation's.
        for i in range.filter(|&i| sampled[i]) {
            self.sample_acceleration(&accs[i], here.layer, here.counted);
        }
    }

    /// An acceleration sample `acc` of the table (X, Y, m/s²) in the layers `layer` (by
    /// marker) and `counted`, into the spectrum and the layers' sums.
    #[inline]
    fn sample_acceleration(&mut self, acc: &[f64; 2], layer: u32, counted: u32) {
        if let Some(welch) = self.welch.as_deref_mut() {
            welch.push(acc);
        }
        self.out.add_acceleration(acc, layer);
        if let Some(l) = self
            .counted
            .as_mut()
            .and_then(|c| c.get_mut(counted as usize))
        {
            l.add_acceleration(acc);
        }
    }

    /// One step to the command `next` at `t1`, in segment `seg`; `false` where the machine is
    /// at rest and still with no segment to come.
    #[inline]
    fn step(&mut self, next: Command, here: Option<Here>, t1: f64) -> Result<bool, Error> {
        let ts = self.settings.ts;
        step_axes(&mut self.axes, &self.prev, &next, &self.jumps, ts)?;
        self.k += 1;
        // A warm-up step is taken, not counted.
        let counting = self.k > self.steps.counted_after;
        self.out.steps += u64::from(counting);
        let (layer, counted) = here.map_or((NO_LAYER, NO_LAYER), |h| (h.layer, h.counted));
        let sample = here.map(|here| {
            let [dx, dy] = self.axes.table();
            let dev = (dx * dx + dy * dy).sqrt() * 1e3;
            let at = [next.pos[0], next.pos[1], t1];
            Sample {
                dev,
                k: self.k,
                at,
                here,
            }
        });
        if let Some(s) = sample.filter(|_| counting) {
            self.sums(s.here).add(s.dev, s.at);
        }
        self.crest(sample);
        self.since += 1;
        let sampling = self
            .welch
            .as_deref_mut()
            .filter(|_| counting && self.since >= self.settings.decimation);
        if sampling.is_some() {
            let dt = self.since as f64 * ts;
            let table = self.axes.table_velocity();
            let acc = table_acceleration(&next, table, &mut self.last_v, dt);
            self.sample_acceleration(&acc, layer, counted);
            self.since = 0;
        }
        let mut jumped = false;
        if here.is_none() && (0..2).all(|l| still(&self.axes.state(l))) {
            // At rest and still: jump to the next move (nothing changes meanwhile).
            let Some(s) = self.get(self.j).map(|s| s.0) else {
                return Ok(false);
            };
            let resume = ((s.start_s / ts).floor() as u64).saturating_sub(1);
            // A first half stops at its last step, at rest.
            let resume = self.steps.until.map_or(resume, |u| resume.min(u));
            if resume > self.k {
                self.k = resume;
                self.axes.rest();
                self.last_v = [0.0; 2];
                self.since = 0;
                (self.before, self.last) = (None, None);
                jumped = true;
            }
        }
        self.prev = if jumped { self.at(self.k).0 } else { next };
        Ok(true)
    }

    /// The sample before `next` raised to the crest between its neighbours where it is a local
    /// maximum of three in a row ([`peak_between`]). The step a second half starts counting
    /// after is the first half's last, which has no step after it there: its crest is found
    /// here, from the warm-up's samples, and merged as the larger peak.
    #[inline]
    fn crest(&mut self, next: Option<Sample>) {
        if let (Some(y0), Some(mid), Some(y2)) = (self.before, self.last, next.map(|s| s.dev)) {
            let counted_here = mid.k >= self.steps.counted_after.max(1);
            if mid.dev >= y0 && mid.dev > y2 && counted_here {
                let peak = peak_between(y0, mid.dev, y2);
                self.sums(mid.here).raise(peak, mid.at);
            }
        }
        self.before = self.last.map(|s| s.dev);
        self.last = next;
    }

    /// A half started later holds, of the segments before its first step, only the last (as
    /// [`Stream::at`] keeps the one before the cursor's): the rest of them would be all the
    /// segments of the file before it, held for nothing.
    fn drop_before_start(&mut self) {
        let start = self.k as f64 * self.settings.ts;
        while self.window.len() > 1 && self.window[1].0.end_s() <= start {
            self.window.pop_front();
            self.base += 1;
        }
        self.j = self.j.max(self.base);
    }

    /// Per-layer sums up to `layer` (and `counted`) where they grow to the layers met: made
    /// as each segment comes, so that the steps find them.
    fn make_room(&mut self, layer: u32, counted: u32) {
        if self.counted.is_none() {
            return;
        }
        let need = |l: u32| if l == NO_LAYER { 0 } else { l as usize + 1 };
        if self.out.layers.len() < need(layer) {
            self.out.layers.resize(need(layer), LayerSums::default());
        }
        if let Some(c) = self.counted.as_mut().filter(|c| c.len() < need(counted)) {
            c.resize(need(counted), LayerSums::default());
        }
    }
}

/// The per-layer sums of a streamed run, `layers` of them, by marker (`by_markers`: the
/// outcome's own) or by counting.
pub(super) fn finish_layers(
    out: &mut Outcome,
    counted: Option<Vec<LayerSums>>,
    layers: usize,
    by_markers: bool,
) {
    if let Some(c) = counted.filter(|_| !by_markers) {
        out.layers = c;
    }
    out.layers.resize(layers, LayerSums::default());
}

/// The [`Emit`] that runs a simulation on a file's segments as the planner times them
/// ([`super::timeline::of_file`]): the machine's dynamics are known from the file's machine,
/// before its first move. Progress runs with the segments read (of about `expected`).
pub(super) struct Simulating<'w, 'p, F> {
    dynamics_for: Option<F>,
    settings: Settings,
    welch: Option<&'w mut Welch>,
    stream: Option<Stream<'w>>,
    machine: Option<MachineDynamics>,
    max_segments: usize,
    expected: usize,
    pushed: usize,
    bounds: Bounds,
    error: Option<Error>,
    progress: Progress<'p>,
    /// The half of a split run this is ([`super::split`]), and the stretch it steps through
    /// once the machine is known (`None`: a second half the run is not split for).
    half: Option<Half>,
    steps: Option<Steps>,
}

impl<'w, 'p, F: FnOnce(&str) -> Result<MachineDynamics, Error>> Simulating<'w, 'p, F> {
    /// A simulation at `settings` into `welch` of `input`, its machine's dynamics from
    /// `dynamics_for` (given the machine preset's name).
    pub(super) fn new(
        dynamics_for: F,
        (settings, welch): (Settings, Option<&'w mut Welch>),
        input: &[u8],
        progress: Progress<'p>,
    ) -> Self {
        // A move per line at most.
        let max_segments = memchr::memchr_iter(b'\n', input).count() + 1;
        Simulating {
            dynamics_for: Some(dynamics_for),
            settings,
            welch,
            stream: None,
            machine: None,
            max_segments,
            expected: crate::gcode::command_lines(input).max(1),
            pushed: 0,
            bounds: Bounds::default(),
            error: None,
            progress,
            half: None,
            steps: Some(Steps::default()),
        }
    }

    /// The run as `half` of a split one.
    pub(super) fn half(mut self, half: Half) -> Self {
        self.half = Some(half);
        self
    }

    /// A half's outcome and sums by counted layer (`None`: a second half the run was not
    /// split for), and whether the run was split.
    pub(super) fn finish_half(self) -> Result<(HalfRun, bool), Error> {
        let Checked {
            stream,
            progress,
            steps,
            ..
        } = self.checked()?;
        let split = steps.is_some_and(|s| s != Steps::default());
        match stream {
            Some(stream) => Ok((Some(stream.finish(progress)?), split)),
            None => Ok((None, split)),
        }
    }

    /// The run's parts once it is known to have gone through ([`Checked`]); the walk's error,
    /// or `Cancelled` where the walk stopped before it learnt the machine.
    fn checked(self) -> Result<Checked<'w, 'p>, Error> {
        if let Some(e) = self.error {
            return Err(e);
        }
        // `path::walk` tells the machine before the first move: none only where the walk
        // stopped before reading.
        let machine = self.machine.ok_or_else(cancelled)?;
        Ok(Checked {
            stream: self.stream,
            machine,
            bounds: self.bounds,
            progress: self.progress,
            steps: self.steps,
        })
    }

    /// The run's outcome (its per-layer sums, `layers` of them, by marker where `by_markers`),
    /// the trajectory's bounds and the machine's dynamics.
    pub(super) fn finish(
        self,
        layers: usize,
        by_markers: bool,
    ) -> Result<(Outcome, Bounds, MachineDynamics), Error> {
        let Checked {
            stream,
            machine,
            bounds,
            progress,
            ..
        } = self.checked()?;
        let stream = stream.ok_or_else(cancelled)?;
        // Read to the end: the rest is a few steps.
        if !progress(0.95) {
            return Err(cancelled());
        }
        let (mut out, counted) = stream.finish(progress)?;
        finish_layers(&mut out, counted, layers, by_markers);
        Ok((out, bounds, machine))
    }
}

/// A run that went through, taken apart to finish: its stream (`None`: a second half the run
/// was not split for), machine, bounds, progress and steps.
struct Checked<'w, 'p> {
    stream: Option<Stream<'w>>,
    machine: MachineDynamics,
    bounds: Bounds,
    progress: Progress<'p>,
    steps: Option<Steps>,
}

impl<F: FnOnce(&str) -> Result<MachineDynamics, Error>> Emit for Simulating<'_, '_, F> {
    fn emit(&mut self, seg: Segment, counted: u32) {
        let Some(stream) = self.stream.as_mut().filter(|_| self.error.is_none()) else {
            return;
        };
        self.bounds.add(&seg);
        if let Err(e) = stream.push(seg, counted, &mut |_| true) {
            self.error = Some(e);
        }
        self.pushed += 1;
        if self.pushed % 4096 == 0 {
            let done = self.pushed as f64 / self.expected as f64;
            if !(self.progress)(0.95 * done.min(1.0)) {
                self.error = Some(cancelled());
            }
        }
    }

    fn finished(&self) -> bool {
        match &self.stream {
            Some(stream) => stream.stopped(),
            // A second half the run is not split for: nothing to read.
            None => self.machine.is_some(),
        }
    }

    fn machine(&mut self, profile: &MachineProfile) {
        let Some(dynamics_for) = self.dynamics_for.take() else {
            return;
        };
        let welch = self.welch.take();
        match dynamics_for(&profile.name) {
            Ok(machine) => {
                let sizes = (None, self.max_segments, None);
                self.steps = self.half.map_or(Some(Steps::default()), |h| {
                    h.steps(&machine, self.settings.ts)
                });
                self.stream = self
                    .steps
                    .map(|st| Stream::new(&machine, self.settings, welch, sizes).stepping(st));
                self.machine = Some(machine);
            }
            Err(e) => self.error = Some(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::trajectory;

    /// Three layers of lines and arcs, travels between, a dwell and a stop.
    const PART: &[u8] = b"G21\nG90\nM83\n;LAYER_CHANGE\n;Z:0.2\nG1 Z0.2 F600\nG1 X30 Y30 F6000\n\
G1 X60 Y30 E1 F2400\nG2 X70 Y40 I0 J10 E0.5\nG1 X70 Y70 E1\nG3 X40 Y70 I-15 J0 E1\n\
G1 X30 Y31 E1\nG1 X31 Y30 E0.1\n;LAYER_CHANGE\n;Z:0.4\nG1 Z0.4\nG4 P1500\n\
G1 X120 Y100 F9000\nG1 X140 Y100 E1 F1800\nG1 X140 Y101 E0.1\nG1 X120 Y101 E1\n\
G2 X120 Y121 I0 J10 E1.5\n;LAYER_CHANGE\n;Z:0.6\nG1 Z0.6\nG1 X10 Y10 F9000\n\
G1 X200 Y12 E9 F4800\nG1 X200 Y40 E1\nG1 X10 Y40 E9\n";

    /// `segs` simulated through `steps`, one step at a time or in runs, with a spectrum.
    fn simulated(segs: &[Segment], steps: Steps, stepwise: bool) -> (Outcome, Vec<f64>) {
        STEPWISE.with(|s| s.set(stepwise));
        let machine = MachineDynamics::preset("desktop-belt").unwrap();
        let settings = Settings {
            ts: 1e-3,
            decimation: 5,
            bucket_m: 5e-3,
        };
        let mut welch = Welch::new(64, 200.0, crate::dynamics::Window::Hamming, 2);
        let layers = (segs.iter().filter(|s| s.layer != NO_LAYER)).map(|s| s.layer as usize + 1);
        let sizes = (Some(layers.max().unwrap_or(0)), segs.len(), None);
        let mut stream = Stream::new(&machine, settings, Some(&mut welch), sizes).stepping(steps);
        for s in segs {
            stream.push(*s, s.layer, &mut |_| true).unwrap();
        }
        let (out, _) = stream.finish(&mut |_| true).unwrap();
        STEPWISE.with(|s| s.set(false));
        (out, welch.finish().power)
    }

    /// Both ways of stepping through `steps` of `segs` give the same outcome and spectrum.
    fn same_both_ways(segs: &[Segment], steps: Steps) {
        let (runs, runs_psd) = simulated(segs, steps, false);
        let (one_by_one, psd) = simulated(segs, steps, true);
        assert!(
            runs.deviation.count > 1000,
            "{steps:?}: {:?}",
            runs.deviation
        );
        assert_eq!(runs.deviation, one_by_one.deviation, "{steps:?}");
        assert_eq!(runs.printing, one_by_one.printing, "{steps:?}");
        assert_eq!(runs.max_at, one_by_one.max_at, "{steps:?}");
        assert_eq!(
            runs.printing_max_at, one_by_one.printing_max_at,
            "{steps:?}"
        );
        assert_eq!(runs.layers, one_by_one.layers, "{steps:?}");
        assert_eq!(runs.steps, one_by_one.steps, "{steps:?}");
        assert_eq!(runs_psd, psd, "{steps:?}");
    }

    #[test]
    fn steps_taken_in_runs_give_the_bits_of_steps_taken_one_by_one() {
        // The playground's demo: a PrusaSlicer part of 20 minutes.
        let demo = include_bytes!("../../../www/demo/demo.gcode");
        let path = crate::path::extract(demo, &Default::default(), true).unwrap();
        same_both_ways(&trajectory::segments(&path).unwrap(), Steps::default());
        let path = crate::path::extract(PART, &Default::default(), true).unwrap();
        let segs = trajectory::segments(&path).unwrap();
        let end = segs.last().unwrap().end_s();
        let at = |share: f64| (end * share / 1e-3) as u64;
        let stretches = [
            Steps::default(),
            // A first half, and a second one warmed up over a layer before it counts.
            Steps {
                until: Some(at(0.6)),
                ..Steps::default()
            },
            Steps {
                from: at(0.2),
                until: None,
                counted_after: at(0.6),
            },
        ];
        for steps in stretches {
            same_both_ways(&segs, steps);
        }
    }
}
