//! Multi-axis G-code in and out: every extruding `G1` becomes a path point (tool tip in the
//! workpiece frame and tool vector through the kinematic model), consecutive extruding moves
//! form a run (broken only by travel, non-extruding moves and tool-tip jumps), and smoothed runs
//! are written back as the same lines with new rotary angles and, in machine coordinates, the
//! machine XYZ that keeps the tool tip where it was.
//!
//! Travel moves, arcs, moves in relative positioning (`G91`) and every other line stay
//! byte-identical. A run starts at the end of the move before it, which is not changed.

use crate::error::Error;
use crate::gcode::{Edit, Line, RawLine};
use crate::machine::{axis, Machine, MoveKind, Pos};
use crate::path::PathMove;
use crate::plan::Profile;
use crate::read::{AnalyzeOptions, Flow, Fold, Reader};

use super::kinematics::{Kinematics, Pose};
use super::metrics::Sample;
use super::words;
use super::Coordinates;
use crate::vec3::V3;

/// Word letters the rewriting can change: X, Y, Z and the rotary axes.
const AXIS_INDEX: [(u8, usize); 6] = [
    (b'X', axis::X),
    (b'Y', axis::Y),
    (b'Z', axis::Z),
    (b'A', axis::A),
    (b'B', axis::B),
    (b'C', axis::C),
];

/// A `G0`/`G1` line as the rewriting needs it.
#[derive(Debug, Clone)]
pub(super) struct MotionLine {
    /// 1-based line number.
    pub number: u32,
    /// Byte range of the line's text in the input.
    pub range: std::ops::Range<usize>,
    /// Whether `G91` was in force.
    pub relative: bool,
    /// Values written for X, Y, Z, A, B, C (in [`AXIS_INDEX`] order).
    pub words: [Option<f64>; 6],
    /// The `G92` / `G28` shifts in force at the line.
    pub offsets: Offsets,
}

/// The fold of [`motion_lines`]. The machine model tracks the logical position beside the
/// machine's (G92, G28) and the positioning mode (G90, G91): the offsets and the mode are its
/// own, not a second reading of those commands.
#[derive(Default)]
struct Lines {
    out: Vec<MotionLine>,
    /// Number and byte range of the line being read.
    current: (u32, std::ops::Range<usize>),
}

impl Fold for Lines {
    fn line(&mut self, raw: &RawLine<'_>, _: Option<&Line<'_>>) -> Result<Flow, Error> {
        self.current = (raw.number, raw.offset..raw.offset + raw.text.len());
        Ok(Flow::Read)
    }

    /// A `G0`/`G1` line changes neither the offsets nor the positioning mode, so the machine
    /// before it tells both.
    fn command(&mut self, line: &Line<'_>, machine: &Machine) {
        if line.code().is_some_and(|c| c.is(b'G', 0) || c.is(b'G', 1)) {
            let (number, range) = self.current.clone();
            self.out.push(MotionLine {
                number,
                range,
                relative: machine.relative_positioning(),
                words: AXIS_INDEX.map(|(l, _)| line.params.get(l)),
                offsets: Offsets::of_machine(machine),
            });
        }
    }
}

/// Every `G0`/`G1` line of the input, in order. (The path extraction has already reported
/// what the reader warns of.)
pub(super) fn motion_lines(
    input: &[u8],
    options: &AnalyzeOptions,
) -> Result<Vec<MotionLine>, Error> {
    let mut lines = Lines::default();
    Reader::new(input, options)?.read(input, &mut lines)?;
    Ok(lines.out)
}

/// One run: indexes of its moves in the path.
pub(super) type Run = Vec<usize>;

/// The kinematic model and the coordinate convention the words are written in: what a
/// machine pose means in the workpiece frame.
#[derive(Debug, Clone, Copy)]
pub(super) struct Frame<'a> {
    /// Kinematic model.
    pub kin: &'a Kinematics,
    /// Whether X, Y, Z are machine axes or the tool tip in the workpiece frame (RTCP).
    pub coordinates: Coordinates,
}

impl Frame<'_> {
    /// Tool-tip position in the workpiece frame of a pose as written: through the kinematic
    /// model for machine coordinates, the X, Y, Z words themselves for workpiece coordinates.
    pub fn tip(&self, pose: &Pose) -> V3 {
        match self.coordinates {
            Coordinates::Machine => self.kin.tip(pose),
            Coordinates::Workpiece => pose.xyz,
        }
    }

    /// The X, Y, Z words that put the tip on workpiece point `p` with rotary angles `rot`.
    pub fn xyz_for(&self, p: V3, rot: [f64; 2]) -> V3 {
        match self.coordinates {
            Coordinates::Machine => self.kin.machine_xyz(p, rot),
            Coordinates::Workpiece => p,
        }
    }
}

