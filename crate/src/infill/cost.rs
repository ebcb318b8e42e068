//! Costing a candidate with the real planner and energy model, without writing its G-code.
//!
//! The file's [`Program`] is replayed through a fresh [`Planner`] and energy
//! [`Accumulator`] exactly as `analyze` drives them (limits where they change, dwells and
//! heater waits flushing the queue, temperature and fan events stamped at the start of the next
//! planned move), with the sparse-infill blocks swapped for the candidate's motions (its lines
//! run through a copy of the machine, as its text would be, see [`super::emit`]) and, for a part rotation, every move of
//! the print turned about the part centre. So a candidate's `time_s`, `thesis_j` and `total_j`
//! are those `analyze` gives for the written file: exactly without rotation; with a rotation up
//! to the 0.001 mm rounding of the rewritten coordinates (the test suite checks both).
//! Replaying skips the parser and the machine, so it costs a fraction of an `analyze` pass.

use std::borrow::Cow;

use super::geom::{rotate, P2};
use super::program::{Mv, Op, Program};
use crate::analyze::toolpath::ToolpathMetrics;
use crate::analyze::Report;
use crate::energy::{Accumulator, EnergyOptions, MaterialSource};
use crate::machine::axis;
use crate::machine::{FanEvent, TemperatureEvent};
use crate::plan::{Motion, Planner};

/// A part rotation about Z: `p' = R(p − centre) + centre + shift`, applied to moves
/// `first..=last` (the print, without start and end code).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Rotation {
    pub cs: (f64, f64),
    pub centre: P2,
    pub shift: P2,
    pub first: usize,
    pub last: usize,
}

impl Rotation {
    /// Where `p` goes.
    pub fn apply(&self, p: P2) -> P2 {
        let q = rotate(p, self.centre, self.cs);
        [q[0] + self.shift[0], q[1] + self.shift[1]]
    }

    /// [`Rotation::apply`] rounded to 0.001 mm, as the rewritten lines give it.
    pub fn apply_r3(&self, p: P2) -> P2 {
        let q = self.apply(p);
        [
            (q[0] * 1000.0).round() / 1000.0,
            (q[1] * 1000.0).round() / 1000.0,
        ]
    }

    fn covers(&self, i: usize) -> bool {
        (self.first..=self.last).contains(&i)
    }
}

/// New motions for a block, and where the nozzle ends (X, Y, Z as the machine holds them).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Replacement {
    pub motions: Vec<Motion>,
    pub end: [f64; 3],
}

/// The numbers of one candidate, for the whole file.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Costs {
    pub time_s: f64,
    pub thesis_j: f64,
    pub total_j: f64,
    pub length_mm: f64,
    pub filament_mm: f64,
    /// VTG trajectory metrics (VTG eq. 24–26, 31) of the new infill strokes alone: the paper's
    /// Fig. 4–5 comparison of patterns by length and turning.
    pub infill: ToolpathMetrics,
}

/// What replay needs from the original analysis.
#[derive(Debug, Clone)]
pub(crate) struct Baseline {
    pub energy: EnergyOptions,
    pub material_from_file: Option<crate::energy::Material>,
    pub filament_mm: f64,
    pub material_g: f64,
}

impl Baseline {
    pub fn new(report: &Report, energy: EnergyOptions) -> Self {
        Self {
            energy,
            material_from_file: (report.energy.fuse.material_source == MaterialSource::File)
                .then_some(report.energy.fuse.material),
            filament_mm: report.filament_mm,
            material_g: report.material_g,
        }
    }
}

enum Pending {
    T(TemperatureEvent),
    F(FanEvent),
}

/// The timing side's bookkeeping during a replay (as `analyze`'s `TimeBook`).
struct Book<'a> {
    energy: Accumulator,
    temperatures: Vec<TemperatureEvent>,
    fans: Vec<FanEvent>,
    pending: std::collections::VecDeque<(u64, Pending)>,
    owner: Vec<u32>,
    per_block: Option<&'a mut Vec<[f64; 2]>>,
}

