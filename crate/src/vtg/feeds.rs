//! Feed-only lines (`G1 F6000` with nothing else) folded into the move that reads the feed
//! first: `G1 F6000` then `G1 X84 Y102 E.013` becomes `G1 X84 Y102 E.013 F6000`, one line
//! where there were two, and the machine does exactly what it did. PrusaSlicer and its
//! descendants write one before most paths (14–17 % of the lines of the corpus's Creality and
//! Slic3r PE benchies), and a rewritten block that leaves the modal feed as the original did
//! ends on one. A line the firmware must read, parse and queue for nothing is what the
//! segment budget is about (issue #31: SD and serial streaming cap lines per second), so the
//! lines folded pay for rounded corners.
//!
//! Marlin, Prusa firmware, Klipper and RepRapFirmware all take a move's `F` before the move,
//! and a feed-only `G1` queues no motion, so the fold changes nothing the machine does, as
//! long as nothing between the two lines reads the modal feed. Only lines known not to are
//! crossed: comments, blank lines, `M73` progress, `M117` messages, `M106`/`M107` fans,
//! `M204` accelerations, `G92` and Klipper's `SET_VELOCITY_LIMIT`; anything else (a macro, a
//! tool change, `M600`, a homing) ends the search and the feed line stays. A `G0` feed is
//! folded only into a `G0`, a `G1` feed into a `G1`, `G2` or `G3`: Marlin built with
//! `VARIABLE_G0_FEEDRATE` keeps a separate feed for `G0`. Where the move already has its own
//! `F` (or another feed line of the same command comes first), the feed line is never read and
//! is dropped. Lines with a comment, a line number or a checksum are left as they are.

use crate::gcode::{parse_line, Code, Command, Line, Lines, RawLine};

/// A file with its feed-only lines folded ([`fold`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Folded {
    /// The file as folded.
    pub bytes: Vec<u8>,
    /// The lines removed, every feed line folded or dropped: their numbers in the original
    /// (1-based, ascending). A line `n` of the original is line `n` less those before it in the
    /// folded file ([`Folded::line_in_folded`]).
    pub removed: Vec<u32>,
}

impl Folded {
    /// Lines removed.
    pub fn lines(&self) -> u64 {
        self.removed.len() as u64
    }

    /// The number in the folded file of the original's line `line` (one that is kept).
    pub fn line_in_folded(&self, line: u32) -> u32 {
        line - self.removed.partition_point(|&r| r < line) as u32
    }
}

/// `input` with its feed-only lines folded into the moves that read them, or dropped where
/// none does; `None` where there is none to fold. One pass over the file that parses only the
/// lines starting `G0 F`/`G1 F` and the few after each.
pub fn fold(input: &[u8]) -> Option<Folded> {
    let plan = Plan::of(input);
    if plan.edits.is_empty() {
        return None;
    }
    let mut bytes = input.to_vec();
    plan.apply(&mut bytes);
    Some(Folded {
        bytes,
        removed: plan.removed,
    })
}

/// [`fold`] in place: `bytes` folded without a second copy of them (a rewrite of the 34 MB
/// corpus file is folded so at every write), and the lines removed.
pub(crate) fn fold_in_place(bytes: &mut Vec<u8>) -> u64 {
    let plan = Plan::of(bytes);
    plan.apply(bytes);
    plan.removed.len() as u64
}

/// The edits that fold a file ([`fold`]), owned, so that they can be made in the file itself.
struct Plan {
    /// In order along the file: remove `.1` bytes at `.0`, then write the bytes `.2` of `words`.
    edits: Vec<(usize, usize, std::ops::Range<usize>)>,
    /// The words written (` F6000`): taken from feed lines the edits remove.
    words: Vec<u8>,
    /// The lines removed, ascending ([`Folded::removed`]).
    removed: Vec<u32>,
}

impl Plan {
    fn of(input: &[u8]) -> Self {
        let mut splices = splices(input);
        splices.sort_by_key(|s| s.at);
        let mut words = Vec::new();
        let edits = splices
            .iter()
            .map(|s| {
                let from = words.len();
                if !s.insert.is_empty() {
                    words.extend_from_slice(b" F");
                    words.extend_from_slice(s.insert);
                }
                (s.at, s.remove, from..words.len())
            })
            .collect();
        let removed = splices.iter().filter_map(|s| s.deletes).collect();
        Plan {
            edits,
            words,
            removed,
        }
    }

    /// The edits made in `bytes`, the file they were planned on. Each word goes in after the
    /// feed line it came from was taken out, and is shorter than that line: what is written
    /// never overtakes what is still to be read.
    fn apply(&self, bytes: &mut Vec<u8>) {
        let (mut write, mut read) = (0, 0);
        for (at, remove, word) in &self.edits {
            bytes.copy_within(read..*at, write);
            write += at - read;
            bytes[write..write + word.len()].copy_from_slice(&self.words[word.clone()]);
            write += word.len();
            read = at + remove;
        }
        let end = bytes.len();
        bytes.copy_within(read..end, write);
        bytes.truncate(write + end - read);
    }
}

