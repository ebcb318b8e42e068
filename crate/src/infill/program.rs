//! The file as a program for the planner: every move and every event that times or flushes
//! the queue, in file order, plus the sparse-infill blocks that a candidate may replace.
//!
//! It is a fold over the same [`Reader`] as [`crate::analyze::analyze`] (same setup, machine,
//! limit commands, dwells, heater waits and event stamping), so that replaying the program
//! through a fresh [`crate::plan::Planner`] gives the same numbers as `analyze` of the file,
//! and replaying it with some blocks replaced gives the numbers of the rewritten file.

use crate::error::Error;
use crate::gcode::{feature_kind, Command, FeatureKind, Line};
use crate::machine::{axis, Event, Heater, Machine, Move, MoveKind};
use crate::plan::{JunctionModel, Limits, MachineProfile};
use crate::read::{AnalyzeOptions, At, Fold, LayerSource, Reader};

/// One thing the timing side sees.
#[derive(Debug, Clone)]
pub(crate) enum Op {
    /// `moves[i]`.
    Move(usize),
    /// A `G4` dwell, s.
    Dwell(f64),
    /// A heater wait: the queue drains.
    Flush,
    /// New limits from a command.
    Limits(Box<Limits>),
    /// A heater target (timed at the next move's start).
    Temperature {
        line: u32,
        heater: Heater,
        target_c: f64,
        wait: bool,
    },
    /// A fan speed (timed at the next move's start).
    Fan { line: u32, index: u16, speed: f64 },
}

/// A move with what the optimiser needs to know about it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Mv {
    pub m: Move,
    /// Whether the line names X, and Y.
    pub names: [bool; 2],
    pub kind: Option<FeatureKind>,
    pub layer: u32,
}

/// A run of sparse-infill moves that a candidate replaces as a whole.
#[derive(Debug, Clone)]
pub(crate) struct Block {
    /// Layer index.
    pub layer: usize,
    /// Moves `first..end`.
    pub first: usize,
    pub end: usize,
    /// Lines `first_line..=last_line` are replaced.
    pub first_line: u32,
    pub last_line: u32,
    /// The machine just before the block's first line.
    pub machine: Machine,
    /// Logical position and feed rate after the block's last line.
    pub end_logical: [f64; 4],
    pub end_physical: [f64; 4],
    pub end_feed_mm_s: f64,
    /// Whether the next move that goes somewhere after the block is a travel (so new infill
    /// may end anywhere: that travel starts from wherever it ends).
    pub free_end: bool,
    /// Whether the filament is retracted at the start and at the end of the block.
    pub retracted_start: bool,
    pub retracted_end: bool,
}

/// The whole file.
#[derive(Debug, Clone)]
pub(crate) struct Program {
    pub moves: Vec<Mv>,
    pub ops: Vec<Op>,
    pub blocks: Vec<Block>,
    pub layer_count: usize,
    pub profile: MachineProfile,
    pub model: JunctionModel,
    pub limits: Limits,
    /// Whether some XY move is in relative coordinates (`G91`): no rotation then.
    pub relative_xy: bool,
    /// Bed rectangle from a `bed_shape` comment, if any.
    pub bed: Option<[f64; 4]>,
}

/// The fold of [`read`]: moves, ops and the sparse-infill blocks as they open and close.
#[derive(Default)]
struct Reading {
    moves: Vec<Mv>,
    pairs: Vec<(u32, u32)>,
    ops: Vec<Op>,
    names: Vec<String>,
    kind: Option<FeatureKind>,
    relative_xy: bool,
    bed: Option<[f64; 4]>,
    raw_blocks: Vec<RawBlock>,
    /// The block being read: first move, first line, the machine before it.
    open: Option<(usize, u32, Box<Machine>)>,
    retracted: bool,
    retract_marks: Vec<bool>,
    /// The machine before the line being read.
    before: Option<Machine>,
}

impl Reading {
    fn close(&mut self, after: &Machine) {
        close(&mut self.open, &self.moves, after, &mut self.raw_blocks);
    }