impl Book<'_> {
    fn planned(&mut self, pm: &crate::plan::PlannedMove) {
        let j = self.energy.planned(pm);
        self.stamp(pm.tag, pm.start_s);
        if let Some(pb) = self.per_block.as_deref_mut() {
            let b = self.owner.get(pm.tag as usize).copied().unwrap_or(u32::MAX);
            if let Some(acc) = pb.get_mut(b as usize) {
                acc[0] += j;
                acc[1] += pm.duration();
            }
        }
    }

    /// Stamps events that come before move `upto` with `t`.
    fn stamp(&mut self, upto: u64, t: f64) {
        while self.pending.front().is_some_and(|p| p.0 <= upto) {
            if let Some((_, p)) = self.pending.pop_front() {
                match p {
                    Pending::T(mut e) => {
                        e.time_s = t;
                        self.temperatures.push(e);
                    }
                    Pending::F(mut e) => {
                        e.time_s = t;
                        self.fans.push(e);
                    }
                }
            }
        }
    }
}

fn motion_length(m: &Motion) -> f64 {
    let [dx, dy, dz, _] = m.delta;
    match &m.arc {
        Some(a) => crate::math::hypot(a.radius * a.sweep.abs(), dz),
        None => crate::math::hypot(crate::math::hypot(dx, dy), dz),
    }
}

/// Where a replay's replacement blocks come from: a list made beforehand, or blocks made as
/// the replay reaches them (one candidate's motions need not all be held at once).
pub(crate) trait Replacements {
    /// Whether block `b` is replaced.
    fn replaced(&self, b: usize) -> bool;
    /// Block `b`'s replacement (`None`: the block is dropped without one).
    fn make(&self, b: usize) -> Option<Cow<'_, Replacement>>;
}

impl Replacements for [Option<Replacement>] {
    fn replaced(&self, b: usize) -> bool {
        self.get(b).is_some_and(Option::is_some)
    }

    fn make(&self, b: usize) -> Option<Cow<'_, Replacement>> {
        self.get(b)?.as_ref().map(Cow::Borrowed)
    }
}

/// Replays `prog` with each block `replace` replaces, and the rotation.
pub(crate) fn replay<R: Replacements + ?Sized>(
    prog: &Program,
    replace: &R,
    rotation: Option<&Rotation>,
    base: &Baseline,
) -> Costs {
    replay_ops(prog, &prog.ops, replace, rotation, base, None)
}

/// [`replay`], also summing `[servo J, s]` of each replaced block's planned moves into
/// `per_block` (indexed like `prog.blocks`).
pub(crate) fn replay_blocks<R: Replacements + ?Sized>(
    prog: &Program,
    replace: &R,
    rotation: Option<&Rotation>,
    base: &Baseline,
    per_block: Option<&mut Vec<[f64; 2]>>,
) -> Costs {
    replay_ops(prog, &prog.ops, replace, rotation, base, per_block)
}