/// Whether a move can be smoothed: an extruding straight `G1` in absolute positioning whose
/// tool tip moves no more than `max_gap_mm` in the workpiece frame. A longer tip move is a
/// jump to another section of the part, whose orientations have nothing to do with those
/// before it; it stays as written and separates the runs.
///
/// The machine XYZ travel is no criterion: at a corner of the path (a tangency discontinuity,
/// where the build direction jumps) the table turns and the machine axes travel far for a
/// short step of the tip, which is exactly where the smoothing is wanted (CIRP section 2.2). A
/// change of inverse-kinematics branch inside a run (the same tool vector reached by the other
/// solution) does not cut it either: the filter works on the tool vectors, which do not depend
/// on the branch, and the rotary angles are chosen afresh over the whole run on the branch of
/// the neighbours ([`super::core::choose_rotary`]).
fn eligible(frame: &Frame<'_>, m: &PathMove, line: Option<&MotionLine>, max_gap_mm: f64) -> bool {
    matches!(m.kind, MoveKind::Linear)
        && m.is_extruding()
        && line.is_some_and(|l| !l.relative)
        && tip_length(frame, m) <= max_gap_mm
}

/// Length of a move's tool-tip path in the workpiece frame (chord), mm. The machine XYZ length
/// is no measure of it: turning the table moves the machine axes a long way for a short step of
/// the tip.
pub(super) fn tip_length(frame: &Frame<'_>, m: &PathMove) -> f64 {
    let a = frame.tip(&pose(frame.kin, &m.from));
    let b = frame.tip(&pose(frame.kin, &m.to));
    crate::vec3::norm(crate::vec3::sub(b, a))
}

/// The motion line of each move (`None` for moves from other commands).
pub(super) fn line_of_moves<'l>(
    moves: &[PathMove],
    lines: &'l [MotionLine],
) -> Vec<Option<&'l MotionLine>> {
    let mut j = 0usize;
    moves
        .iter()
        .map(|m| {
            while lines.get(j).is_some_and(|l| l.number < m.line) {
                j += 1;
            }
            lines.get(j).filter(|l| l.number == m.line)
        })
        .collect()
}

