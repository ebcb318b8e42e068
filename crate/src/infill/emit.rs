//! G-code for new infill, written with the file's own habits, and the planner's view of it.
//!
//! A block's new lines are run through a copy of the machine as it stood before the block, with
//! the very words its text parses to, so the motions a candidate is costed with are exactly
//! those `analyze` will read from the written file (same rounding, same extrusion mode, same
//! firmware retraction) without printing and parsing the text.

use std::fmt::Write as _;

use super::cost::Replacement;
use super::geom::{dist, Path, P2};
use super::program::{Block, Program};
use crate::error::Warnings;
use crate::gcode::number::{least_positive, push_fixed, rounded};
#[cfg(test)]
use crate::gcode::parse_line;
use crate::machine::{axis, Event, ExtrusionMode, MoveKind};
use crate::plan::Motion;

/// How the file prints its infill and travels (measured from the file).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Habit {
    /// Filament per mm of sparse infill.
    pub e_per_mm: f64,
    /// Feed rates, mm/min.
    pub print_f: f64,
    pub travel_f: f64,
    pub retract_f: f64,
    pub unretract_f: f64,
    /// Retraction length, mm of filament (0: the file does not retract).
    pub retract_mm: f64,
    /// Travels at least this long are retracted, mm.
    pub min_travel_mm: f64,
    /// `G10`/`G11` instead of E moves.
    pub firmware: bool,
}

/// The value that most of `items`' weight sits at (ties: the first).
fn mode_by_weight(items: impl Iterator<Item = (f64, f64)>) -> Option<f64> {
    let mut bins: Vec<(f64, f64)> = Vec::new();
    for (v, w) in items {
        if !v.is_finite() || !w.is_finite() {
            continue;
        }
        if let Some(b) = bins.iter_mut().find(|b| (b.0 - v).abs() < 1e-6) {
            b.1 += w;
        } else if bins.len() < 4096 {
            bins.push((v, w));
        }
    }
    bins.into_iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|b| b.0)
}

/// Measures the habit from the file's moves.
pub(crate) fn habit(prog: &Program) -> Option<Habit> {
    let sparse = || {
        prog.blocks
            .iter()
            .flat_map(|b| prog.moves.get(b.first..b.end).unwrap_or(&[]))
            .filter(|m| m.m.is_extruding())
    };
    let (e, l) = sparse().fold((0.0, 0.0), |(e, l), m| {
        (e + m.m.extrusion(), l + m.m.length_mm)
    });
    if !(l > 0.0 && e > 0.0) {
        return None;
    }
    let print_f = mode_by_weight(sparse().map(|m| (m.m.feed_mm_s, m.m.length_mm)))? * 60.0;
    let travels = prog
        .moves
        .iter()
        .filter(|m| m.m.length_mm > 1e-9 && m.m.extrusion().abs() < 1e-12);
    let travel_f = mode_by_weight(travels.clone().map(|m| (m.m.feed_mm_s, m.m.length_mm)))
        .unwrap_or(print_f / 60.0)
        * 60.0;
    let pure_e = |sign: f64| {
        prog.moves.iter().filter(move |m| {
            m.m.length_mm <= 1e-9
                && m.m.extrusion() * sign > 1e-9
                && !matches!(m.m.kind, MoveKind::Home)
        })
    };
    let firmware = prog
        .moves
        .iter()
        .any(|m| matches!(m.m.kind, MoveKind::FirmwareRetract));
    let retract_mm =
        mode_by_weight(pure_e(-1.0).map(|m| ((-m.m.extrusion() * 1e5).round() / 1e5, 1.0)))
            .unwrap_or(0.0);
    let retract_f =
        mode_by_weight(pure_e(-1.0).map(|m| (m.m.feed_mm_s, 1.0))).unwrap_or(35.0) * 60.0;
    let unretract_f = mode_by_weight(pure_e(1.0).map(|m| (m.m.feed_mm_s, 1.0)))
        .unwrap_or(retract_f / 60.0)
        * 60.0;
    // Shortest travel that follows a retraction.
    let mut min_travel: f64 = f64::INFINITY;
    for w in prog.moves.windows(2) {
        let (a, b) = (&w[0].m, &w[1].m);
        if a.length_mm <= 1e-9
            && a.extrusion() < -1e-9
            && b.length_mm > 1e-9
            && b.extrusion().abs() < 1e-12
        {
            min_travel = min_travel.min(b.length_mm);
        }
    }
    let min_travel_mm = if min_travel.is_finite() {
        min_travel.clamp(0.5, 20.0)
    } else {
        2.0
    };
    Some(Habit {
        e_per_mm: e / l,
        print_f,
        travel_f,
        retract_f,
        unretract_f,
        retract_mm,
        min_travel_mm,
        firmware,
    })
}