/// [`replay_blocks`] over `ops`, the program's operations or a subsequence of them (a sample
/// of its layers, [`super::racing`]).
pub(crate) fn replay_ops<R: Replacements + ?Sized>(
    prog: &Program,
    ops: &[Op],
    replace: &R,
    rotation: Option<&Rotation>,
    base: &Baseline,
    per_block: Option<&mut Vec<[f64; 2]>>,
) -> Costs {
    let mut run = Replay::new(prog, base, per_block);
    let mut filament = base.filament_mm;
    let starts = replaced_starts(prog, replace);
    let mut next_start = 0usize;
    let mut skip_until = 0usize;
    let mut resume_from: Option<[f64; 3]> = None;
    let mut kept = 0usize;
    let mut infill_metrics = crate::analyze::toolpath::MetricsAccumulator::new(
        crate::analyze::toolpath::DEFAULT_CRITICAL_ANGLE_DEG,
    );
    for op in ops {
        let Op::Move(i) = op else {
            run.other(op);
            continue;
        };
        let i = *i;
        if i < skip_until {
            continue;
        }
        if let Some(&(first, b)) = starts.get(next_start) {
            if first == i {
                next_start += 1;
                let blk = &prog.blocks[b];
                skip_until = blk.end;
                let orig = prog
                    .moves
                    .get(blk.first..blk.end)
                    .map_or(0.0, |ms| ms.iter().map(|m| m.m.extrusion()).sum::<f64>());
                filament -= orig;
                if let Some(r) = replace.make(b) {
                    // Turning and length need directions only: positions from the
                    // block's start.
                    let mut at = [0.0f64; 3];
                    for m in &r.motions {
                        filament += m.delta[3];
                        let to = [at[0] + m.delta[0], at[1] + m.delta[1], at[2] + m.delta[2]];
                        infill_metrics.push(&at, &to, None, m.delta[3] > 0.0, b as u32, true);
                        at = to;
                        run.push(*m, b as u32);
                    }
                    resume_from = Some(r.end);
                }
                continue;
            }
        }
        let Some(mv) = prog.moves.get(i) else {
            continue;
        };
        let mut m = rotated_motion(mv, i, rotation);
        if let Some(end) = resume_from {
            resume_from = resume(&mut m, mv, i, rotation, end);
        }
        // A block kept as the file has it is still its own (per-layer choices cost it).
        while prog.blocks.get(kept).is_some_and(|b| b.end <= i) {
            kept += 1;
        }
        let owner = match prog.blocks.get(kept) {
            Some(b) if b.first <= i => kept as u32,
            _ => u32::MAX,
        };
        run.push(m, owner);
    }
    run.finish(base, filament, infill_metrics.finish())
}

/// The planner and the books of one replay.
struct Replay<'a> {
    planner: Planner,
    book: Book<'a>,
    /// Motions pushed so far (the tag of the next).
    seq: u64,
    /// Length of the motions pushed, mm.
    length: f64,
    /// Whether `book.owner` is kept (for `per_block`).
    track: bool,
}

impl<'a> Replay<'a> {
    fn new(prog: &Program, base: &Baseline, per_block: Option<&'a mut Vec<[f64; 2]>>) -> Self {
        let mut book = Book {
            energy: Accumulator::new(&base.energy, &prog.profile.name),
            temperatures: Vec::new(),
            fans: Vec::new(),
            pending: Default::default(),
            owner: Vec::new(),
            per_block,
        };
        if let Some(pb) = book.per_block.as_deref_mut() {
            pb.clear();
            pb.resize(prog.blocks.len(), [0.0; 2]);
        }
        if let Some(m) = base.material_from_file {
            book.energy.set_material_from_file(m);
        }
        let track = book.per_block.is_some();
        Self {
            planner: Planner::new(prog.limits.clone(), prog.model),
            book,
            seq: 0,
            length: 0.0,
            track,
        }
    }

    /// Plans motion `m`, owned by block `owner` (`u32::MAX`: by none).
    fn push(&mut self, m: Motion, owner: u32) {
        self.length += motion_length(&m);
        if self.track {
            self.book.owner.push(owner);
        }
        let book = &mut self.book;
        self.planner.push(&m, self.seq, &mut |pm| book.planned(pm));
        self.seq += 1;
    }

    fn flush(&mut self) {
        let book = &mut self.book;
        self.planner.flush(&mut |pm| book.planned(pm));
    }

    /// The costs once every operation is replayed, with `filament` mm of net filament.
    fn finish(mut self, base: &Baseline, filament: f64, infill: ToolpathMetrics) -> Costs {
        self.flush();
        let time_s = self.planner.elapsed_s();
        self.book.stamp(u64::MAX, time_s);
        let Book {
            energy,
            temperatures,
            fans,
            ..
        } = self.book;
        let material_g = if base.filament_mm > 0.0 {
            base.material_g * filament / base.filament_mm
        } else {
            base.material_g
        };
        let e = energy.finish(time_s, material_g, &temperatures, &fans);
        Costs {
            time_s,
            thesis_j: e.thesis_j,
            total_j: e.total_j,
            length_mm: self.length,
            filament_mm: filament,
            infill,
        }
    }