/// Splits the moves into runs of consecutive eligible moves.
pub(super) fn runs(
    frame: &Frame<'_>,
    moves: &[PathMove],
    lines: &[Option<&MotionLine>],
    max_gap_mm: f64,
) -> Vec<Run> {
    let mut out = Vec::new();
    let mut cur: Run = Vec::new();
    for (i, m) in moves.iter().enumerate() {
        if eligible(frame, m, lines.get(i).copied().flatten(), max_gap_mm) {
            cur.push(i);
        } else if !cur.is_empty() {
            out.push(std::mem::take(&mut cur));
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Whether a rotary axis of `kin` is off zero anywhere in `moves`: a file whose rotary axes
/// never leave zero is a three-axis toolpath, whose tool vector is constant.
pub(super) fn has_rotary_motion(kin: &Kinematics, moves: &[PathMove]) -> bool {
    let [r0, r1] = kin.model.rotary_axes();
    let moved =
        |p: &Pos| p.get(r0).is_some_and(|&v| v != 0.0) || p.get(r1).is_some_and(|&v| v != 0.0);
    moves.iter().any(|m| moved(&m.from) || moved(&m.to))
}

/// Pose of a machine position.
pub(super) fn pose(kin: &Kinematics, pos: &Pos) -> Pose {
    let [r0, r1] = kin.model.rotary_axes();
    Pose {
        xyz: [pos[axis::X], pos[axis::Y], pos[axis::Z]],
        rot: [pos[r0], pos[r1]],
    }
}

/// The samples of a run: where it starts, then the end of each move.
pub(super) fn samples(frame: &Frame<'_>, moves: &[PathMove], run: &Run) -> Vec<Sample> {
    let mut out = Vec::with_capacity(run.len() + 1);
    let mut push = |pos: &Pos, dt: f64, profile: Option<Profile>| {
        let pose = pose(frame.kin, pos);
        out.push(Sample {
            p: frame.tip(&pose),
            v: frame.kin.tool_vector(pose.rot),
            rot: pose.rot,
            dt,
            profile,
        });
    };
    if let Some(first) = run.first().and_then(|&i| moves.get(i)) {
        push(&first.from, 0.0, None);
    }
    for m in run.iter().filter_map(|&i| moves.get(i)) {
        push(
            &m.to,
            m.timing.map_or(0.0, |t| t.duration_s),
            m.timing.map(|t| t.profile),
        );
    }
    out
}

/// The five axes a rewritten line carries: X, Y, Z and the two rotary axes.
fn five_axes(kin: &Kinematics) -> [usize; 5] {
    let [r0, r1] = kin.model.rotary_axes();
    [axis::X, axis::Y, axis::Z, r0, r1]
}

/// Which of the five axes the line leaves out (it then inherits them from the line before).
pub(super) fn omitted(line: &MotionLine, kin: &Kinematics) -> [bool; 5] {
    five_axes(kin).map(|ax| {
        AXIS_INDEX
            .iter()
            .position(|(_, a)| *a == ax)
            .and_then(|k| line.words.get(k).copied().flatten())
            .is_none()
    })
}

/// How axis words are written: the model, the G92 offsets in force, the decimals.
#[derive(Debug, Clone, Copy)]
pub(super) struct WordFormat<'a> {
    /// Kinematic model (which rotary letters).
    pub kin: &'a Kinematics,
    /// `word = position + offset`.
    pub offsets: &'a Offsets,
    /// Decimals written.
    pub decimals: usize,
    /// Whether X, Y, Z are rewritten (machine coordinates); in workpiece coordinates they are
    /// the tool tip, which stays, and only the rotary words change.
    pub rewrite_xyz: bool,
}

/// Which of the five axes the new pose writes differently from the original position.
pub(super) fn differs(fmt: &WordFormat<'_>, old_to: &Pos, new: &Pose) -> [bool; 5] {
    let WordFormat {
        kin,
        offsets,
        decimals,
        ..
    } = *fmt;
    let values = [new.xyz[0], new.xyz[1], new.xyz[2], new.rot[0], new.rot[1]];
    let axes = five_axes(kin);
    std::array::from_fn(|k| {
        let (ax, v) = (
            axes.get(k).copied().unwrap_or(0),
            values.get(k).copied().unwrap_or(0.0),
        );
        let old = old_to.get(ax).copied().unwrap_or(0.0) + offsets.of(ax);
        words::format_value(v + offsets.of(ax), decimals) != words::format_value(old, decimals)
    })
}

/// Offsets between written words and machine positions (G92 shifts, undone by G28):
/// `word = position + offset`.
#[derive(Debug, Default, Clone, Copy)]
pub(super) struct Offsets([f64; 6]);

impl Offsets {
    /// The machine model's logical position less its machine position, per axis.
    fn of_machine(machine: &Machine) -> Self {
        let (logical, physical) = (machine.logical_position(), machine.position());
        Self(AXIS_INDEX.map(|(_, ax)| {
            let d =
                logical.get(ax).copied().unwrap_or(0.0) - physical.get(ax).copied().unwrap_or(0.0);
            if d.is_finite() {
                d
            } else {
                0.0
            }
        }))
    }

    /// Offset of an axis index.
    pub fn of(&self, ax: usize) -> f64 {
        AXIS_INDEX
            .iter()
            .position(|(_, a)| *a == ax)
            .and_then(|k| self.0.get(k).copied())
            .unwrap_or(0.0)
    }
}

/// The edit of one motion line (which moved to `old_to`) for its new pose, or `None` when the
/// written values would not change (and not `force`d). A changed line gets all five axis words.
pub(super) fn edit_for(
    input: &[u8],
    line: &MotionLine,
    fmt: &WordFormat<'_>,
    old_to: &Pos,
    new: &Pose,
    force: bool,
) -> Option<Edit> {
    let WordFormat {
        kin,
        offsets,
        decimals,
        rewrite_xyz,
    } = *fmt;
    let [r0, r1] = kin.model.rotary_axes();
    let targets = [
        (b'X', axis::X, new.xyz[0]),
        (b'Y', axis::Y, new.xyz[1]),
        (b'Z', axis::Z, new.xyz[2]),
        (rot_letter(r0), r0, new.rot[0]),
        (rot_letter(r1), r1, new.rot[1]),
    ];
    let mut values = Vec::with_capacity(5);
    let mut changed = force;
    let skip = if rewrite_xyz { 0 } else { 3 };
    for (letter, ax, v) in targets.into_iter().skip(skip) {
        let text = words::format_value(v + offsets.of(ax), decimals);
        // What the line means now: its word, or the modal position it leaves unchanged.
        let old = old_to.get(ax).copied().unwrap_or(0.0) + offsets.of(ax);
        if words::format_value(old, decimals) != text {
            changed = true;
        }
        values.push((letter, text));
    }
    if !changed {
        return None;
    }
    let text = input.get(line.range.clone())?;
    Some(Edit {
        line: line.number,
        replacement: words::rewrite_line(text, &values),
    })
}

fn rot_letter(ax: usize) -> u8 {
    crate::machine::AXIS_LETTERS
        .get(ax)
        .copied()
        .unwrap_or(b'B')
}