fn r3(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0
}
fn r5(v: f64) -> f64 {
    (v * 1e5).round() / 1e5
}

/// Where a block's lines go: text for the written file ([`Text`]), or straight into a copy of
/// the machine ([`Run`]), which gets the very words the text parses to without printing and
/// parsing a line (the round trip was a third of an infill search).
/// The writer hands every feed through [`least_positive`] first, at the places each sink writes
/// it with: a positive feed is never written as `F0` (no feed at all, to Marlin).
trait Sink {
    /// `G10` (`on`) or `G11`.
    fn firmware_retract(&mut self, on: bool);
    /// `G1 E<e> F<f>`: `e` already on the 0.00001 grid, `f` written as `{:.0}`.
    fn filament(&mut self, e: f64, f: f64);
    /// `G1 X<x> Y<y> F<f>`: `x`, `y` on the 0.001 grid, `f` written as `{:.0}`.
    fn travel(&mut self, to: P2, f: f64);
    /// `G1 X<x> Y<y> E<e>` and `F<f>` (`{:.0}`) if given.
    fn extrude(&mut self, to: P2, e: f64, f: Option<f64>);
    /// `G92 E<e>` (`{:.5}`).
    fn set_e(&mut self, e: f64);
    /// `G1 F<f>` (`{:.3}`), the block's last line.
    fn feed(&mut self, f: f64);
}

/// The block as G-code text (without a final newline).
struct Text(String);

impl Sink for Text {
    fn firmware_retract(&mut self, on: bool) {
        self.0.push_str(if on { "G10\n" } else { "G11\n" });
    }

    fn filament(&mut self, e: f64, f: f64) {
        self.0.push_str("G1 E");
        push_fixed(&mut self.0, e, 5);
        let _ = writeln!(self.0, " F{f:.0}");
    }

    fn travel(&mut self, to: P2, f: f64) {
        self.0.push_str("G1 X");
        push_fixed(&mut self.0, to[0], 3);
        self.0.push_str(" Y");
        push_fixed(&mut self.0, to[1], 3);
        let _ = writeln!(self.0, " F{f:.0}");
    }

    fn extrude(&mut self, to: P2, e: f64, f: Option<f64>) {
        self.0.push_str("G1 X");
        push_fixed(&mut self.0, to[0], 3);
        self.0.push_str(" Y");
        push_fixed(&mut self.0, to[1], 3);
        self.0.push_str(" E");
        push_fixed(&mut self.0, e, 5);
        if let Some(f) = f {
            let _ = write!(self.0, " F{f:.0}");
        }
        self.0.push('\n');
    }

    fn set_e(&mut self, e: f64) {
        let _ = writeln!(self.0, "G92 E{e:.5}");
    }

    fn feed(&mut self, f: f64) {
        let _ = write!(self.0, "G1 F{f:.3}");
    }
}

/// The block run on a copy of the machine as it stood before it, collecting its motions.
struct Run {
    machine: crate::machine::Machine,
    line_no: u32,
    warnings: Warnings,
    motions: Vec<Motion>,
    /// Where the machine copy believes the nozzle starts, and where it does in the
    /// candidate's frame (a rotated part starts elsewhere).
    p0: P2,
    start: P2,
    moved: bool,
    /// The last value written with a formatter other than [`push_fixed`], and what it parses
    /// to (a block writes one or two such feed rates again and again).
    parsed: Vec<(u64, usize, f64)>,
}

impl Run {
    /// What `{v:.decimals$}` parses back to.
    fn as_written(&mut self, v: f64, decimals: usize) -> f64 {
        let key = (v.to_bits(), decimals);
        if let Some(&(_, _, p)) = self.parsed.iter().find(|p| (p.0, p.1) == key) {
            return p;
        }
        let p = format!("{v:.decimals$}").parse().unwrap_or(v);
        if self.parsed.len() < 8 {
            self.parsed.push((key.0, key.1, p));
        }
        p
    }