    /// Any operation but a move.
    fn other(&mut self, op: &Op) {
        match op {
            Op::Move(_) => {}
            Op::Dwell(secs) => {
                self.flush();
                self.book.stamp(u64::MAX, self.planner.elapsed_s());
                let book = &mut self.book;
                self.planner.dwell(*secs, &mut |pm| book.planned(pm));
                self.book.energy.dwell(*secs);
            }
            Op::Flush => self.flush(),
            Op::Limits(l) => *self.planner.limits_mut() = (**l).clone(),
            Op::Temperature {
                line,
                heater,
                target_c,
                wait,
            } => self.book.pending.push_back((
                self.seq,
                Pending::T(TemperatureEvent {
                    line: *line,
                    time_s: 0.0,
                    heater: *heater,
                    target_c: *target_c,
                    wait: *wait,
                }),
            )),
            Op::Fan { line, index, speed } => self.book.pending.push_back((
                self.seq,
                Pending::F(FanEvent {
                    line: *line,
                    time_s: 0.0,
                    index: *index,
                    speed: *speed,
                }),
            )),
        }
    }
}

/// Blocks replaced, as (first move, block index), in file order.
fn replaced_starts<R: Replacements + ?Sized>(prog: &Program, replace: &R) -> Vec<(usize, usize)> {
    let mut starts: Vec<(usize, usize)> = prog
        .blocks
        .iter()
        .enumerate()
        .filter(|(b, _)| replace.replaced(*b))
        .map(|(b, blk)| (blk.first, b))
        .collect();
    starts.sort_unstable();
    starts
}

/// The motion of move `i` of the file, turned with the part when `rotation` covers it.
fn rotated_motion(mv: &Mv, i: usize, rotation: Option<&Rotation>) -> Motion {
    let mut m = Motion::from(&mv.m);
    if let Some(r) = rotation {
        let from = [mv.m.from[axis::X], mv.m.from[axis::Y]];
        let to = [mv.m.to[axis::X], mv.m.to[axis::Y]];
        // As the rewritten lines give them (0.001 mm).
        let f = if i > r.first && i <= r.last + 1 {
            r.apply_r3(from)
        } else {
            from
        };
        let t = if r.covers(i) { r.apply_r3(to) } else { to };
        m.delta[0] = t[0] - f[0];
        m.delta[1] = t[1] - f[1];
        if r.covers(i) {
            if let Some(a) = m.arc.as_mut() {
                a.center = r.apply(a.center);
                a.start_angle += crate::math::atan2(r.cs.1, r.cs.0);
            }
        }
    }
    m
}

/// Moves after new infill start where the new infill ended (`end`): the axes a line does not
/// name stay there (a Z lift or a retraction stays put; a rotated line names both). Sets the
/// motion `m` of move `i` from there; the point the next move starts from when this one still
/// leaves an axis where the infill ended.
fn resume(
    m: &mut Motion,
    mv: &Mv,
    i: usize,
    rotation: Option<&Rotation>,
    end: [f64; 3],
) -> Option<[f64; 3]> {
    let rotated = rotation.is_some_and(|r| r.covers(i));
    let to = [mv.m.to[axis::X], mv.m.to[axis::Y]];
    let moves_xy = to != [mv.m.from[axis::X], mv.m.from[axis::Y]];
    let names = if rotated && moves_xy {
        [true; 2]
    } else {
        mv.names
    };
    let t = match rotation {
        Some(r) if rotated => r.apply_r3(to),
        _ => to,
    };
    let x = if names[0] { t[0] } else { end[0] };
    let y = if names[1] { t[1] } else { end[1] };
    m.delta[0] = x - end[0];
    m.delta[1] = y - end[1];
    m.delta[2] = mv.m.to[axis::Z] - end[2];
    (!names[0] || !names[1]).then_some([x, y, mv.m.to[axis::Z]])
}
