//! The progress and time lines slicers write, recognised and rewritten with new times.
//!
//! Each recogniser takes a whole line and answers with the line rewritten for the given
//! times, or `None` when the line is not of its kind. Only whole-line comments and `M73`
//! commands are touched; a setting that merely contains such text (a start script in a
//! config block) is not, because it does not start with the marker.

use std::fmt::Write;

/// Times at one line of the file, s.
#[derive(Debug, Clone, Copy)]
pub(crate) struct At {
    /// Elapsed when the machine reaches the line.
    pub elapsed_s: f64,
    /// The whole print.
    pub total_s: f64,
    /// The first layer, when the file has layers.
    pub first_layer_s: Option<f64>,
}

impl At {
    fn remaining_s(&self) -> f64 {
        (self.total_s - self.elapsed_s).max(0.0)
    }

    /// Percent done, rounded down as slicers write it (100 only at the end).
    fn percent(&self) -> u32 {
        if self.total_s > 0.0 {
            (100.0 * self.elapsed_s / self.total_s)
                .floor()
                .clamp(0.0, 100.0) as u32
        } else {
            100
        }
    }
}

/// What a rewritten line was.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Kind {
    /// An `M73` progress command.
    Progress,
    /// A time comment.
    Comment,
}

/// The line rewritten for `at`, with its kind; `None` if it carries no estimate.
pub(crate) fn rewrite(text: &[u8], at: &At) -> Option<(Kind, String)> {
    let text = std::str::from_utf8(text).ok()?;
    if let Some(line) = m73(text, at) {
        return Some((Kind::Progress, line));
    }
    comment(text, at).map(|line| (Kind::Comment, line))
}

/// `M73 P… R…` (and the silent mode's `Q… S…`): percent done and minutes remaining, the
/// letters and their order kept, a trailing comment kept.
fn m73(text: &str, at: &At) -> Option<String> {
    let rest = text.strip_prefix("M73")?;
    if !(rest.is_empty() || rest.starts_with([' ', '\t', ';'])) {
        return None;
    }
    let (words, comment) = match rest.find(';') {
        Some(i) => (&rest[..i], Some(&rest[i..])),
        None => (rest, None),
    };
    let minutes = (at.remaining_s() / 60.0).round() as u64;
    let mut out = String::from("M73");
    for word in words.split_whitespace() {
        let letter = word.as_bytes().first().map(u8::to_ascii_uppercase);
        match letter {
            Some(b'P') | Some(b'Q') => write!(out, " {}{}", &word[..1], at.percent()).ok()?,
            Some(b'R') | Some(b'S') => write!(out, " {}{minutes}", &word[..1]).ok()?,
            _ => write!(out, " {word}").ok()?,
        }
    }
    if let Some(c) = comment {
        out.push(' ');
        out.push_str(c);
    }
    Some(out)
}

/// The time comments of PrusaSlicer and its forks, Cura, ideaMaker and Kiri:Moto.
fn comment(text: &str, at: &At) -> Option<String> {
    const PRUSA: [&str; 2] = [
        "; estimated printing time (normal mode) = ",
        "; estimated printing time (silent mode) = ",
    ];
    const PRUSA_FIRST: [&str; 2] = [
        "; estimated first layer printing time (normal mode) = ",
        "; estimated first layer printing time (silent mode) = ",
    ];
    for p in PRUSA {
        if text.starts_with(p) {
            return Some(format!("{p}{}", dhms(at.total_s)));
        }
    }
    for p in PRUSA_FIRST {
        if text.starts_with(p) {
            return Some(format!("{p}{}", dhms(at.first_layer_s?)));
        }
    }
    let number = |prefix: &str| {
        text.strip_prefix(prefix)
            .filter(|v| v.trim().parse::<f64>().is_ok())
            .map(|_| ())
    };
    if number(";TIME:").is_some() {
        return Some(format!(";TIME:{}", at.total_s.round() as u64));
    }
    if number(";TIME_ELAPSED:").is_some() {
        return Some(format!(";TIME_ELAPSED:{:.6}", at.elapsed_s));
    }
    if number(";PRINTING_TIME:").is_some() {
        return Some(format!(";PRINTING_TIME: {}", at.elapsed_s.round() as u64));
    }
    if number(";REMAINING_TIME:").is_some() {
        return Some(format!(
            ";REMAINING_TIME: {}",
            at.remaining_s().round() as u64
        ));
    }
    if let Some(prefix) = simplify3d_build_time(text) {
        let minutes = (at.total_s / 60.0).round() as u64;
        return Some(format!(
            "{prefix}{} hours {} minutes",
            minutes / 60,
            minutes % 60
        ));
    }
    if text.starts_with("; --- print time: ") && text.ends_with("s ---") {
        return Some(format!(
            "; --- print time: {}s ---",
            at.total_s.round() as u64
        ));
    }
    None
}

