//! What the rewriter needs to know about each move's source line, beyond [`crate::path`]:
//! whether the line can be replaced safely, the extrusion mode its `E` word is read in, its
//! `E` word and the modal feed rate word after it.
//!
//! A second fold over the `Reader`, as `path::extract` is, so its moves line up one for one
//! with the path's.

use crate::error::Error;
use crate::gcode::{Command, Line, RawLine};
use crate::machine::{axis, Event, ExtrusionMode, Machine};
use crate::plan::Limits;
use crate::read::{AnalyzeOptions, At, Flow, Fold, Reader};

/// A move's source line as the rewriter sees it. Kept for every move of the file, beside the
/// path's own: 56 bytes, the modal feeds stored as `f64` with NaN for "none" (the reader never
/// gives a NaN word) and the notes' range as a start and a length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveSource {
    /// 1-based line.
    pub line: u32,
    /// A plain `G1` with only X/Y/Z/E/F words, no comment, E present, and its X/Y/Z words equal
    /// to the machine position (absolute positioning in mm, no G92 offsets): safe to replace.
    pub plain: bool,
    /// Mode its `E` word is read in.
    pub mode: ExtrusionMode,
    /// The modal `F` after the line is never read: the next move sets its own (a `G1`, `G2` or
    /// `G3` with an `F` word) with only lines between that read no feed (those
    /// [`crate::vtg::feeds`] folds across). A rewritten block ending here need not leave the
    /// modal feed as the original did.
    pub feed_overridden: bool,
    /// Its `E` word.
    pub e_word: f64,
    /// Logical (G-code) E before the line.
    pub e_before: f64,
    /// The modal `F` word before the line, mm/min (NaN: none); see [`MoveSource::f_before`].
    f_before: f64,
    /// The modal `F` word after the line, mm/min (NaN: none); see [`MoveSource::f_after`].
    f_after: f64,
    /// Annotation lines right before this one (see [`is_annotation`]).
    pub notes: Notes,
}

impl MoveSource {
    /// The modal `F` word before the line, mm/min (`None` before any `F`).
    pub fn f_before(&self) -> Option<f64> {
        Some(self.f_before).filter(|f| !f.is_nan())
    }

    /// The modal `F` word after the line, mm/min (`None` before any `F`).
    pub fn f_after(&self) -> Option<f64> {
        Some(self.f_after).filter(|f| !f.is_nan())
    }
}

/// A run of annotation lines (see [`is_annotation`]) in the input: how many, and their bytes
/// (from the first one's start to the last one's end, terminators between them included).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Notes {
    /// Lines.
    pub lines: u32,
    /// Length of the byte range (a run that would pass 4 GB starts again at its next line).
    pub len: u32,
    /// Start of the byte range in the input.
    pub from: usize,
}

impl Notes {
    /// The byte range in the input.
    pub fn range(&self) -> std::ops::Range<usize> {
        self.from..self.from + self.len as usize
    }

    /// This run with the annotation at bytes `offset..end` added: a run of its own where this
    /// one would outgrow `max` bytes (the earlier annotations then stay where they are, before
    /// a rewritten block, and the line count no longer joins the moves either side into one
    /// path); `None` where the line alone would, so it is read as a plain comment.
    fn with(self, offset: usize, end: usize, max: usize) -> Option<Notes> {
        let fits = |from: usize| {
            u32::try_from(end - from)
                .ok()
                .filter(|&l| l as usize <= max)
        };
        match fits(self.from).filter(|_| self.lines > 0) {
            Some(len) => Some(Notes {
                lines: self.lines + 1,
                len,
                from: self.from,
            }),
            None => Some(Notes {
                lines: 1,
                len: fits(offset)?,
                from: offset,
            }),
        }
    }
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

/// The fold of [`move_sources`]. Paired with the path's walk ([`path_and_sources`]) it is also
/// told of the annotation lines it skips; it takes them as comments, of which it keeps nothing
/// (their `command` sets `before`, which the next command sets again before any move).
struct Read {
    sources: Sources,
    /// Annotation lines since the last other line.
    notes: Notes,
    /// The annotations before the line being read.
    line_notes: Notes,
    /// The modal `F` word.
    f_modal: Option<f64>,
    /// Since the last move, every line read no feed ([`crate::vtg::feeds::crosses`]).
    feed_unread: bool,
    /// What the line's move needs of the state before it: mode, logical E, modal `F`.
    before: (ExtrusionMode, f64, Option<f64>),
}

impl Read {
    /// The fold of a pass over `input` by `reader`, before its first line.
    fn new(input: &[u8], reader: &Reader) -> Self {
        Read {
            sources: Sources {
                moves: Vec::with_capacity(crate::gcode::command_lines(input)),
                limits: vec![(0, reader.limits.clone())],
            },
            notes: Notes::default(),
            line_notes: Notes::default(),
            f_modal: None,
            feed_unread: true,
            before: (ExtrusionMode::Absolute, 0.0, None),
        }
    }
}

impl Fold for Read {
    fn line(&mut self, raw: &RawLine<'_>, line: Option<&Line<'_>>) -> Result<Flow, Error> {
        let Some(line) = line else {
            self.notes = Notes::default();
            self.feed_unread = false;
            return Ok(Flow::Read);
        };
        // Moves are told in `event`; a motion line that makes none moves nothing.
        if !crate::vtg::feeds::crosses(line) && !line.code().is_some_and(|c| c.is_motion()) {
            self.feed_unread = false;
        }
        let end = raw.offset + raw.text.len();
        let joined = is_annotation(line)
            .then(|| self.notes.with(raw.offset, end, u32::MAX as usize))
            .flatten();
        let Some(notes) = joined else {
            self.line_notes = std::mem::take(&mut self.notes);
            return Ok(Flow::Read);
        };
        self.notes = notes;
        Ok(Flow::Skip)
    }

