//! Splitting a byte buffer into lines without copying.
//!
//! A line is the text up to (not including) its terminator, which is `\n`, `\r\n`, or nothing for
//! a last line without a final newline. Text plus terminator of every line, concatenated, is the
//! input again byte for byte: this is what makes lossless rewriting possible.

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
