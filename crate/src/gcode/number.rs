//! Writing numbers into G-code: a fixed number of decimals, by integer arithmetic.
//!
//! Every optimiser writes millions of coordinates; `format!("{v:.3}")` goes through the general
//! float formatter and a heap string per number. Scaling by `10^decimals`, rounding half away
//! from zero and printing the integer gives the same digits (for every value whose scaled form
//! fits an `i64` exactly; larger ones fall back to the formatter) several times faster, and lets
//! the caller know exactly which number it wrote ([`rounded`]). Zero is never written with a sign
//! (`-0.000` reads as a negative to some firmware parsers and diffs badly).

use std::fmt::Write as _;

const POW10: [f64; 10] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9];

/// `v · 10^decimals` rounded to an integer (half away from zero) and the scale, when the
/// integer is exactly representable; the written value is then exactly `n / 10^decimals`.
fn scaled(v: f64, decimals: usize) -> Option<(i64, f64)> {
    let p = *POW10.get(decimals)?;
    let s = libm::round(v * p);
    (s.is_finite() && s.abs() < 9.0e15).then_some((s as i64, p))
}

/// Appends `v` with exactly `decimals` places (`2912.700`).
pub fn push_fixed(out: &mut String, v: f64, decimals: usize) {
    push(out, v, decimals, false);
}

/// Appends `v` with at most `decimals` places, trailing zeros and a bare point dropped
/// (`2912.7`, `3`).
pub fn push_trimmed(out: &mut String, v: f64, decimals: usize) {
    push(out, v, decimals, true);
}

/// `v` with exactly `decimals` places, as a new string.
pub fn fixed(v: f64, decimals: usize) -> String {
    let mut s = String::with_capacity(16);
    push_fixed(&mut s, v, decimals);
    s
}

/// `v`, or where it is positive but under one unit of the last of `decimals` places, that unit:
/// the least positive number `decimals` places write. A feed rate written as `F0` is no feed at
/// all to Marlin (it keeps the one before), not a slow one.
pub fn least_positive(v: f64, decimals: usize) -> f64 {
    if v > 0.0 {
        v.max(0.1f64.powi(decimals as i32))
    } else {
        v
    }
}

/// The value [`push_fixed`] and [`push_trimmed`] write, as a number.
pub fn rounded(v: f64, decimals: usize) -> f64 {
    match scaled(v, decimals) {
        Some((n, p)) => n as f64 / p,
        None => v,
    }
}

fn push(out: &mut String, v: f64, decimals: usize, trim: bool) {
    let Some((n, _)) = scaled(v, decimals) else {
        // Huge, non-finite or more than nine places: the general formatter.
        let start = out.len();
        let _ = write!(out, "{v:.decimals$}");
        if trim {
            trim_zeros(out, start);
        }
        return;
    };
    if n < 0 {
        out.push('-');
    }
    // Digits of |n|, least significant first, padded so there is at least one integer digit.
    let mut digits = [b'0'; 24];
    let mut len = 0;
    let mut a = n.unsigned_abs();
    while a > 0 || len <= decimals {
        digits[len] = b'0' + (a % 10) as u8;
        a /= 10;
        len += 1;
    }
    let mut keep = 0; // fraction digits kept (from the most significant)
    if trim {
        keep = (0..decimals)
            .find(|&i| digits[i] != b'0')
            .map_or(0, |i| decimals - i);
    }
    let frac = if trim { keep } else { decimals };
    for &d in digits[decimals..len].iter().rev() {
        out.push(char::from(d));
    }
    if frac > 0 {
        out.push('.');
        for &d in digits[decimals - frac..decimals].iter().rev() {
            out.push(char::from(d));
        }
    }
}

/// Drops trailing fraction zeros (and then the point) from `out[start..]`, and the sign of a
/// zero.
fn trim_zeros(out: &mut String, start: usize) {
    if out[start..].contains('.') {
        while out.ends_with('0') {
            out.pop();
        }
        if out.ends_with('.') {
            out.pop();
        }
    }
    if &out[start..] == "-0" {
        out.truncate(start);
        out.push('0');
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trimmed(v: f64, d: usize) -> String {
        let mut s = String::new();
        push_trimmed(&mut s, v, d);
        s
    }

    #[test]
    fn a_positive_number_is_kept_above_what_rounds_to_zero() {
        assert_eq!(least_positive(0.3, 0), 1.0);
        assert_eq!(least_positive(1e-49, 3), 0.1f64.powi(3));
        assert_eq!(trimmed(least_positive(1e-49, 3), 3), "0.001");
        assert_eq!(least_positive(1800.0, 0), 1800.0);
        assert_eq!(least_positive(-5.0, 1), -5.0);
        assert_eq!(least_positive(0.0, 1), 0.0);
    }

    #[test]
    fn fixed_places() {
        for (v, d, want) in [
            (70.85, 3, "70.850"),
            (-0.0004, 3, "0.000"),
            (-1.0004, 3, "-1.000"),
            (-0.0456, 3, "-0.046"),
            (2912.7, 3, "2912.700"),
            (-2.0, 5, "-2.00000"),
            (0.123456, 5, "0.12346"),
            (-12.3456, 3, "-12.346"),
            (7.5, 0, "8"),
            (-0.4, 0, "0"),
        ] {
            assert_eq!(fixed(v, d), want, "{v} {d}");
        }
        assert_eq!(fixed(1e300, 2).len(), 304);
    }

    #[test]
    fn trimmed_places() {
        for (v, d, want) in [
            (2912.7, 3, "2912.7"),
            (3.0, 3, "3"),
            (-0.0004, 3, "0"),
            (0.00097, 5, "0.00097"),
            (-10.0, 1, "-10"),
            (1800.04, 1, "1800"),
            (0.5, 3, "0.5"),
        ] {
            assert_eq!(trimmed(v, d), want, "{v} {d}");
        }
        assert_eq!(trimmed(-1e300, 3), format!("{:.0}", -1e300));
    }

    #[test]
    fn the_text_is_the_rounded_value_and_agrees_with_the_formatter() {
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        for _ in 0..20_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let v = ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 10f64.powi((x % 12) as i32);
            for d in 0..=6 {
                let text = fixed(v, d);
                assert_eq!(text.parse::<f64>().ok(), Some(rounded(v, d)), "{v} {d}");
                assert_eq!(
                    trimmed(v, d).parse::<f64>().ok(),
                    Some(rounded(v, d)),
                    "{v} {d}"
                );
                // The general formatter rounds half to even on the exact binary value; they
                // differ only on ties, by one unit in the last place (plus the spacing of
                // doubles, for huge values).
                let std: f64 = format!("{v:.d$}").parse().unwrap_or(f64::NAN);
                let unit = 1.0 / 10f64.powi(d as i32) + 4.0 * f64::EPSILON * v.abs();
                assert!((std - rounded(v, d)).abs() <= 1.01 * unit, "{v} {d}");
            }
        }
        for v in [-25.4624999, 0.0005, -0.0005, 38.4795, 1234.56789, -2689.7] {
            for d in 1..=6 {
                assert_eq!(
                    fixed(v, d).parse::<f64>().ok(),
                    Some(rounded(v, d)),
                    "{v} {d}"
                );
            }
        }
    }
}