    fn limits(&mut self, limits: &Limits, _: &Machine) {
        let changes = &mut self.sources.limits;
        let k = self.sources.moves.len();
        // Several commands in a row before the next move: keep the last.
        if changes.last().is_some_and(|(from, _)| *from == k) {
            changes.pop();
        }
        changes.push((k, limits.clone()));
    }

    fn command(&mut self, line: &Line<'_>, machine: &Machine) {
        let e_before = machine.logical_position()[axis::E];
        self.before = (machine.extrusion_mode(), e_before, self.f_modal);
        if line.code().is_some_and(|c| c.is_motion()) {
            if let Some(f) = line.params.get(b'F') {
                self.f_modal = Some(f);
            }
        }
    }

    fn event(&mut self, line: &Line<'_>, event: &Event, at: At<'_>) -> Result<(), Error> {
        if let Event::Move(m) = event {
            let overrides = self.feed_unread && crate::vtg::feeds::sets_feed(line);
            if let Some(last) = self.sources.moves.last_mut() {
                last.feed_overridden = overrides;
            }
            self.feed_unread = true;
            let (mode, e_before, f_before) = self.before;
            self.sources.moves.push(MoveSource {
                line: at.line,
                plain: is_plain(line, &m.to),
                mode,
                feed_overridden: false,
                e_word: line.params.get(b'E').unwrap_or(0.0),
                e_before,
                f_before: f_before.unwrap_or(f64::NAN),
                f_after: self.f_modal.unwrap_or(f64::NAN),
                notes: self.line_notes,
            });
        }
        Ok(())
    }
}

/// Reads the source of every move and the limits along the file.
pub fn move_sources(input: &[u8], options: &AnalyzeOptions) -> Result<Sources, Error> {
    let mut reader = Reader::new(input, options)?;
    let mut fold = Read::new(input, &reader);
    reader.read(input, &mut fold)?;
    Ok(fold.sources)
}

/// The file's path ([`crate::path::extract`]) and its moves' sources ([`move_sources`]) from
/// one pass: the same two results, read and parsed once (`vtg` needs both of every file it
/// rewrites; on the 34 MB corpus file the second pass was a sixth of the reading's CPU time).
pub fn path_and_sources(
    input: &[u8],
    options: &AnalyzeOptions,
    plan: bool,
) -> Result<(crate::path::PrintPath, Sources), Error> {
    let (path, read) =
        crate::path::extract_also(input, options, plan, |reader| Read::new(input, reader))?;
    Ok((path, read.sources))
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

#[cfg(test)]
mod tests {
    use super::*;

    /// One is kept for every move of a file (1.1 million on the 34 MB corpus file).
    #[test]
    fn a_move_source_takes_56_bytes_natively() {
        if cfg!(target_pointer_width = "64") {
            assert_eq!(std::mem::size_of::<MoveSource>(), 56);
        }
    }

    #[test]
    fn notes_and_modal_feeds_are_read_back() {
        let g = b"G90\nM82\nG1 X5 Y5 F600\nG1 X1 E1\n;WIDTH:0.4\n;HEIGHT:0.2\nG1 X2 E2\n";
        let s = move_sources(g, &AnalyzeOptions::default()).unwrap();
        let last = s.moves.last().unwrap();
        assert_eq!(last.line, 7);
        assert_eq!(last.notes.lines, 2);
        assert_eq!(&g[last.notes.range()], b";WIDTH:0.4\n;HEIGHT:0.2");
        assert_eq!(
            (last.f_before(), last.f_after()),
            (Some(600.0), Some(600.0))
        );
        let first = s.moves.first().unwrap();
        assert_eq!((first.f_before(), first.notes.lines), (None, 0));
        assert_eq!(first.f_after(), Some(600.0));
    }

    /// A move's modal feed is overridden where the next move is a `G1`–`G3` with its own `F`
    /// and only lines that read no feed lie between; a macro, a `G0` (Marlin may keep its feed
    /// apart) or a move without `F` reads or may read it.
    #[test]
    fn a_feed_the_next_move_sets_again_is_overridden() {
        let overridden = |between: &str, next: &str| {
            let g = format!("G90\nM83\nG1 X1 Y1 E1 F600\n{between}{next}\n");
            let s = move_sources(g.as_bytes(), &AnalyzeOptions::default()).unwrap();
            s.moves[0].feed_overridden
        };
        assert!(overridden("", "G1 X5 Y5 F9000"));
        assert!(overridden(
            ";TYPE:Skirt\nM204 S800\nG92 E0\n",
            "G1 E-.8 F2100"
        ));
        assert!(overridden("", "G2 X3 Y3 I1 J1 E1 F1200"));
        assert!(!overridden("", "G1 X5 Y5 E1"));
        assert!(!overridden("", "G0 X5 Y5 F9000"));
        assert!(!overridden("M600\n", "G1 X5 Y5 F9000"));
        assert!(!overridden("PAUSE\n", "G1 X5 Y5 F9000"));
    }

    #[test]
    fn a_run_of_notes_that_would_outgrow_its_length_starts_again() {
        let one = Notes::default().with(10, 20, 25).unwrap();
        assert_eq!((one.lines, one.from, one.len), (1, 10, 10));
        let two = one.with(21, 30, 25).unwrap();
        assert_eq!((two.lines, two.from, two.len), (2, 10, 20));
        // 10..40 is 30 bytes, over 25: the run starts again at the new line.
        let again = two.with(31, 40, 25).unwrap();
        assert_eq!((again.lines, again.from, again.len), (1, 31, 9));
        // A line longer than the bound alone is no note.
        assert_eq!(again.with(41, 80, 25), None);
    }
}
