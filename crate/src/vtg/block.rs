//! The G-code block a rewritten path is written as: one `G1` per new point (or one `G2`/`G3`
//! per run of points on a circle, [`super::arcs`]), filament as the original's extrusion mode
//! writes it, feed rates only where they change, the original's annotation lines back in place,
//! and the modal feed left where the original left it.

use std::fmt::Write as _;

use super::arcs::Piece;
use crate::gcode::number::{least_positive, push_trimmed, rounded};
use crate::machine::ExtrusionMode;

/// What the block must agree with in the file around it.
#[derive(Debug, Clone)]
pub(crate) struct Frame<'a> {
    /// Where the path starts (the position before its first move).
    pub(crate) start: [f64; 3],
    /// The path climbs along its length (spiral vase): every point keeps a fine Z.
    pub(crate) climbs: bool,
    /// The original's extrusion mode.
    pub(crate) mode: ExtrusionMode,
    /// Logical E before the path (absolute mode).
    pub(crate) e_before: f64,
    /// The original's last `E` word (absolute mode: the block ends on it exactly).
    pub(crate) last_e_word: f64,
    /// Filament of the whole path (relative mode: the rounded words add up to it).
    pub(crate) total_e: f64,
    /// The modal feed before the path, mm/min (`None`: no `F` so far, none is written).
    pub(crate) f_before: Option<f64>,
    /// The modal feed the original leaves behind, mm/min.
    pub(crate) f_after: Option<f64>,
    /// Whether anything reads that feed before the next move sets its own
    /// ([`super::source::MoveSource::feed_overridden`]): else the block need not restore it,
    /// and saves the line.
    pub(crate) f_after_read: bool,
    /// Annotation lines with the filament pushed where each stood; each is written before the
    /// first new point past it.
    pub(crate) notes: Vec<(f64, &'a str)>,
}

/// The block for new `points` after the start (filament `e` from the path start to each), as
/// `pieces` (each ending at point `end`, counted with the start point as 0).
pub(crate) fn write(frame: &Frame<'_>, points: &[[f64; 3]], e: &[f64], pieces: &[Piece]) -> String {
    let mut text = String::with_capacity(pieces.len() * 40);
    let mut z_now = frame.start[2];
    // A path whose Z changes along it (spiral vase, FullControl designs) keeps a Z on every
    // point, finely enough that each step still climbs: written to 3 decimals, a slow spiral's
    // short steps would come out flat, and the file would read as a stack of flat layers.
    let (z_step, z_decimals) = if frame.climbs { (5e-6, 5) } else { (5e-4, 3) };
    let mut f_now = frame.f_before;
    let mut e_written = 0.0; // relative mode: rounded running total written so far
    let mut from_xy = [rounded(frame.start[0], 3), rounded(frame.start[1], 3)];
    let mut notes = frame.notes.iter().peekable();
    for (k, piece) in pieces.iter().enumerate() {
        let w = piece.end.saturating_sub(1);
        let (Some(p), Some(&ek)) = (points.get(w), e.get(w)) else {
            break;
        };
        while let Some((_, note)) = notes.next_if(|&&(at, _)| ek > at + 1e-12) {
            if !text.is_empty() {
                text.push('\n');
            }
            text.push_str(note);
        }
        if !text.is_empty() {
            text.push('\n');
        }
        text.push_str(match piece.arc {
            None => "G1 X",
            Some(a) if a.ccw => "G3 X",
            Some(_) => "G2 X",
        });
        push_trimmed(&mut text, p[0], 3);
        text.push_str(" Y");
        push_trimmed(&mut text, p[1], 3);
        if (p[2] - z_now).abs() > z_step {
            text.push_str(" Z");
            push_trimmed(&mut text, p[2], z_decimals);
            z_now = p[2];
        }
        if let Some(a) = piece.arc {
            // Offsets from the start as written, so the firmware's centre is the fitted one.
            text.push_str(" I");
            push_trimmed(&mut text, rounded(a.center[0] - from_xy[0], 4), 4);
            text.push_str(" J");
            push_trimmed(&mut text, rounded(a.center[1] - from_xy[1], 4), 4);
        }
        from_xy = [rounded(p[0], 3), rounded(p[1], 3)];
        let last = k + 1 == pieces.len();
        push_e(&mut text, frame, ek, last, &mut e_written);
        // No F is written into a file that has none yet.
        if let Some(now) = f_now {
            let f = writable_feed(piece.feed * 60.0, 1);
            if (now - f).abs() > 0.05 {
                text.push_str(" F");
                push_trimmed(&mut text, f, 1);
                f_now = Some(f);
            }
        }
    }
    for (_, note) in notes {
        text.push('\n');
        text.push_str(note);
    }
    // Leave the modal feed where the original left it, where anything reads it.
    if let (Some(now), Some(after), true) = (f_now, frame.f_after, frame.f_after_read) {
        if (now - after).abs() > 1e-9 {
            text.push_str("\nG1 F");
            push_trimmed(&mut text, writable_feed(after, 3), 3);
        }
    }
    text
}

/// The feed `f` (mm/min) as written with `decimals` places, never `F0` for a positive one
/// ([`least_positive`]).
fn writable_feed(f: f64, decimals: usize) -> f64 {
    rounded(least_positive(f, decimals), decimals)
}

/// The ` E` word of the point with filament `ek` from the path start (`last`: the block's last
/// point), as the frame's extrusion mode writes it: absolute mode ends on the original's last
/// word exactly, relative mode writes differences of rounded running totals (`e_written`) so
/// the words add up to the path's filament.
fn push_e(text: &mut String, frame: &Frame<'_>, ek: f64, last: bool, e_written: &mut f64) {
    text.push_str(" E");
    match frame.mode {
        ExtrusionMode::Absolute if last => {
            let _ = write!(text, "{}", frame.last_e_word);
        }
        ExtrusionMode::Absolute => push_trimmed(text, frame.e_before + ek, 5),
        ExtrusionMode::Relative => {
            let target = if last { frame.total_e } else { ek };
            let written = rounded(target, 5);
            push_trimmed(text, written - *e_written, 5);
            *e_written = written;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::writable_feed;

    #[test]
    fn a_positive_feed_is_never_written_as_zero() {
        assert_eq!(writable_feed(0.026, 1), 0.1);
        assert_eq!(writable_feed(1e-49, 3), 0.001);
        assert_eq!(writable_feed(1234.56, 1), 1234.6);
        assert_eq!(writable_feed(0.04, 3), 0.04);
        // Not positive: as it is (the firmware ignores it, as it ignored the original's).
        assert_eq!(writable_feed(-12.0, 1), -12.0);
        assert_eq!(writable_feed(0.0, 1), 0.0);
    }
}
