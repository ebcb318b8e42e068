//! The schedule the rotary rates are measured on: the tool tip travelling the file's path at
//! its feed rates, as the planner times it.
//!
//! In workpiece coordinates (RTCP/TCPM) that is the file's own plan: X, Y, Z are the tip. In
//! machine coordinates the planner times the machine's XYZ travel and knows no rotary-axis
//! limits, so a rewritten move whose XYZ travel shrinks (the table turning against the tip's
//! direction) would be given an unbounded rotary speed, and a long compensating move a gentle
//! one: neither is what a 5-axis machine runs. The same motion lines written with the tip's
//! X, Y, Z instead (rotary words unchanged) are the program an RTCP controller would run, and
//! the paper's robot does (CIRP section 3.3): planned by the same planner, with the same
//! limits and feeds, it gives one schedule for the file before and after smoothing, since the
//! tip does not move.

use super::program::{self, Frame, MotionLine, WordFormat};
use super::{Coordinates, SmoothOptions};
use crate::gcode::{self, Edit};
use crate::path::{self, PathMove};

/// Decimals of the tip coordinates in the timing program (well below any planner tolerance).
const TIP_DECIMALS: usize = 6;

/// `moves` with the planner's timing of their tool-tip path. In workpiece coordinates, or
/// when the tip program cannot be written or read back move for move (relative positioning,
/// arcs), the file's own timing stays.
pub(super) fn tip_timed(
    input: &[u8],
    frame: &Frame<'_>,
    moves: &[PathMove],
    lines: &[MotionLine],
    options: &SmoothOptions,
) -> Vec<PathMove> {
    if frame.coordinates == Coordinates::Workpiece {
        return moves.to_vec();
    }
    tip_program(input, frame, moves, lines)
        .and_then(|text| path::extract(&text, &options.analyze, true).ok())
        .filter(|tip| {
            tip.moves.len() == moves.len()
                && tip.moves.iter().zip(moves).all(|(a, b)| a.line == b.line)
        })
        .map_or_else(
            || moves.to_vec(),
            |tip| {
                moves
                    .iter()
                    .zip(&tip.moves)
                    .map(|(m, t)| PathMove {
                        timing: t.timing,
                        ..*m
                    })
                    .collect()
            },
        )
}

/// The input with every motion line's X, Y, Z replaced by the tool tip in the workpiece frame
/// of the pose it leaves the machine in (a line that does not move, its modal pose: its words
/// must not be read as tip coordinates either); `None` if a motion line is relative or a move
/// is not straight.
fn tip_program(
    input: &[u8],
    frame: &Frame<'_>,
    moves: &[PathMove],
    lines: &[MotionLine],
) -> Option<Vec<u8>> {
    let mut edits: Vec<Edit> = Vec::with_capacity(lines.len());
    let (mut j, mut at) = (0usize, None);
    for line in lines {
        while let Some(m) = moves.get(j).filter(|m| m.line <= line.number) {
            if matches!(m.kind, crate::machine::MoveKind::Arc(_)) {
                return None;
            }
            at = Some(m.to);
            j += 1;
        }
        let Some(to) = at else { continue };
        if line.relative {
            return None;
        }
        let pose = program::pose(frame.kin, &to);
        let tip = super::kinematics::Pose {
            xyz: frame.tip(&pose),
            rot: pose.rot,
        };
        let fmt = WordFormat {
            kin: frame.kin,
            offsets: &line.offsets,
            decimals: TIP_DECIMALS,
            rewrite_xyz: true,
        };
        edits.extend(program::edit_for(input, line, &fmt, &to, &tip, true));
    }
    Some(gcode::apply_edits(input, &edits))
}
