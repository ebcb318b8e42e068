//! The file as a program for the planner: every move and every event that times or flushes
//! the queue, in file order, plus the sparse-infill blocks that a candidate may replace.
//!
//! The pass mirrors [`crate::analyze::analyze`] line for line (same setup, same machine, same
//! limit commands, dwells, heater waits and event stamping), so that replaying the program
//! through a fresh [`crate::plan::Planner`] gives the same numbers as `analyze` of the file,
//! and replaying it with some blocks replaced gives the numbers of the rewritten file.

use crate::analyze::{layers::LayerTracker, prepare, AnalyzeOptions, LayerSource, Setup};
use crate::error::Error;
use crate::gcode::{self, classify_comment, feature_kind, Command, FeatureKind, Marker};
use crate::machine::{axis, Event, Heater, Machine, Move, MoveKind};
use crate::plan::{JunctionModel, Limits, MachineProfile};

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

/// Reads `input` into a [`Program`].
pub(crate) fn read(input: &[u8], options: &AnalyzeOptions) -> Result<Program, Error> {
    let setup = prepare(input, options)?;
    let mut machine = setup.machine();
    let Setup {
        strictness,
        mut warnings,
        profile,
        model,
        limits,
        units,
        ..
    } = setup;
    let mut limits_now = limits.clone();
    let mut tracker = LayerTracker::new();
    let mut moves: Vec<Mv> = Vec::new();
    let mut pairs: Vec<(u32, u32)> = Vec::new();
    let mut ops: Vec<Op> = Vec::new();
    let mut names: Vec<String> = Vec::new();
    let mut kind: Option<FeatureKind> = None;
    let mut relative_xy = false;
    let mut relative_now = false;
    let mut bed = None;
    // Block candidates: (first move, first line, machine before), open while sparse moves come.
    let mut raw_blocks: Vec<RawBlock> = Vec::new();
    let mut open: Option<(usize, u32, Box<Machine>)> = None;
    let mut retracted = false;
    let mut retract_marks: Vec<bool> = Vec::new();

    gcode::for_each_line(input, strictness, &mut warnings, |raw, line, warnings| {
        let Some(line) = line else { return Ok(()) };
        if let Some(comment) = line.comment {
            match classify_comment(comment) {
                Some(Marker::Layer { kind: k, z }) => {
                    tracker.marker(k, z, raw.number);
                    close(&mut open, &moves, &machine, &mut raw_blocks);
                }
                Some(Marker::Feature(name)) => {
                    kind = Some(feature_kind(name));
                    if names.len() < 4096 && !names.iter().any(|n| n == name) {
                        names.push(name.to_string());
                    }
                    close(&mut open, &moves, &machine, &mut raw_blocks);
                }
                None => {
                    if bed.is_none() {
                        bed = parse_bed(comment);
                    }
                }
            }
        }
        let code = line.code();
        if let Some(c) = code {
            if c.letter == b'G' && c.number == 91 {
                relative_now = true;
            } else if c.letter == b'G' && c.number == 90 {
                relative_now = false;
            }
        }
        let is_motion_code =
            matches!(code, Some(c) if c.letter == b'G' && c.number <= 3 && c.sub.is_none());
        let harmless = matches!(line.command, Command::None)
            || is_motion_code
            || matches!(code, Some(c) if c.letter == b'M' && c.number == 73);
        if !harmless {
            close(&mut open, &moves, &machine, &mut raw_blocks);
        }
        if limits_now.apply_command(line, units) {
            ops.push(Op::Limits(Box::new(limits_now.clone())));
            return Ok(());
        }
        let before = machine.clone();
        match machine.apply(raw.number, line, warnings) {
            Some(Event::Move(m)) => {
                tracker.motion(&m);
                pairs.push(tracker.current());
                let sparse = kind == Some(FeatureKind::SparseInfill)
                    && !relative_now
                    && (m.to[axis::Z] - m.from[axis::Z]).abs() < 1e-9
                    && !matches!(m.kind, MoveKind::Home);
                if !sparse {
                    close(&mut open, &moves, &before, &mut raw_blocks);
                } else if open.is_none() {
                    open = Some((moves.len(), raw.number, Box::new(before)));
                }
                if relative_now && m.length_mm > 0.0 {
                    relative_xy = true;
                }
                retract_marks.push(retracted);
                if m.is_extruding() {
                    retracted = false;
                } else if m.length_mm <= 1e-9 && m.extrusion() < -1e-9 {
                    retracted = true;
                } else if m.length_mm <= 1e-9 && m.extrusion() > 1e-9 {
                    retracted = false;
                }
                ops.push(Op::Move(moves.len()));
                moves.push(Mv {
                    m,
                    names: [line.params.has(b'X'), line.params.has(b'Y')],
                    kind,
                    layer: u32::MAX,
                });
            }
            Some(Event::Dwell(secs)) => ops.push(Op::Dwell(secs)),
            Some(Event::Temperature {
                heater,
                target_c,
                wait,
            }) => {
                ops.push(Op::Temperature {
                    line: raw.number,
                    heater,
                    target_c,
                    wait,
                });
                if wait {
                    ops.push(Op::Flush);
                }
            }
            Some(Event::Fan { index, speed }) => ops.push(Op::Fan {
                line: raw.number,
                index,
                speed,
            }),
            None => {}
        }
        Ok(())
    })?;
    close(&mut open, &moves, &machine, &mut raw_blocks);
    retract_marks.push(retracted);

    let (summaries, source) = tracker.finish();
    let by_marker = matches!(source, LayerSource::Markers(_));
    for (mv, &(a, b)) in moves.iter_mut().zip(&pairs) {
        mv.layer = if by_marker { a } else { b };
    }
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
    Ok(Program {
        moves,
        ops,
        blocks,
        layer_count: summaries.len(),
        profile,
        model,
        limits,
        relative_xy,
        bed,
    })
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
