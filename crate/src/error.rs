//! Typed errors and warnings.
//!
//! Every problem found in a G-code file is tied to a 1-based line and column so that a user
//! can jump to it in an editor. In lenient mode (the default) problems become [`Warning`]s and
//! the offending line is passed through untouched; in strict mode the first one is returned as
//! an [`Error`].

use serde::Serialize;

/// What went wrong, independent of where.
#[derive(Debug, Clone, PartialEq, thiserror::Error, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum ErrorKind {
    /// A word letter was followed by something that is not a number (`X1.2.3`, `Yabc`).
    #[error("invalid number after '{letter}'")]
    InvalidNumber {
        /// The word letter, upper case.
        letter: char,
    },
    /// A number that overflows to infinity or is spelled `nan`/`inf`.
    #[error("non-finite number after '{letter}'")]
    NonFiniteNumber {
        /// The word letter, upper case.
        letter: char,
    },
    /// A byte that has no meaning in G-code outside a comment.
    #[error("unexpected character {found:?}")]
    UnexpectedCharacter {
        /// The offending character (bytes above 0x7f are shown as U+FFFD).
        found: char,
    },
    /// A `( ...` comment that is never closed on its line.
    #[error("unclosed '(' comment")]
    UnclosedComment,
    /// `*nn` does not match the XOR of the bytes before it.
    #[error("checksum mismatch: line says {found}, computed {computed}")]
    ChecksumMismatch {
        /// The checksum written in the line.
        found: u32,
        /// The checksum computed from the line.
        computed: u8,
    },
    /// More words on one line than the parser keeps (a hostile or corrupted line).
    #[error("too many words on one line (more than {max})")]
    TooManyWords {
        /// The limit.
        max: usize,
    },
    /// The same word given twice (`G1 X1 X2`); the last one wins in lenient mode.
    #[error("word '{letter}' given twice")]
    DuplicateWord {
        /// The repeated letter.
        letter: char,
    },
    /// An arc whose geometry is impossible (zero radius, an `R` arc shorter than its chord...).
    #[error("invalid arc: {reason}")]
    InvalidArc {
        /// Why.
        reason: &'static str,
    },
    /// The file is UTF-16 encoded (G-code is ASCII / UTF-8).
    #[error("file is UTF-16 encoded; G-code must be ASCII or UTF-8 (re-save it as UTF-8)")]
    Utf16,
    /// The input is not text (NUL bytes in the middle of a line).
    #[error("binary data (NUL byte) in a G-code line")]
    Binary,
    /// A line longer than the parser accepts for a command (comments may be any length).
    #[error("command line longer than {max} bytes")]
    LineTooLong {
        /// The limit.
        max: usize,
    },
    /// An option value is out of range.
    #[error("invalid option: {reason}")]
    InvalidOption {
        /// Why.
        reason: &'static str,
    },
    /// A line of the printer's settings (`machine_gcode`, Marlin's `M503` text) is not G-code.
    #[error("machine settings, line {line}: {reason}")]
    MachineSettings {
        /// 1-based line of the settings text.
        line: u32,
        /// Why, with the line.
        reason: String,
    },
    /// Tool-orientation smoothing was given a file whose rotary axes never move: a 3-axis
    /// toolpath (or the wrong kinematic model's letters), with a constant tool vector.
    #[error(
        "no {first}/{second} rotary motion in the file: the tool vector is constant, there is \
         nothing to smooth (a 3-axis toolpath, or the wrong --kinematics / `kinematics.model`)"
    )]
    NoRotaryMotion {
        /// The first rotary axis letter of the kinematic model.
        first: char,
        /// The second rotary axis letter.
        second: char,
    },
    /// Data handed between the two halves of an analysis run apart (the playground's two
    /// workers) was cut short or garbled.
    #[error("analysis data between workers is damaged: {reason}")]
    Transfer {
        /// Why.
        reason: &'static str,
    },
    /// The file has nothing of the kind an optimizer rewrites (no sparse infill for the infill
    /// search): the file is fine, the optimizer has no work on it.
    #[error("nothing to regenerate: {reason}")]
    NothingToRegenerate {
        /// What the file lacks.
        reason: &'static str,
    },
    /// The job was cancelled by the caller.
    #[error("cancelled")]
    Cancelled,
}

