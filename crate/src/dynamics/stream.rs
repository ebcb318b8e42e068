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
    Jumps, LayerSums, Outcome, Settings,
};
use super::split::{Half, HalfRun};
use super::timeline::Emit;
use super::trajectory::{Bounds, Command, Segment};
use super::welch::Welch;
use crate::error::Error;
use crate::path::NO_LAYER;
use crate::plan::MachineProfile;
use crate::progress::Progress;

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
            self.prev = self.at(0.0).0;
        }
        if !self.primed {
            self.drop_before_start();
        }
        self.advance(None, self.end_s, progress)
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

    /// Command at `t` (non-decreasing between calls) and what the segment it is in says of
    /// where it is.
    #[inline]
    fn at(&mut self, t: f64) -> (Command, Option<Here>) {
        self.seek(t);
        self.trim();
        self.command_at(t)
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

    /// The command at `t`, the cursor at `t` ([`Stream::seek`]).
    #[inline]
    fn command_at(&self, t: f64) -> (Command, Option<Here>) {
        match self.get(self.j) {
            Some((s, counted)) if t >= s.start_s => {
                let here = Here {
                    layer: s.layer,
                    counted: *counted,
                    extruding: s.extruding,
                };
                (s.command(t - s.start_s), Some(here))
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

    /// The command at `t1`, one period after `t0`, and the jumps of the commanded velocity
    /// in `(t0, t1]`: where a segment starts, from the velocity the one before it ended at (a
    /// rest between two moves is reached and left smoothly: the planner stops before it).
    /// Most periods have none: the cursor stays in a segment that started before `t0`.
    #[inline]
    fn step_to(&mut self, t0: f64, t1: f64) -> (Command, Option<Here>) {
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
                self.jumps.push((t1 - s.start_s) / (t1 - t0), dv);
            }
        }
        self.trim();
        self.command_at(t1)
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
                self.prev = self.at(self.k as f64 * ts).0;
                self.primed = true;
            }
            let (next, here) = self.step_to(t1 - ts, t1);
            if !self.step(next, here, t1)? {
                break;
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
            let extruding = s.here.extruding;
            self.out.add_deviation(s.dev, s.at, extruding, layer);
            if let Some(l) = self
                .counted
                .as_mut()
                .and_then(|c| c.get_mut(counted as usize))
            {
                l.add_deviation(s.dev, extruding);
            }
        }
        self.crest(sample);
        self.since += 1;
        let sampling = self
            .welch
            .as_deref_mut()
            .filter(|_| counting && self.since >= self.settings.decimation);
        if let Some(welch) = sampling {
            let dt = self.since as f64 * ts;
            let acc = table_acceleration(&next, &self.axes, &mut self.last_v, dt);
            welch.push(&acc);
            self.out.add_acceleration(&acc, layer);
            if let Some(l) = self
                .counted
                .as_mut()
                .and_then(|c| c.get_mut(counted as usize))
            {
                l.add_acceleration(&acc);
            }
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
        self.prev = if jumped {
            self.at(self.k as f64 * ts).0
        } else {
            next
        };
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
                let Here {
                    layer,
                    counted,
                    extruding,
                } = mid.here;
                self.out.raise(peak, mid.at, extruding, layer);
                if let Some(l) = self
                    .counted
                    .as_mut()
                    .and_then(|c| c.get_mut(counted as usize))
                {
                    l.raise(peak, extruding);
                }
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