/// The splices that fold `input`'s feed-only lines ([`fold`]), in the order found.
fn splices(input: &[u8]) -> Vec<Splice<'_>> {
    let mut splices = Vec::new();
    let mut pending: Option<Feed<'_>> = None;
    for raw in Lines::new(input) {
        if pending.is_none() && !starts_feed(raw.text) {
            continue;
        }
        let Ok(line) = parse_line(raw.text) else {
            pending = None;
            continue;
        };
        if let Some(feed) = Feed::of(&line, &raw) {
            if pending.is_some_and(|p| p.code.is(b'G', feed.code.number)) {
                // Two feeds of one command in a row: the first is never read.
                splices.extend(pending.map(|p| p.dropped()));
            }
            pending = Some(feed);
            continue;
        }
        let Some(feed) = pending else {
            continue;
        };
        if crosses(&line) {
            continue;
        }
        pending = None;
        if let Some(splice) = feed.into_move(&line, &raw) {
            splices.extend(splice);
        }
    }
    splices
}

/// Whether `text` starts like a feed-only line: `G0 F` or `G1 F` (the parse decides).
fn starts_feed(text: &[u8]) -> bool {
    text.starts_with(b"G1 F") || text.starts_with(b"G0 F")
}

/// Whether the line between a feed line and its move leaves the modal feed unread.
pub(crate) fn crosses(line: &Line<'_>) -> bool {
    match line.command {
        Command::None => true,
        Command::Code(c) => [
            (b'M', 73),
            (b'M', 117),
            (b'M', 106),
            (b'M', 107),
            (b'M', 204),
            (b'G', 92),
        ]
        .iter()
        .any(|&(letter, number)| c.is(letter, number)),
        Command::Extended(name) => name.eq_ignore_ascii_case(b"SET_VELOCITY_LIMIT"),
        Command::Bare => false,
    }
}

/// Whether the line sets the modal feed a `G1` reads: a `G1`, `G2` or `G3` with an `F` word.
pub(crate) fn sets_feed(line: &Line<'_>) -> bool {
    line.code().is_some_and(reads_g1_feed) && line.params.get(b'F').is_some()
}

/// Whether a move of `code` reads the modal feed a `G1` sets: a `G1`, `G2` or `G3` (not a
/// `G0`: Marlin built with `VARIABLE_G0_FEEDRATE` keeps its feed apart).
fn reads_g1_feed(code: Code) -> bool {
    code.is_motion() && !code.is(b'G', 0)
}

/// A feed-only line waiting for the move that reads it.
#[derive(Debug, Clone, Copy)]
struct Feed<'a> {
    code: Code,
    /// Its line number.
    line: u32,
    /// The whole line, terminator included, as bytes of the input.
    span: (usize, usize),
    /// The `F` word's number as written.
    number: &'a [u8],
}

impl<'a> Feed<'a> {
    /// The line as a feed-only `G0`/`G1`: its only word `F`, no comment, line number or
    /// checksum.
    fn of(line: &Line<'_>, raw: &RawLine<'a>) -> Option<Self> {
        let code = line.code().filter(|c| c.is(b'G', 0) || c.is(b'G', 1))?;
        let plain = line.comment.is_none() && line.line_number.is_none();
        let only_f = line.params.numbered() == 1 << (b'F' - b'A') && !line.params.has_bare_word();
        if !(plain && line.checksum.is_none() && only_f && line.text.is_empty()) {
            return None;
        }
        let at = raw.text.iter().position(|&b| b == b'F' || b == b'f')?;
        let word = &raw.text[at + 1..];
        let end = word
            .iter()
            .position(|b| b.is_ascii_whitespace())
            .unwrap_or(word.len());
        let end_of_line = raw.offset + raw.text.len() + raw.terminator.len();
        Some(Feed {
            code,
            line: raw.number,
            span: (raw.offset, end_of_line),
            number: &word[..end],
        })
    }

    /// The splice that removes the line.
    fn dropped(self) -> Splice<'a> {
        Splice {
            at: self.span.0,
            remove: self.span.1 - self.span.0,
            insert: &[],
            deletes: Some(self.line),
        }
    }

    /// The splices that fold this feed into `line`, the next line that reads the modal feed:
    /// none where it is not a move of the same feed, or has a comment, line number or
    /// checksum; the feed line dropped alone where it has its own `F`.
    fn into_move(self, line: &Line<'_>, raw: &RawLine<'_>) -> Option<[Splice<'a>; 2]> {
        let code = line.code()?;
        let same = match self.code.number {
            0 => code.is(b'G', 0),
            _ => reads_g1_feed(code),
        };
        let plain = line.comment.is_none() && line.line_number.is_none();
        if !same || !plain || line.checksum.is_some() {
            return None;
        }
        let end = raw.offset + raw.text.trim_ascii_end().len();
        let insert: &[u8] = if line.params.get(b'F').is_some() {
            &[]
        } else {
            self.number
        };
        Some([
            self.dropped(),
            Splice {
                at: end,
                remove: 0,
                insert,
                deletes: None,
            },
        ])
    }
}

/// An edit of the input's bytes: `remove` bytes from `at`, then ` F` and `insert` written
/// there (nothing where `insert` is empty).
#[derive(Debug, Clone, Copy)]
struct Splice<'a> {
    at: usize,
    remove: usize,
    insert: &'a [u8],
    /// The line it deletes, if it deletes one.
    deletes: Option<u32>,
}

#[cfg(test)]
mod tests;