    fn g(&mut self, number: u16, words: &[(u8, f64)]) {
        let mut line = crate::gcode::Line {
            command: crate::gcode::Command::Code(crate::gcode::Code {
                letter: b'G',
                number,
                sub: None,
            }),
            ..Default::default()
        };
        for &(letter, v) in words {
            line.params.set(letter, v);
        }
        if let Some(Event::Move(m)) = self.machine.apply(self.line_no, &line, &mut self.warnings) {
            let mut motion = Motion::from(&m);
            if !self.moved && line.params.has(b'X') {
                // Every XY line written here names X and Y: the first one's displacement is
                // from the true start.
                motion.delta[0] += self.p0[0] - self.start[0];
                motion.delta[1] += self.p0[1] - self.start[1];
                self.moved = true;
            }
            self.motions.push(motion);
        }
    }
}

impl Sink for Run {
    fn firmware_retract(&mut self, on: bool) {
        self.g(if on { 10 } else { 11 }, &[]);
    }

    fn filament(&mut self, e: f64, f: f64) {
        let f = self.as_written(f, 0);
        self.g(1, &[(b'E', e), (b'F', f)]);
    }

    fn travel(&mut self, to: P2, f: f64) {
        let f = self.as_written(f, 0);
        self.g(1, &[(b'X', to[0]), (b'Y', to[1]), (b'F', f)]);
    }

    fn extrude(&mut self, to: P2, e: f64, f: Option<f64>) {
        match f {
            Some(f) => {
                let f = self.as_written(f, 0);
                self.g(1, &[(b'X', to[0]), (b'Y', to[1]), (b'E', e), (b'F', f)]);
            }
            None => self.g(1, &[(b'X', to[0]), (b'Y', to[1]), (b'E', e)]),
        }
    }

    fn set_e(&mut self, e: f64) {
        let e = self.as_written(e, 5);
        self.g(92, &[(b'E', e)]);
    }

    fn feed(&mut self, f: f64) {
        let f = self.as_written(f, 3);
        self.g(1, &[(b'F', f)]);
    }
}

/// Writes a block whose new strokes (machine frame) are `strokes`, from the block's start to
/// `end` (machine frame), leaving the filament as the original left it.
struct Writer<'a, S> {
    out: S,
    habit: &'a Habit,
    pos: P2,
    retracted: bool,
    absolute: bool,
    e: f64,
    /// Filament (mm) an E unit stands for at the block
    /// ([`crate::machine::Machine::filament_per_e_unit`]):
    /// the habit is measured in filament, the words are written in the file's units (a
    /// volume where `M200` or the flavour says so, before the `M221` flow factor).
    e_unit: f64,
}

impl<S: Sink> Writer<'_, S> {
    fn retract(&mut self, on: bool) {
        if self.retracted == on || (self.habit.retract_mm <= 0.0 && !self.habit.firmware) {
            self.retracted = on;
            return;
        }
        self.retracted = on;
        if self.habit.firmware {
            self.out.firmware_retract(on);
            return;
        }
        let (d, f) = if on {
            (-self.habit.retract_mm, self.habit.retract_f)
        } else {
            (self.habit.retract_mm, self.habit.unretract_f)
        };
        let d = d / self.e_unit;
        let v = if self.absolute {
            self.e = r5(self.e + d);
            self.e
        } else {
            r5(d)
        };
        self.out.filament(rounded(v, 5), least_positive(f, 0));
    }

    fn travel(&mut self, to: P2) {
        let to = [r3(to[0]), r3(to[1])];
        let d = dist(self.pos, to);
        if d < 1e-9 {
            return;
        }
        if d >= self.habit.min_travel_mm {
            self.retract(true);
        }
        self.out.travel(
            [rounded(to[0], 3), rounded(to[1], 3)],
            least_positive(self.habit.travel_f, 0),
        );
        self.pos = to;
    }

    fn stroke(&mut self, s: &[P2]) {
        let Some(&head) = s.first() else { return };
        self.travel(head);
        self.retract(false);
        let mut first = true;
        for &q in s.iter().skip(1) {
            let q = [r3(q[0]), r3(q[1])];
            let d = dist(self.pos, q);
            if d < 1e-9 {
                continue;
            }
            let inc = self.habit.e_per_mm * d / self.e_unit;
            let v = if self.absolute {
                self.e = r5(self.e + inc);
                self.e
            } else {
                r5(inc)
            };
            let f = first.then_some(least_positive(self.habit.print_f, 0));
            first = false;
            self.out
                .extrude([rounded(q[0], 3), rounded(q[1], 3)], rounded(v, 5), f);
            self.pos = q;
        }
    }

    /// Writes the block: its strokes, the way back to `end` and the filament state and
    /// absolute E the original left behind.
    fn block(mut self, block: &Block, strokes: &[Path], end: P2) -> S {
        for s in strokes {
            self.stroke(s);
        }
        if !block.free_end {
            self.travel(end);
        }
        self.retract(block.retracted_end);
        if self.absolute {
            self.out.set_e(block.end_logical[3]);
        }
        self.out.feed(least_positive(block.end_feed_mm_s * 60.0, 3));
        self.out
    }
}

