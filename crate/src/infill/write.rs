//! Writing the chosen candidate: whole-line edits through [`crate::gcode::write_with_edits`],
//! so every line the candidate does not change stays byte for byte.
//!
//! - Each replaced block: its first line becomes the new text, its other lines go.
//! - A part rotation: every move line of the print that moves in XY gets its X and Y rewritten
//!   to the rotated target (both words, even where the original gave one), arc offsets `I`/`J`
//!   turned with it; the other words are written back as parsed, the comment kept.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use super::cost::Rotation;
use super::program::Program;
use crate::gcode::{parse_line, Edit, Lines};
use crate::machine::{axis, MoveKind};

/// The edits of a candidate: `texts[b]` replaces block `b` when `Some`.
pub(crate) fn edits(
    input: &[u8],
    prog: &Program,
    texts: &[Option<String>],
    rotation: Option<&Rotation>,
) -> Vec<Edit> {
    let mut edits: Vec<Edit> = Vec::new();
    let replaced = replaced_blocks(prog, texts);
    let rotated = rotation.map(|r| rotated_moves(prog, r)).unwrap_or_default();
    let mut skip_to = 0u32;
    for raw in Lines::new(input) {
        let n = raw.number;
        if n <= skip_to && n != 0 {
            edits.push(Edit {
                line: n,
                replacement: Vec::new(),
            });
            continue;
        }
        if let Some(&(last, text)) = replaced.get(&n) {
            skip_to = last;
            edits.push(Edit {
                line: n,
                replacement: text.as_bytes().to_vec(),
            });
            continue;
        }
        let (Some(&(_, to)), Some(r)) = (rotated.get(&n), rotation) else {
            continue;
        };
        if let Some(t) = rotated_line(raw.text, to, r) {
            edits.push(Edit {
                line: n,
                replacement: t.into_bytes(),
            });
        }
    }
    edits
}

/// The replaced blocks by their first line: their last line and their new text.
fn replaced_blocks<'t>(
    prog: &Program,
    texts: &'t [Option<String>],
) -> BTreeMap<u32, (u32, &'t str)> {
    let mut replaced = BTreeMap::new();
    for (b, text) in texts.iter().enumerate() {
        let (Some(text), Some(blk)) = (text, prog.blocks.get(b)) else {
            continue;
        };
        replaced.insert(blk.first_line, (blk.last_line, text.as_str()));
    }
    replaced
}

/// The moves a part rotation rewrites, by line: their index and rotated XY target.
fn rotated_moves(prog: &Program, r: &Rotation) -> BTreeMap<u32, (usize, [f64; 2])> {
    let mut rotated = BTreeMap::new();
    for (i, mv) in prog.moves.iter().enumerate().take(r.last + 1).skip(r.first) {
        // Moves that stay in XY (lifts, retractions) keep their words: they stay wherever
        // the nozzle is, which after new infill is where the new infill ended.
        let still =
            mv.m.to[axis::X] == mv.m.from[axis::X] && mv.m.to[axis::Y] == mv.m.from[axis::Y];
        if still || matches!(mv.m.kind, MoveKind::FirmwareRetract | MoveKind::Home) {
            continue;
        }
        let to = r.apply([mv.m.to[axis::X], mv.m.to[axis::Y]]);
        rotated.insert(mv.m.line, (i, to));
    }
    rotated
}

/// The move line `text` written to the rotated target `to`, its arc offsets turned with it;
/// `None` if it is not a plain `G0`–`G3` line.
fn rotated_line(text: &[u8], to: [f64; 2], r: &Rotation) -> Option<String> {
    let line = parse_line(text).ok()?;
    let code = line.code()?;
    if code.letter != b'G' || code.number > 3 || line.params.has_bare_word() {
        return None;
    }
    let mut t = format!("G{}", code.number);
    let _ = write!(t, " X{:.3} Y{:.3}", to[0], to[1]);
    let (i, j) = (line.params.get(b'I'), line.params.get(b'J'));
    for (letter, value) in line.params.iter() {
        let Some(v) = value else { continue };
        match letter {
            b'X' | b'Y' | b'I' | b'J' => {}
            _ => {
                let _ = write!(t, " {}{}", letter as char, v);
            }
        }
    }
    if i.is_some() || j.is_some() {
        let (i, j) = (i.unwrap_or(0.0), j.unwrap_or(0.0));
        let (c, s) = r.cs;
        let _ = write!(t, " I{:.4} J{:.4}", c * i - s * j, s * i + c * j);
    }
    if let Some(comment) = line.comment {
        t.push_str(" ;");
        t.push_str(&String::from_utf8_lossy(comment));
    }
    Some(t)
}