    /// Whether the filament is retracted after `m`.
    fn track_retraction(&mut self, m: &Move) {
        self.retract_marks.push(self.retracted);
        if m.is_extruding() {
            self.retracted = false;
        } else if m.length_mm <= 1e-9 && m.extrusion() < -1e-9 {
            self.retracted = true;
        } else if m.length_mm <= 1e-9 && m.extrusion() > 1e-9 {
            self.retracted = false;
        }
    }

    fn moved(&mut self, line: &Line<'_>, m: &Move, at: At<'_>) {
        self.pairs.push(at.layers);
        let relative = at.machine.relative_positioning();
        let sparse = self.kind == Some(FeatureKind::SparseInfill)
            && !relative
            && (m.to[axis::Z] - m.from[axis::Z]).abs() < 1e-9
            && !matches!(m.kind, MoveKind::Home);
        let before = self.before.take().unwrap_or_else(|| at.machine.clone());
        if !sparse {
            self.close(&before);
        } else if self.open.is_none() {
            self.open = Some((self.moves.len(), at.line, Box::new(before)));
        }
        if relative && m.length_mm > 0.0 {
            self.relative_xy = true;
        }
        self.track_retraction(m);
        self.ops.push(Op::Move(self.moves.len()));
        self.moves.push(Mv {
            m: *m,
            names: [line.params.has(b'X'), line.params.has(b'Y')],
            kind: self.kind,
            layer: u32::MAX,
        });
    }
}

impl Fold for Reading {
    fn layer_marker(&mut self, machine: &Machine) {
        self.close(machine);
    }

    fn feature(&mut self, name: &str, machine: &Machine) {
        self.kind = Some(feature_kind(name));
        if self.names.len() < 4096 && !self.names.iter().any(|n| n == name) {
            self.names.push(name.to_string());
        }
        self.close(machine);
    }

    fn comment(&mut self, comment: &[u8]) {
        if self.bed.is_none() {
            self.bed = parse_bed(comment);
        }
    }

    fn limits(&mut self, limits: &Limits, machine: &Machine) {
        self.close(machine);
        self.ops.push(Op::Limits(Box::new(limits.clone())));
    }

    fn command(&mut self, line: &Line<'_>, machine: &Machine) {
        let code = line.code();
        let harmless = matches!(line.command, Command::None)
            || code.is_some_and(|c| c.is_motion() || c.is(b'M', 73));
        if !harmless {
            self.close(machine);
        }
        self.before = Some(machine.clone());
    }

    fn event(&mut self, line: &Line<'_>, event: &Event, at: At<'_>) -> Result<(), Error> {
        match *event {
            Event::Move(ref m) => self.moved(line, m, at),
            Event::Dwell(secs) => self.ops.push(Op::Dwell(secs)),
            Event::Temperature {
                heater,
                target_c,
                wait,
            } => {
                self.ops.push(Op::Temperature {
                    line: at.line,
                    heater,
                    target_c,
                    wait,
                });
                if wait {
                    self.ops.push(Op::Flush);
                }
            }
            Event::Fan { index, speed } => self.ops.push(Op::Fan {
                line: at.line,
                index,
                speed,
            }),
        }
        Ok(())
    }
}

/// Reads `input` into a [`Program`].
pub(crate) fn read(input: &[u8], options: &AnalyzeOptions) -> Result<Program, Error> {
    let mut reader = Reader::new(input, options)?;
    let mut r = Reading::default();
    reader.read(input, &mut r)?;
    r.close(&reader.machine);
    r.retract_marks.push(r.retracted);
    let Reader { setup, layers, .. } = reader;
    let (summaries, source) = layers.finish();
    let by_marker = matches!(source, LayerSource::Markers(_));
    for (mv, &(a, b)) in r.moves.iter_mut().zip(&r.pairs) {
        mv.layer = if by_marker { a } else { b };
    }
    let blocks = blocks(
        &r.moves,
        std::mem::take(&mut r.raw_blocks),
        &r.retract_marks,
    );
    Ok(Program {
        moves: r.moves,
        ops: r.ops,
        blocks,
        layer_count: summaries.len(),
        profile: setup.profile,
        model: setup.model,
        limits: setup.limits,
        relative_xy: r.relative_xy,
        bed: r.bed,
    })
}

