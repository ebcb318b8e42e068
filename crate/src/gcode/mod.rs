//! The G-code engine's text layer: lines, words, slicer dialects and lossless writing.
//!
//! Everything here borrows from the input buffer; a parsed line costs no allocation.

pub mod dialect;
pub mod line;
pub mod lines;
pub mod number;
pub mod writer;

pub use dialect::{
    classify_comment, feature_kind, FeatureKind, LayerMarkerKind, Marker, SlicerInfo,
};
pub use line::{parse_line, parse_line_into, Code, Command, Line, LineError, Params};
pub use lines::{looks_like_utf16, Lines, RawLine};
pub use writer::{apply_edits, write_with_edits, Edit};

use crate::error::{Error, ErrorKind, Warnings};

/// How to treat malformed lines.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Strictness {
    /// A malformed line becomes a warning with its line number and is passed through.
    #[default]
    Lenient,
    /// The first malformed line is an error.
    Strict,
}

/// Parses every line of `input`, calling `each` with the raw line and its parse (`None` for a
/// malformed line in lenient mode, after recording a warning) and the warning list.
///
/// This is the streaming entry point shared by analysis, rewriting and the optimisers.
pub fn for_each_line<'a, F>(
    input: &'a [u8],
    strictness: Strictness,
    warnings: &mut Warnings,
    mut each: F,
) -> Result<(), Error>
where
    F: FnMut(&RawLine<'a>, Option<&Line<'a>>, &mut Warnings) -> Result<(), Error>,
{
    check_encoding(input)?;
    let mut line = Line::default();
    let mut lines = Lines::new(input);
    loop {
        // Plain G-code lines, nearly all of a file, are split and parsed in one pass.
        if let Some(raw) = lines.next_plain(&mut line) {
            each(&raw, Some(&line), warnings)?;
            continue;
        }
        let Some(raw) = lines.next() else {
            break;
        };
        match parse_line_into(raw.text, &mut line) {
            Ok(()) => each(&raw, Some(&line), warnings)?,
            Err(e) => {
                let err = Error::new(raw.number, e.column, e.kind);
                if strictness == Strictness::Strict {
                    return Err(err);
                }
                warnings.push_error(&err);
                each(&raw, None, warnings)?;
            }
        }
    }
    Ok(())
}

/// Lines of `input`: its newlines, and one more where its last line has none.
pub fn file_lines(input: &[u8]) -> u64 {
    let newlines = memchr::memchr_iter(b'\n', input).count() as u64;
    newlines + u64::from(input.last().is_some_and(|&b| b != b'\n'))
}

/// Lines of `input` that start with a `G` command: about as many as the moves a reader will
/// find, for sizing a list of them up front. A list grown by doubling as it goes ends up with
/// up to twice the room it needs (a 34 MB file's 1.09 million moves took 704 MB of list for
/// 367 MB of moves), and copies itself at each step. Lines that start otherwise (`N12 G1`,
/// indented) are not counted: the list then grows as before.
pub fn command_lines(input: &[u8]) -> usize {
    let starts_g = |b: Option<&u8>| matches!(b, Some(b'G' | b'g'));
    let first = usize::from(starts_g(input.first()));
    first
        + memchr::memchr_iter(b'\n', input)
            .filter(|&i| starts_g(input.get(i + 1)))
            .count()
}

/// Rejects inputs that are not G-code text at all (UTF-16). Binary noise is left to the line
/// parser, which reports it line by line.
pub fn check_encoding(input: &[u8]) -> Result<(), Error> {
    if looks_like_utf16(input) {
        return Err(Error::new(1, 1, ErrorKind::Utf16));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    #[test]
    fn command_lines_counts_lines_that_start_with_g() {
        let text = b"G28\n; G1 in a comment\nG1 X1\ng1 x2\n  G1 X3\nN12 G1 X4\nM104 S200\nG92 E0";
        assert_eq!(super::command_lines(text), 4);
        assert_eq!(super::command_lines(b""), 0);
        assert_eq!(super::command_lines(b"\n\n"), 0);
    }
}
