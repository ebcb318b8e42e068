//! Rewriting the axis words of one motion line, keeping everything else as written.

pub use crate::gcode::number::{fixed as format_value, rounded};

/// `text` with the value of each word in `values` (upper-case letter, new number text)
/// replaced where the word is present (with or without a number) and appended after the last
/// word where it is not.
/// Comments and every other word stay as written; a `*nn` checksum is recomputed.
pub fn rewrite_line(text: &[u8], values: &[(u8, String)]) -> Vec<u8> {
    let comment_at = text
        .iter()
        .position(|&b| b == b';' || b == b'(')
        .unwrap_or(text.len());
    let (code_all, comment) = text.split_at(comment_at);
    let star = code_all.iter().position(|&b| b == b'*');
    let code = match star {
        Some(i) => code_all.get(..i).unwrap_or(code_all),
        None => code_all,
    };
    let mut done = vec![false; values.len()];
    let mut out = Vec::with_capacity(text.len() + 16);
    let mut i = 0usize;
    while i < code.len() {
        let b = code.get(i).copied().unwrap_or(b' ');
        let slot = values
            .iter()
            .position(|(l, _)| *l == b.to_ascii_uppercase());
        if let Some(k) = slot.filter(|_| b.is_ascii_alphabetic()) {
            let mut j = i + 1;
            while j < code.len()
                && code
                    .get(j)
                    .copied()
                    .is_some_and(|c| c == b' ' || c == b'\t')
            {
                j += 1;
            }
            let start = j;
            // The number exactly as the parser reads it (`Y-0e+40` is one number after an
            // upper-case letter), so no part of it is left behind the new value.
            j += crate::gcode::line::scan_number(
                code.get(start..).unwrap_or_default(),
                b.is_ascii_uppercase(),
            );
            if j == start {
                // A word without a number (`Z` in `G1 X5 Z E2`): it is replaced too, keeping
                // the blank after it, or the line would carry the letter twice.
                j = i + 1;
            }
            if !done.get(k).copied().unwrap_or(true) {
                out.push(b);
                if let Some((_, v)) = values.get(k) {
                    out.extend_from_slice(v.as_bytes());
                }
                if let Some(d) = done.get_mut(k) {
                    *d = true;
                }
                i = j;
                continue;
            }
        }
        out.push(b);
        i += 1;
    }
    // Missing words go after the last word, before trailing blanks and the comment.
    let keep = out
        .iter()
        .rposition(|b| !b.is_ascii_whitespace())
        .map_or(0, |p| p + 1);
    let tail: Vec<u8> = out.split_off(keep);
    for ((letter, v), d) in values.iter().zip(&done) {
        if !d {
            out.push(b' ');
            out.push(*letter);
            out.extend_from_slice(v.as_bytes());
        }
    }
    if star.is_some() {
        let cs = crate::gcode::line::checksum(&out);
        out.extend_from_slice(format!("*{cs}").as_bytes());
    }
    out.extend_from_slice(&tail);
    out.extend_from_slice(comment);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vals(v: &[(u8, &str)]) -> Vec<(u8, String)> {
        v.iter().map(|(l, s)| (*l, s.to_string())).collect()
    }

    #[test]
    fn replaces_and_appends() {
        let out = rewrite_line(
            b"G1 X-25.462 Y-6.227 Z38.479 B-6.000 C-4.775 E1.290 ; keep",
            &vals(&[
                (b'X', "1.000"),
                (b'B', "2.000"),
                (b'C', "-3.500"),
                (b'A', "0.5"),
            ]),
        );
        assert_eq!(
            out,
            b"G1 X1.000 Y-6.227 Z38.479 B2.000 C-3.500 E1.290 A0.5 ; keep".to_vec()
        );
    }

    #[test]
    fn a_word_without_a_number_is_replaced_not_repeated() {
        let out = rewrite_line(b"G1 X-25 Z E12", &vals(&[(b'X', "1"), (b'Z', "0.3")]));
        assert_eq!(out, b"G1 X1 Z0.3 E12".to_vec());
        let out = rewrite_line(b"G1 X-25 Z", &vals(&[(b'Z', "0.3")]));
        assert_eq!(out, b"G1 X-25 Z0.3".to_vec());
    }

    #[test]
    fn a_number_with_an_exponent_is_replaced_whole() {
        let out = rewrite_line(b"G1 X1 Y-0e+40 E2", &vals(&[(b'Y', "0.182")]));
        assert_eq!(out, b"G1 X1 Y0.182 E2".to_vec());
        // Upper-case E is never an exponent: the extrusion word stays.
        let out = rewrite_line(b"G1X10E-2", &vals(&[(b'X', "5")]));
        assert_eq!(out, b"G1X5E-2".to_vec());
    }

    #[test]
    fn checksum_is_recomputed() {
        let out = rewrite_line(b"N10 G1 X1 E2*99", &vals(&[(b'X', "5")]));
        let cs = crate::gcode::line::checksum(b"N10 G1 X5 E2");
        assert_eq!(out, format!("N10 G1 X5 E2*{cs}").into_bytes());
    }
}
