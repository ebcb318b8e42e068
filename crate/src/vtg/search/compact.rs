//! Paths without sharp corners written with fewer lines, to pay for the corners rounded
//! elsewhere (the file's line budget, [`super::budget`]): with arcs where the firmware runs
//! them, and with nearly collinear lines joined ([`super::straights`]) everywhere.
//!
//! A slicer writes a curved wall as a chain of short chords; ArcWelder's observation is that
//! most of those chains lie on circles within a few hundredths of a millimetre and can be sent
//! as one `G2`/`G3` each (it cuts 55–76 % of the lines of real files). Here the original's own
//! points are fitted, within `Tuning::compact_share` of the tolerance, and nothing else
//! changes: the filament of each stretch, the feeds, the notes between the lines. Such a path
//! is offered as a rewrite that removes no corners and saves lines, written only where the
//! budget needs its lines and the time and energy other rewrites save pay for what it costs
//! through the firmware's own arc cutting (a little either way), and that stays within the
//! tolerance of the original both ways. Where no run lies on a circle, or the firmware runs no
//! arcs, chains of lines that bend by less than the same share are joined instead.

use super::budget::Outcome;
use super::rewrite::{edits, fit_arcs, lines_added, notes, PlanContext, Polyline, Rewritten};
use crate::path::PathMove;
use crate::vec3::{norm, sub};
use crate::vtg::arcs::Piece;
use crate::vtg::block::{self, Frame};
use crate::vtg::smooth::Settings;
use crate::vtg::source::MoveSource;
use crate::vtg::tuning::TUNING;

/// The path `run` (its lines `src`) with its runs on a circle written as arcs where
/// `settings.arcs`, and its nearly collinear lines joined, if that saves lines; what it adds in
/// time and energy comes with it, for the budget to pay.
pub(super) fn compact_path(
    input: &[u8],
    run: &[PathMove],
    src: &[MoveSource],
    settings: &Settings,
    machine: &PlanContext<'_>,
) -> Option<Outcome> {
    let o = Polyline::of(run, src)?;
    let (pts, e, feed) = (&o.pts, &o.e, &o.feed);
    let fit = TUNING.compact_share * settings.tolerance_mm;
    let arcs = settings
        .arcs
        .then(|| fit_arcs((pts, feed), fit, (pts, 0.0), settings))
        .flatten()
        .map(|(pieces, deviation)| (within_block_rate((pts, feed), pieces, settings), deviation));
    let (pieces, deviation) = arcs.unwrap_or_else(|| (crate::vtg::arcs::lines(feed), 0.0));
    // Arcs are fitted within `fit` of the path and joined lines stay within `fit` of theirs,
    // on separate stretches: the larger of the two bounds the whole (both ways).
    let (pieces, joined) = super::straights::joined(pts, e, &pieces, fit);
    let deviation = deviation.max(joined);
    if pieces.len() >= run.len() {
        return None;
    }
    let original = machine.cost(pts[0], &pts[1..], &e[1..], feed);
    let (s, j) = machine.cost_pieces(pts[0], &pts[1..], &e[1..], &pieces);
    if !(s.is_finite() && j.is_finite()) {
        return None;
    }
    let (first, last) = (src.first()?, src.last()?);
    let frame = Frame {
        start: pts[0],
        climbs: run.iter().any(|m| (m.to[2] - m.from[2]).abs() > 1e-9),
        mode: first.mode,
        e_before: first.e_before,
        last_e_word: last.e_word,
        total_e: *e.last()?,
        f_before: first.f_before(),
        f_after: last.f_after(),
        f_after_read: !last.feed_overridden,
        notes: notes(input, src, e)?,
    };
    let text = block::write(&frame, &pts[1..], &e[1..], &pieces);
    let edits = edits(src, text);
    let lines = lines_added(&edits);
    if lines >= 0 {
        return None;
    }
    let part = Rewritten {
        compacted_paths: 1,
        replaced_moves: run.len() as u64,
        written_moves: pieces.len() as u64,
        arcs_written: pieces.iter().filter(|p| p.arc.is_some()).count() as u64,
        max_deviation_mm: deviation,
        ..Rewritten::default()
    };
    Some(Outcome {
        edits,
        part,
        added: [s - original.0, j - original.1],
        dearer: false,
        corners_removed: 0,
        lines_added: lines,
    })
}