/// An error tied to its position in the input. Shown as `line L, column C: what`, the
/// position left out where it is 0 (an error about the whole file or the options).
#[derive(Debug, Clone, PartialEq, thiserror::Error, Serialize)]
#[error("{}{kind}", Position(*.line, *.column))]
pub struct Error {
    /// 1-based line number in the file (0 when not tied to a line).
    pub line: u32,
    /// 1-based column (byte offset in the line + 1; 0 when not tied to a column).
    pub column: u32,
    /// What went wrong.
    pub kind: ErrorKind,
}

impl Error {
    /// An error at `line`/`column`.
    pub fn new(line: u32, column: u32, kind: ErrorKind) -> Self {
        Self { line, column, kind }
    }
}

/// The `line L, column C: ` prefix of an [`Error`], each part only where it is known.
struct Position(u32, u32);

impl core::fmt::Display for Position {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match (self.0, self.1) {
            (0, _) => Ok(()),
            (line, 0) => write!(f, "line {line}: "),
            (line, column) => write!(f, "line {line}, column {column}: "),
        }
    }
}

/// A non-fatal problem, reported with its line so the user can look at it.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[cfg_attr(test, derive(ts_rs::TS))]
#[cfg_attr(not(target_arch = "wasm32"), derive(serde::Deserialize))]
pub struct Warning {
    /// 1-based line number (0 for file-level remarks).
    pub line: u32,
    /// Human-readable message.
    pub message: String,
}

impl From<&Error> for Warning {
    fn from(e: &Error) -> Self {
        let message = match e.column {
            0 => e.kind.to_string(),
            column => format!("column {column}: {}", e.kind),
        };
        Warning {
            line: e.line,
            message,
        }
    }
}

/// Collects warnings with a cap, so that a hostile file with millions of bad lines produces a
/// bounded report (the count of dropped warnings is kept).
#[derive(Debug, Default, Clone)]
pub struct Warnings {
    list: Vec<Warning>,
    dropped: u64,
}

impl Warnings {
    /// Most warnings kept in a report; the rest are only counted.
    pub const MAX_KEPT: usize = 1000;

    /// Adds a warning (or counts it once the cap is reached).
    pub fn push(&mut self, line: u32, message: impl Into<String>) {
        if self.list.len() < Self::MAX_KEPT {
            self.list.push(Warning {
                line,
                message: message.into(),
            });
        } else {
            self.dropped += 1;
        }
    }

    /// Adds a positioned error as a warning.
    pub fn push_error(&mut self, e: &Error) {
        if self.list.len() < Self::MAX_KEPT {
            self.list.push(Warning::from(e));
        } else {
            self.dropped += 1;
        }
    }

    /// The kept warnings, in file order.
    pub fn list(&self) -> &[Warning] {
        &self.list
    }

    /// How many warnings were counted but not kept.
    pub fn dropped(&self) -> u64 {
        self.dropped
    }

    /// Splits into the kept list and the dropped count.
    pub fn into_parts(self) -> (Vec<Warning>, u64) {
        (self.list, self.dropped)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_message_names_only_the_position_known() {
        let kind = || ErrorKind::InvalidNumber { letter: 'X' };
        assert_eq!(
            Error::new(4, 7, kind()).to_string(),
            "line 4, column 7: invalid number after 'X'"
        );
        assert_eq!(
            Error::new(4, 0, kind()).to_string(),
            "line 4: invalid number after 'X'"
        );
        let whole = Error::new(0, 0, ErrorKind::Cancelled);
        assert_eq!(whole.to_string(), "cancelled");
        assert_eq!(
            Warning::from(&Error::new(4, 0, kind())).message,
            kind().to_string()
        );
        assert_eq!(
            Warning::from(&Error::new(4, 7, kind())).message,
            "column 7: invalid number after 'X'"
        );
    }
}
