//! Rewriting the axis words of one motion line, keeping everything else as written.

/// `v · 10^decimals` rounded to an integer (half away from zero), when it is exactly
/// representable; the written value is then exactly `scaled / 10^decimals`.
fn scaled(v: f64, decimals: usize) -> Option<(i64, f64)> {
    const POW10: [f64; 10] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];
    let p = *POW10.get(decimals)?;
    let s = libm::round(v * p);
    (s.is_finite() && s.abs() < 9.0e15).then_some((s as i64, p))
}

/// Formats `v` with `decimals` places, without a sign on zero (`-0.000` → `0.000`).
pub fn format_value(v: f64, decimals: usize) -> String {
    let Some((n, _)) = scaled(v, decimals).filter(|_| decimals > 0) else {
        return format!("{v:.decimals$}");
    };
    let digits = n.unsigned_abs().to_string();
    let mut out = String::with_capacity(digits.len() + decimals + 3);
    if n < 0 {
        out.push('-');
    }
    if digits.len() <= decimals {
        out.push_str("0.");
        out.extend(std::iter::repeat_n('0', decimals - digits.len()));
        out.push_str(&digits);
    } else {
        let (int, frac) = digits.split_at(digits.len() - decimals);
        out.push_str(int);
        if decimals > 0 {
            out.push('.');
            out.push_str(frac);
        }
    }
    out
}

/// The value [`format_value`] writes, as a number.
pub fn rounded(v: f64, decimals: usize) -> f64 {
    match scaled(v, decimals) {
        Some((n, p)) => n as f64 / p,
        None => v,
    }
}

fn is_number_byte(b: u8) -> bool {
    b.is_ascii_digit() || b == b'.' || b == b'-' || b == b'+'
}

/// `text` with the value of each word in `values` (upper-case letter, new number text)
/// replaced where the word is present and appended after the last word where it is not.
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
            while j < code.len() && code.get(j).copied().is_some_and(is_number_byte) {
                j += 1;
            }
            if j > start && !done.get(k).copied().unwrap_or(true) {
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
    fn checksum_is_recomputed() {
        let out = rewrite_line(b"N10 G1 X1 E2*99", &vals(&[(b'X', "5")]));
        let cs = crate::gcode::line::checksum(b"N10 G1 X5 E2");
        assert_eq!(out, format!("N10 G1 X5 E2*{cs}").into_bytes());
    }

    #[test]
    fn negative_zero_is_written_as_zero() {
        assert_eq!(format_value(-0.0004, 3), "0.000");
        assert_eq!(format_value(-1.0004, 3), "-1.000");
        assert_eq!(format_value(-0.0456, 3), "-0.046");
        assert_eq!(format_value(2912.7, 3), "2912.700");
        assert_eq!(format_value(1e300, 2).len(), 304);
    }

    #[test]
    fn rounded_is_what_is_written() {
        for v in [-25.4624999, 0.0005, -0.0005, 38.4795, 1234.56789, -2689.7] {
            for d in 1..=6 {
                let text = format_value(v, d);
                assert_eq!(text.parse::<f64>().ok(), Some(rounded(v, d)), "{v} {d}");
            }
        }
    }
}