/// Of the firmware's blocks a second, how long a burst over the budget may last at most, s
/// ([`within_block_rate`]): a 106° arc of gyroid infill cut into 22 chords takes 46 ms.
const BLOCK_BURST_S: f64 = 0.1;

/// `pieces` through `pts`, with as few of their arcs written back as the original lines
/// (`feed`) as it takes for the firmware to plan them at no more blocks a second than the
/// machine reads (`settings.max_blocks_per_s`), or than the original lines made. An arc takes
/// one line to send but as many planner blocks as `settings.arc_cutting` cuts it into chords:
/// Marlin 2.1 cuts a 106° wave of gyroid infill (2.8 mm, radius 1.5 mm) into 22 where the
/// slicer wrote 8, and at 60 mm/s such arcs ask some 470 blocks a second of a machine that
/// reads 350 or so. The blocks are metered as a token bucket, each piece over its time at
/// its feed (a lower bound, which the acceleration only lengthens): the bucket fills at the
/// rate allowed while each piece runs, carries at most [`BLOCK_BURST_S`] of it from one piece
/// to the next, and an arc it cannot pay for is written as its lines. So the path asks at
/// most that rate over any second, plus the burst, and its arcs are spread along it instead
/// of bunched at one end.
fn within_block_rate(
    (pts, feed): (&[[f64; 3]], &[f64]),
    pieces: Vec<Piece>,
    settings: &Settings,
) -> Vec<Piece> {
    let Some(cutting) = settings.arc_cutting else {
        return pieces;
    };
    let seconds = |length: f64, v: f64| length / v.max(f64::MIN_POSITIVE);
    let original_s: f64 = (pts.windows(2).zip(feed))
        .map(|(w, &v)| seconds(norm(sub(w[1], w[0])), v))
        .sum();
    let rate = settings
        .max_blocks_per_s
        .max(feed.len() as f64 / original_s);
    let capacity = rate * BLOCK_BURST_S;
    let (mut tokens, mut from) = (0.0f64, 0usize);
    let mut out = Vec::with_capacity(pieces.len());
    for piece in pieces {
        let end = piece.end.min(pts.len() - 1);
        let (a, b) = (pts[from], pts[end]);
        let lines = (from + 1..=end).map(|k| Piece {
            end: k,
            arc: None,
            feed: feed[k - 1],
        });
        let Some(shape) = piece.arc else {
            tokens = (tokens + rate * seconds(norm(sub(b, a)), piece.feed) - 1.0).min(capacity);
            out.push(piece);
            from = end;
            continue;
        };
        let arc = shape.resolve(&a, &b);
        let planar = arc.radius * arc.sweep.abs();
        let chords = cutting.segments(arc.radius, (planar, b[2] - a[2]), piece.feed) as f64;
        let filled = tokens + rate * seconds(planar.hypot(b[2] - a[2]), piece.feed);
        if filled >= chords {
            tokens = (filled - chords).min(capacity);
            out.push(piece);
        } else {
            tokens = (filled - (end - from) as f64).min(capacity);
            out.extend(lines);
        }
        from = end;
    }
    out
}

#[cfg(test)]
mod tests {
    use crate::vtg::{vtg, ArcsMode, VtgOptions, VtgReport};

    /// `src` rewritten by default, but with `arcs` and without the dynamics model.
    fn without_dynamics(src: &str, arcs: ArcsMode) -> VtgReport {
        let options = VtgOptions {
            dynamics: false,
            arcs,
            ..VtgOptions::default()
        };
        vtg(src.as_bytes(), &options).expect("vtg")
    }

