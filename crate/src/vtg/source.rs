//! What the rewriter needs to know about each move's source line, beyond [`crate::path`]:
//! whether the line can be replaced safely, the extrusion mode its `E` word is read in, its
//! `E` word and the modal feed rate word after it.
//!
//! A second pass reads the file exactly as `path::extract` does (same setup, limit commands
//! skipped the same way), so its moves line up one for one with the path's.

use crate::analyze::{prepare, AnalyzeOptions};
use crate::error::Error;
use crate::gcode::{self, Command, Line};
use crate::machine::{axis, Event, ExtrusionMode};
use crate::plan::Limits;

/// A move's source line as the rewriter sees it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveSource {
    /// 1-based line.
    pub line: u32,
    /// A plain `G1` with only X/Y/Z/E/F words, no comment, E present, and its X/Y/Z words equal
    /// to the machine position (absolute positioning in mm, no G92 offsets): safe to replace.
    pub plain: bool,
    /// Mode its `E` word is read in.
    pub mode: ExtrusionMode,
    /// Its `E` word.
    pub e_word: f64,
    /// Logical (G-code) E before the line.
    pub e_before: f64,
    /// The modal `F` word before the line, mm/min.
    pub f_before: Option<f64>,
    /// The modal `F` word after the line, mm/min (`None` before any `F`).
    pub f_after: Option<f64>,
    /// Annotation lines right before this one (see [`is_annotation`]): how many, and their
    /// bytes in the input (from the first one's start to the last one's end, terminators
    /// between them included).
    pub notes: Notes,
}

/// A run of annotation lines (see [`is_annotation`]) in the input.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Notes {
    /// Lines.
    pub lines: u32,
    /// Byte range in the input.
    pub from: usize,
    /// End of the byte range.
    pub to: usize,
}

/// A comment-only line that describes the extrusion for a viewer, and nothing the machine
/// does: PrusaSlicer's, SuperSlicer's and Slic3r's `;WIDTH:` and `;HEIGHT:`, which they write
/// between the moves of one path wherever the line width changes (variable-width gap fill and
/// thin walls, arc-fitted infill). A path may run across them: a rewrite deletes them and
/// writes them again inside the new block, at the same place along the path.
pub fn is_annotation(line: &Line<'_>) -> bool {
    matches!(line.command, Command::None)
        && line.params.is_empty()
        && line.text.is_empty()
        && line.line_number.is_none()
        && line
            .comment
            .is_some_and(|c| c.starts_with(b"WIDTH:") || c.starts_with(b"HEIGHT:"))
}

/// The source of every move, and the machine limits along the file.
#[derive(Debug, Clone, Default)]
pub struct Sources {
    /// One entry per move, in the order `path::extract` lists them.
    pub moves: Vec<MoveSource>,
    /// `(k, limits)`: the limits in force from move `k` on (the first at 0), as the file's
    /// own commands (`M201`–`M205`, `SET_VELOCITY_LIMIT`) change them.
    pub limits: Vec<(usize, Limits)>,
}

impl Sources {
    /// The limits in force at move `k`.
    pub fn limits_at(&self, k: usize) -> Option<&Limits> {
        let i = self.limits.partition_point(|(from, _)| *from <= k);
        self.limits.get(i.checked_sub(1)?).map(|(_, l)| l)
    }
}

/// Reads the source of every move and the limits along the file.
pub fn move_sources(input: &[u8], options: &AnalyzeOptions) -> Result<Sources, Error> {
    let setup = prepare(input, options)?;
    let mut machine = setup.machine();
    let mut warnings = setup.warnings;
    let mut limits = setup.limits;
    let mut f_modal: Option<f64> = None;
    let mut out = Vec::new();
    let mut changes = vec![(0usize, limits.clone())];
    let mut notes = Notes::default();
    gcode::for_each_line(
        input,
        setup.strictness,
        &mut warnings,
        |raw, line, warnings| {
            let Some(line) = line else {
                notes = Notes::default();
                return Ok(());
            };
            if is_annotation(line) {
                let end = raw.offset + raw.text.len();
                notes = if notes.lines > 0 {
                    Notes {
                        lines: notes.lines + 1,
                        to: end,
                        ..notes
                    }
                } else {
                    Notes {
                        lines: 1,
                        from: raw.offset,
                        to: end,
                    }
                };
                return Ok(());
            }
            let notes = std::mem::take(&mut notes);
            if limits.apply_command(line, setup.units) {
                // Several commands in a row before the next move: keep the last.
                if changes.last().is_some_and(|(k, _)| *k == out.len()) {
                    changes.pop();
                }
                changes.push((out.len(), limits.clone()));
                return Ok(());
            }
            let mode = machine.extrusion_mode();
            let e_before = machine.logical_position()[axis::E];
            let f_before = f_modal;
            let is_motion = line
                .code()
                .is_some_and(|c| c.letter == b'G' && c.number <= 3 && c.sub.is_none());
            if is_motion {
                if let Some(f) = line.params.get(b'F') {
                    f_modal = Some(f);
                }
            }
            if let Some(Event::Move(m)) = machine.apply(raw.number, line, warnings) {
                let plain = is_plain(line, &m.to);
                out.push(MoveSource {
                    line: raw.number,
                    plain,
                    mode,
                    e_word: line.params.get(b'E').unwrap_or(0.0),
                    e_before,
                    f_before,
                    f_after: f_modal,
                    notes,
                });
            }
            Ok(())
        },
    )?;
    Ok(Sources {
        moves: out,
        limits: changes,
    })
}

fn is_plain(line: &Line<'_>, to: &crate::machine::Pos) -> bool {
    let Some(code) = line.code() else {
        return false;
    };
    if !code.is(b'G', 1) || line.comment.is_some() || line.line_number.is_some() {
        return false;
    }
    if !line.params.has(b'E') || line.params.has_bare_word() {
        return false;
    }
    for (letter, value) in line.params.iter() {
        let Some(v) = value else { return false };
        let ax = match letter {
            b'X' => axis::X,
            b'Y' => axis::Y,
            b'Z' => axis::Z,
            b'E' | b'F' => continue,
            _ => return false,
        };
        if (to[ax] - v).abs() > 1e-9 {
            return false;
        }
    }
    true
}