/// Simplify3D's `;   Build Time: 1 hours 2 minutes` (`Build time` before version 5): the text
/// up to the time, if the line is one.
fn simplify3d_build_time(text: &str) -> Option<&str> {
    let body = text.strip_prefix(';')?.trim_start();
    let label = body.get(..11)?;
    if !label.eq_ignore_ascii_case("build time:") || !body.ends_with("minutes") {
        return None;
    }
    let cut = text.len() - body.len() + 11;
    let prefix = &text[..cut];
    Some(if text[cut..].starts_with(' ') {
        &text[..cut + 1]
    } else {
        prefix
    })
}

/// PrusaSlicer's `1d 2h 3m 4s` form, leading zero units left out.
pub(crate) fn dhms(secs: f64) -> String {
    let s = secs.max(0.0).round() as u64;
    let (d, h, m, s) = (s / 86_400, s / 3_600 % 24, s / 60 % 60, s % 60);
    if d > 0 {
        format!("{d}d {h}h {m}m {s}s")
    } else if h > 0 {
        format!("{h}h {m}m {s}s")
    } else if m > 0 {
        format!("{m}m {s}s")
    } else {
        format!("{s}s")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const AT: At = At {
        elapsed_s: 600.0,
        total_s: 2400.0,
        first_layer_s: Some(95.4),
    };

    fn line(text: &str) -> Option<String> {
        rewrite(text.as_bytes(), &AT).map(|(_, s)| s)
    }

    #[test]
    fn m73_keeps_its_letters_and_comment() {
        assert_eq!(line("M73 P3 R40").as_deref(), Some("M73 P25 R30"));
        assert_eq!(
            line("M73 Q3 S41 ; silent").as_deref(),
            Some("M73 Q25 S30 ; silent")
        );
        assert_eq!(line("M73 P7").as_deref(), Some("M73 P25"));
        assert_eq!(line("M731 P1"), None);
        assert_eq!(line("G1 X1"), None);
    }

    #[test]
    fn slicer_comments() {
        assert_eq!(
            line("; estimated printing time (normal mode) = 5h 28m 22s").as_deref(),
            Some("; estimated printing time (normal mode) = 40m 0s")
        );
        assert_eq!(
            line("; estimated first layer printing time (silent mode) = 1m").as_deref(),
            Some("; estimated first layer printing time (silent mode) = 1m 35s")
        );
        assert_eq!(line(";TIME:6666").as_deref(), Some(";TIME:2400"));
        assert_eq!(line(";TIME:1489.56").as_deref(), Some(";TIME:2400"));
        assert_eq!(
            line(";TIME_ELAPSED:14.4").as_deref(),
            Some(";TIME_ELAPSED:600.000000")
        );
        assert_eq!(
            line(";PRINTING_TIME: 41").as_deref(),
            Some(";PRINTING_TIME: 600")
        );
        assert_eq!(
            line(";REMAINING_TIME: 704").as_deref(),
            Some(";REMAINING_TIME: 1800")
        );
        assert_eq!(
            line("; --- print time: 806s ---").as_deref(),
            Some("; --- print time: 2400s ---")
        );
        assert_eq!(
            line(";   Build Time: 0 hours 3 minutes").as_deref(),
            Some(";   Build Time: 0 hours 40 minutes")
        );
        assert_eq!(
            line(";   Build time: 2 hours 6 minutes").as_deref(),
            Some(";   Build time: 0 hours 40 minutes")
        );
        // A setting that holds such text, and a placeholder, are not estimates.
        assert_eq!(
            line(";   startingScript,\";TIME:[total_print_time_sec].00\""),
            None
        );
        assert_eq!(line(";TIME:[total_print_time_sec]"), None);
    }

    #[test]
    fn durations() {
        assert_eq!(dhms(19_702.0), "5h 28m 22s");
        assert_eq!(dhms(59.6), "1m 0s");
        assert_eq!(dhms(93_784.0), "1d 2h 3m 4s");
        assert_eq!(dhms(7.0), "7s");
    }
}