    /// A 72-chord circle (5° turns: no sharp corner) and a square: with arcs, the circle
    /// written as arcs pays for the square's rounded corners, and the file has fewer lines
    /// than before; without, the square stays sharp and nothing changes.
    #[test]
    fn a_circle_in_arcs_pays_for_a_square_s_corners() {
        let mut src =
            String::from("; flavor: marlin2\nM83\nM204 P1250\nG1 X60 Y50 F6000\nG1 Z0.2\n");
        for k in 1..=72 {
            let a = (k as f64 * 5.0).to_radians();
            let (x, y) = (50.0 + 10.0 * a.cos(), 50.0 + 10.0 * a.sin());
            src.push_str(&format!("G1 X{x:.3} Y{y:.3} E0.03 F1800\n"));
        }
        src.push_str("G1 X80 Y80 F6000\n");
        for (x, y) in [(100, 80), (100, 100), (80, 100), (80, 80)] {
            src.push_str(&format!("G1 X{x} Y{y} E0.7 F1800\n"));
        }
        let lines = |b: &[u8]| b.iter().filter(|&&c| c == b'\n').count();
        let with = without_dynamics(&src, ArcsMode::On);
        assert_eq!(with.paths.compacted, 1);
        assert!(with.paths.arcs_written >= 1);
        assert_eq!(with.paths.rewritten, 1);
        assert_eq!(
            with.table1.n_turning.after, 0.0,
            "{:?}",
            with.table1.n_turning
        );
        assert!(lines(&with.output) <= lines(src.as_bytes()));
        assert!(with.max_deviation_mm <= 0.1);
        // The filament is the original's, to the rounding of the E words.
        let e = |b: &[u8]| {
            String::from_utf8_lossy(b)
                .split(|c: char| c.is_whitespace())
                .filter_map(|w| w.strip_prefix('E')?.parse::<f64>().ok())
                .sum::<f64>()
        };
        assert!((e(&with.output) - e(src.as_bytes())).abs() < 1e-3);
        let without = without_dynamics(&src, ArcsMode::Off);
        assert_eq!((without.paths.compacted, without.paths.rewritten), (0, 0));
        assert_eq!(without.output, src.as_bytes());
    }

    /// Gyroid-like waves of 0.3 mm chords at 60 mm/s, which Marlin 2.1 would cut into some
    /// 470 chords a second written as arcs: as many arcs are written back as lines as it
    /// takes for the rewrite to stay within the blocks a second the firmware reads, and the
    /// report does not warn.
    #[test]
    fn arcs_the_firmware_would_cut_faster_than_it_reads_are_written_as_lines() {
        let mut src = String::from(
            "; flavor: marlin2\nM83\nM204 P1000\nG1 X20 Y50 F6000\nG1 Z0.2\nG1 F3600\n",
        );
        // Arcs of 1.5 mm radius and 106°, bending each way in turn, in 8 chords each.
        let sweep = 106f64.to_radians();
        let chord = 2.0 * 1.5 * (sweep / 2.0).sin();
        for row in 0..40 {
            let y0 = 50.0 + 4.0 * row as f64;
            src.push_str(&format!("G0 X20 Y{y0:.3} F6000\nG1 F3600\n"));
            for w in 0..40 {
                let (x0, up) = (20.0 + chord * w as f64, if w % 2 == 0 { 1.0 } else { -1.0 });
                // The centre below the chord for a wave bulging up, above for one bulging down.
                let (cx, cy) = (x0 + chord / 2.0, y0 - up * 1.5 * (sweep / 2.0).cos());
                for k in 1..=8 {
                    let a = std::f64::consts::FRAC_PI_2 + sweep / 2.0 - sweep * k as f64 / 8.0;
                    let (x, y) = (cx + 1.5 * a.cos(), cy + up * 1.5 * a.sin());
                    src.push_str(&format!("G1 X{x:.3} Y{y:.3} E0.012\n"));
                }
            }
        }
        // Squares whose corners the lines saved pay for.
        for k in 0..400 {
            let (x, y) = (150.0 + 2.5 * (k / 40) as f64, 50.0 + 2.5 * (k % 40) as f64);
            src.push_str(&format!("G0 X{x} Y{y} F6000\nG1 F1800\n"));
            for (dx, dy) in [(2.0, 0.0), (2.0, 2.0), (0.0, 2.0), (0.0, 0.0)] {
                src.push_str(&format!("G1 X{} Y{} E0.07\n", x + dx, y + dy));
            }
        }
        let with = without_dynamics(&src, ArcsMode::On);
        let firmware = with.firmware.as_ref().expect("firmware figures");
        assert!(firmware.warning.is_none(), "{:?}", firmware.warning);
        assert!(
            firmware.after.peak_segments_per_s <= firmware.after.budget_segments_per_s,
            "{firmware:?}"
        );
        // Some arcs are written still, and the file has fewer lines than before.
        assert!(with.paths.arcs_written > 0, "{:?}", with.paths);
        assert!(firmware.after.lines < firmware.before.lines, "{firmware:?}");
    }
}