fn writer<'a, S: Sink>(block: &Block, out: S, start: P2, habit: &'a Habit) -> Writer<'a, S> {
    Writer {
        out,
        habit,
        pos: [r3(start[0]), r3(start[1])],
        retracted: block.retracted_start,
        absolute: block.machine.extrusion_mode() == ExtrusionMode::Absolute,
        e: block.machine.logical_position()[axis::E],
        e_unit: Some(block.machine.filament_per_e_unit())
            .filter(|u| u.is_finite() && *u > 0.0)
            .unwrap_or(1.0),
    }
}

/// One block to write: the block, its new strokes, where it starts and ends (all in the
/// machine frame, turned with the part) and the file's habits at the layer's flow.
pub(crate) struct Job<'a> {
    pub block: &'a Block,
    pub strokes: Vec<Path>,
    pub start: P2,
    pub end: P2,
    pub habit: Habit,
}

/// The new text of a block (without a final newline): its strokes, then back to its end
/// unless the file travels on from there anyway, with the filament state and absolute E the
/// original left behind.
pub(crate) fn block_text(job: &Job<'_>) -> String {
    let cap = job.strokes.iter().map(|s| s.len() * 34).sum::<usize>() + 64;
    let text = Text(String::with_capacity(cap));
    writer(job.block, text, job.start, &job.habit)
        .block(job.block, &job.strokes, job.end)
        .0
}

/// The motions [`block_text`] makes when run from the machine state before the block, with the
/// nozzle at the job's start (in the candidate's frame: a rotated part starts elsewhere than
/// the machine copy believes), and where the nozzle ends: the same, bit for bit, as parsing the
/// text back ([`motions`]).
pub(crate) fn block_motions(job: &Job<'_>) -> Replacement {
    let Job {
        block,
        strokes,
        start,
        end,
        habit,
    } = job;
    let machine = block.machine.clone();
    let p0 = *machine.position();
    let run = Run {
        machine,
        line_no: block.first_line,
        warnings: Warnings::default(),
        motions: Vec::with_capacity(strokes.iter().map(Vec::len).sum::<usize>() + 8),
        p0: [p0[axis::X], p0[axis::Y]],
        start: [r3(start[0]), r3(start[1])],
        moved: false,
        parsed: Vec::new(),
    };
    let run = writer(block, run, *start, habit).block(block, strokes, *end);
    let p = run.machine.position();
    let end = if run.moved {
        [p[axis::X], p[axis::Y]]
    } else {
        run.start
    };
    Replacement {
        motions: run.motions,
        end: [end[0], end[1], p[axis::Z]],
    }
}

/// The motions `text` makes when run from the machine state before `block`, with the nozzle
/// at `start` (the block's start in the candidate's frame: a rotated part starts elsewhere
/// than the machine copy believes), and where the nozzle ends.
#[cfg(test)]
pub(crate) fn motions(block: &Block, text: &str, start: P2) -> Replacement {
    let mut machine = block.machine.clone();
    let mut warnings = Warnings::default();
    let mut motions = Vec::new();
    let p0 = *machine.position();
    let start = [r3(start[0]), r3(start[1])];
    let mut moved = false;
    for l in text.lines() {
        let Ok(line) = parse_line(l.as_bytes()) else {
            continue;
        };
        if let Some(Event::Move(m)) = machine.apply(block.first_line, &line, &mut warnings) {
            let mut motion = Motion::from(&m);
            if !moved && line.params.has(b'X') {
                motion.delta[0] += p0[axis::X] - start[0];
                motion.delta[1] += p0[axis::Y] - start[1];
                moved = true;
            }
            motions.push(motion);
        }
    }
    let p = machine.position();
    let end = if moved {
        [p[axis::X], p[axis::Y]]
    } else {
        start
    };
    Replacement {
        motions,
        end: [end[0], end[1], p[axis::Z]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weighted_mode() {
        assert_eq!(
            mode_by_weight([(1.0, 1.0), (2.0, 3.0), (1.0, 1.0)].into_iter()),
            Some(2.0)
        );
        assert_eq!(mode_by_weight(std::iter::empty()), None);
    }
}
