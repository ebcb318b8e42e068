//! Splitting a byte buffer into lines without copying.
//!
//! A line is the text up to (not including) its terminator, which is `\n`, `\r\n`, or nothing for
//! a last line without a final newline. Text plus terminator of every line, concatenated, is the
//! input again byte for byte: this is what makes lossless rewriting possible.

use super::line::{parse_plain_line, Line, MAX_COMMAND_BYTES};

/// One line of the input, borrowed from it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct RawLine<'a> {
    /// 1-based line number.
    pub number: u32,
    /// Byte offset of the line's first byte in the input.
    pub offset: usize,
    /// The line without its terminator.
    pub text: &'a [u8],
    /// `b"\n"`, `b"\r\n"` or `b""` (last line without newline).
    pub terminator: &'a [u8],
}

/// Iterator over the lines of a buffer. Never allocates.
#[derive(Debug, Clone)]
pub struct Lines<'a> {
    input: &'a [u8],
    pos: usize,
    number: u32,
}

impl<'a> Lines<'a> {
    /// Lines of `input`.
    pub fn new(input: &'a [u8]) -> Self {
        Self {
            input,
            pos: 0,
            number: 0,
        }
    }

    /// Byte offset of the next line; equals the input length once exhausted.
    pub fn position(&self) -> usize {
        self.pos
    }

    /// The next line, parsed into `line`, if it is a plain G-code line (see
    /// [`parse_plain_line`]): found and parsed in one pass. `None`, with nothing consumed,
    /// for any other line, which [`Iterator::next`] and [`super::parse_line_into`] then read.
    #[inline]
    pub(crate) fn next_plain(&mut self, line: &mut Line<'a>) -> Option<RawLine<'a>> {
        let rest = self.input.get(self.pos..)?;
        let stop = parse_plain_line(rest, line)?;
        // As `next` splits: `stop` is the newline, or the end of a last line without one.
        let (text, terminator) = if stop < rest.len() {
            let with_cr = stop > 0 && rest[stop - 1] == b'\r';
            let text_end = if with_cr { stop - 1 } else { stop };
            (&rest[..text_end], &rest[text_end..=stop])
        } else {
            (rest, &rest[rest.len()..])
        };
        if text.len() > MAX_COMMAND_BYTES {
            return None;
        }
        let offset = self.pos;
        self.pos += text.len() + terminator.len();
        self.number = self.number.saturating_add(1);
        Some(RawLine {
            number: self.number,
            offset,
            text,
            terminator,
        })
    }
}

impl<'a> Iterator for Lines<'a> {
    type Item = RawLine<'a>;

    #[inline]
    fn next(&mut self) -> Option<RawLine<'a>> {
        let rest = self.input.get(self.pos..)?;
        if rest.is_empty() {
            return None;
        }
        let offset = self.pos;
        self.number = self.number.saturating_add(1);
        let (text, terminator) = match memchr::memchr(b'\n', rest) {
            Some(nl) => {
                let with_cr = nl > 0 && rest[nl - 1] == b'\r';
                let text_end = if with_cr { nl - 1 } else { nl };
                self.pos += nl + 1;
                (&rest[..text_end], &rest[text_end..=nl])
            }
            None => {
                self.pos = self.input.len();
                (rest, &rest[rest.len()..])
            }
        };
        Some(RawLine {
            number: self.number,
            offset,
            text,
            terminator,
        })
    }
}

/// Detects a UTF-16 file by its byte-order mark or by the NUL-every-other-byte pattern of
/// ASCII text stored as UTF-16 without a mark.
pub fn looks_like_utf16(input: &[u8]) -> bool {
    if input.starts_with(&[0xFF, 0xFE]) || input.starts_with(&[0xFE, 0xFF]) {
        return true;
    }
    let probe = &input[..input.len().min(256)];
    if probe.len() < 8 {
        return false;
    }
    let even_nuls = probe.iter().step_by(2).filter(|&&b| b == 0).count();
    let odd_nuls = probe.iter().skip(1).step_by(2).filter(|&&b| b == 0).count();
    let half = probe.len() / 2;
    even_nuls * 10 >= half * 9 || odd_nuls * 10 >= half * 9
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gcode::Line;

    fn concat(input: &[u8]) -> Vec<u8> {
        Lines::new(input)
            .flat_map(|l| l.text.iter().chain(l.terminator.iter()).copied())
            .collect()
    }

    #[test]
    fn splits_lf_crlf_and_missing_final_newline() {
        let input = b"G1 X1\r\nG1 X2\n\nG1 X3";
        let lines: Vec<_> = Lines::new(input).collect();
        assert_eq!(lines.len(), 4);
        assert_eq!(lines[0].text, b"G1 X1");
        assert_eq!(lines[0].terminator, b"\r\n");
        assert_eq!(lines[1].terminator, b"\n");
        assert_eq!(lines[2].text, b"");
        assert_eq!(lines[3].text, b"G1 X3");
        assert_eq!(lines[3].terminator, b"");
        assert_eq!(lines[3].number, 4);
        assert_eq!(lines[3].offset, 14);
        assert_eq!(concat(input), input);
    }

    #[test]
    fn empty_input_has_no_lines() {
        assert_eq!(Lines::new(b"").count(), 0);
        assert_eq!(Lines::new(b"\n").count(), 1);
    }

    #[test]
    fn plain_lines_read_in_one_pass_as_the_general_parser_reads_them() {
        let input = b"G1 X1 Y2\r\nG0X1Y-2.5 E.5 F1800\nG1 X1 X2\nG1 X1 ; c\nG10\nG1.1 X1\n\
G00001 X1\nG12345 X1\ng1 x1\nG1 X1e3\nG1  X1  \t\nG1 X1\r\r\nG1 X 1\nG1 X1(c)\nG1 Xa\n\
G1 X1.2.3\nG1 X0.1234567890123456\nM104 S200\n;G1 X1\n\nG28\nG1 X1\r";
        let reference = Lines::new(input);
        let mut lines = Lines::new(input);
        let mut line = Line::default();
        let mut plain = 0;
        for expected in reference {
            let parsed = super::super::parse_line(expected.text);
            match lines.next_plain(&mut line) {
                Some(raw) => {
                    plain += 1;
                    assert_eq!(raw, expected);
                    // (Compared as printed: a reused line keeps stale values of absent words.)
                    let parsed = parsed.map(|l| format!("{l:?}"));
                    assert_eq!(Ok(format!("{line:?}")), parsed);
                }
                None => assert_eq!(lines.next(), Some(expected)),
            }
        }
        assert_eq!(lines.next(), None);
        assert_eq!(plain, 7);
    }

    #[test]
    fn lone_cr_stays_in_text() {
        let lines: Vec<_> = Lines::new(b"a\rb\n").collect();
        assert_eq!(lines[0].text, b"a\rb");
    }

    #[test]
    fn utf16_detection() {
        assert!(looks_like_utf16(&[0xFF, 0xFE, b'G', 0]));
        let utf16: Vec<u8> = "G1 X10 Y20\nG1 X5\n"
            .encode_utf16()
            .flat_map(|u| u.to_le_bytes())
            .collect();
        assert!(looks_like_utf16(&utf16));
        assert!(!looks_like_utf16(b"G1 X10 Y20\nG1 X5\n"));
    }
}