/// The blocks a candidate may replace: each raw block within one layer that extrudes.
fn blocks(moves: &[Mv], raw_blocks: Vec<RawBlock>, retract_marks: &[bool]) -> Vec<Block> {
    let mut blocks = Vec::new();
    for (first, end, first_line, last_line, machine, end_logical, end_physical, end_feed) in
        raw_blocks
    {
        let Some(head) = moves.get(first) else {
            continue;
        };
        let layer = head.layer;
        // Split at layer boundaries (a marker closes blocks, but Z-counted layers do not).
        if layer == u32::MAX || moves[first..end].iter().any(|m| m.layer != layer) {
            continue;
        }
        let filament_mm: f64 = moves[first..end]
            .iter()
            .filter(|m| m.m.is_extruding())
            .map(|m| m.m.extrusion())
            .sum();
        if filament_mm <= 0.0 {
            continue;
        }
        blocks.push(Block {
            layer: layer as usize,
            first,
            end,
            first_line,
            last_line,
            machine: *machine,
            end_logical,
            end_physical,
            end_feed_mm_s: end_feed,
            retracted_start: retract_marks.get(first).copied().unwrap_or(false),
            retracted_end: retract_marks.get(end).copied().unwrap_or(false),
            free_end: moves
                .get(end..)
                .and_then(|rest| rest.iter().find(|m| m.m.length_mm > 1e-9))
                .is_some_and(|m| !m.m.is_extruding() && !matches!(m.m.kind, MoveKind::Arc(_))),
        });
    }
    blocks
}

type RawBlock = (
    usize,
    usize,
    u32,
    u32,
    Box<Machine>,
    [f64; 4],
    [f64; 4],
    f64,
);

/// Ends the open block (if any) after the moves read so far; `after` is the machine state
/// after the block's last line.
fn close(
    open: &mut Option<(usize, u32, Box<Machine>)>,
    moves: &[Mv],
    after: &Machine,
    out: &mut Vec<RawBlock>,
) {
    if let Some((first, first_line, machine)) = open.take() {
        let end = moves.len();
        if let Some(last) = moves.get(end.wrapping_sub(1)).filter(|_| end > first) {
            let l = after.logical_position();
            let p = after.position();
            out.push((
                first,
                end,
                first_line,
                last.m.line,
                machine,
                [l[0], l[1], l[2], l[3]],
                [p[0], p[1], p[2], p[3]],
                after.feed_mm_s(),
            ));
        }
    }
}

/// `; bed_shape = 0x0,250x0,250x210,0x210` (PrusaSlicer, SuperSlicer, OrcaSlicer
/// `printable_area`): the bounding rectangle `[x0, y0, x1, y1]`.
fn parse_bed(comment: &[u8]) -> Option<[f64; 4]> {
    let text = std::str::from_utf8(comment).ok()?.trim();
    let rest = text
        .strip_prefix("bed_shape")
        .or_else(|| text.strip_prefix("printable_area"))?;
    let rest = rest.trim_start().strip_prefix('=')?.trim();
    let mut b = [
        f64::INFINITY,
        f64::INFINITY,
        f64::NEG_INFINITY,
        f64::NEG_INFINITY,
    ];
    for pair in rest.split(',') {
        let (x, y) = pair.trim().split_once('x')?;
        let (x, y): (f64, f64) = (x.trim().parse().ok()?, y.trim().parse().ok()?);
        if !x.is_finite() || !y.is_finite() {
            return None;
        }
        b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
    }
    (b[2] > b[0] && b[3] > b[1]).then_some(b)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bed_shape_comment() {
        assert_eq!(
            parse_bed(b" bed_shape = 0x0,250x0,250x210,0x210"),
            Some([0.0, 0.0, 250.0, 210.0])
        );
        assert_eq!(parse_bed(b" bed_shape = junk"), None);
    }
}
