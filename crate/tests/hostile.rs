//! Hostile and broken inputs: an error or warnings with line numbers, never a panic, and a
//! bounded cost.
#![cfg(not(target_arch = "wasm32"))]

use std::time::{Duration, Instant};

use quietpath::analyze::{analyze, AnalyzeOptions};
use quietpath::error::ErrorKind;
use quietpath::gcode::apply_edits;

fn lenient(input: &[u8]) -> Result<quietpath::Report, quietpath::Error> {
    analyze(input, &AnalyzeOptions::default())
}

fn strict(input: &[u8]) -> Result<quietpath::Report, quietpath::Error> {
    analyze(
        input,
        &AnalyzeOptions {
            strict: true,
            ..AnalyzeOptions::default()
        },
    )
}

#[test]
fn empty_and_blank_files() {
    for input in [&b""[..], b"\n", b"\r\n\r\n", b"   ", b";", b"%"] {
        let r = lenient(input).expect("empty is fine");
        assert_eq!((r.moves, r.layers, r.time_s), (0, 0, 0.0));
        assert!(r.warnings.is_empty());
        assert!(apply_edits(input, &[]) == input);
    }
}

#[test]
fn non_finite_numbers_are_warned_with_their_line() {
    let input = b"G1 X1 F600\nG1 Xnan\nG1 Y-inf\nG1 Z1e999\nG1 E1e309\nG1 X2\n";
    let r = lenient(input).expect("lenient");
    let lines: Vec<u32> = r.warnings.iter().map(|w| w.line).collect();
    assert_eq!(lines, vec![2, 3, 4, 5]);
    assert_eq!(r.moves, 2);
    assert!(r.distance_mm.is_finite());
    let e = strict(input).expect_err("strict");
    assert_eq!((e.line, e.column), (2, 5));
    assert!(matches!(e.kind, ErrorKind::NonFiniteNumber { letter: 'X' }));
}

/// A limit below the feed floor (0.001 mm/s) caps a move at the floor, in Marlin's planner and
/// in Klipper's (`SET_VELOCITY_LIMIT`: Klipper has no `M203`), not at a speed that makes it last
/// for ever (found by the seeded mutation run: `M203 … Y93.0495e-324`).
#[test]
fn a_vanishing_feed_limit_keeps_the_feed_floor() {
    for (flavor, limit) in [
        ("", "M203 X180 Y9.3e-323"),
        (";FLAVOR:Klipper\n", "SET_VELOCITY_LIMIT VELOCITY=9.3e-323"),
    ] {
        let input = format!("{flavor}G21\nG90\n{limit}\nG1 Y10 F600\n");
        let r = lenient(input.as_bytes()).expect("lenient");
        // 10 mm at 0.001 mm/s, give or take the ramps.
        assert!(
            (r.time_s - 10_000.0).abs() < 1.0,
            "{flavor:?}: {} s",
            r.time_s
        );
    }
}

#[test]
fn random_bytes_never_panic() {
    // A fixed xorshift stream: reproducible, no dependency.
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    let mut next = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for round in 0..200 {
        let len = (next() % 4096) as usize;
        let mut bytes: Vec<u8> = (0..len).map(|_| next() as u8).collect();
        if round % 2 == 0 {
            // Bias half the inputs towards G-code characters.
            const ALPHABET: &[u8] = b"G0123M X.Y-Z E;F\nIJR()*N\r";
            for b in &mut bytes {
                *b = ALPHABET[usize::from(*b) % ALPHABET.len()];
            }
        }
        let _ = lenient(&bytes);
        let _ = strict(&bytes);
        assert!(apply_edits(&bytes, &[]) == bytes);
    }
}

#[test]
fn a_20_mb_line_costs_little() {
    let mut comment = b"G1 X1 F600\n;".to_vec();
    comment.resize(20 << 20, b'x');
    comment.extend_from_slice(b"\nG1 X2\n");
    let start = Instant::now();
    let r = lenient(&comment).expect("a long comment is fine");
    assert_eq!(r.moves, 2);

    let mut command = b"G1 X1 F600\nG1 ".to_vec();
    while command.len() < 20 << 20 {
        command.extend_from_slice(b"Y1 ");
    }
    command.extend_from_slice(b"\nG1 X2\n");
    let r = lenient(&command).expect("lenient");
    assert_eq!(r.warnings.len(), 1);
    assert_eq!(r.warnings[0].line, 2);
    assert_eq!(r.moves, 2);
    assert!(matches!(
        strict(&command).expect_err("strict").kind,
        ErrorKind::LineTooLong { .. }
    ));
    // Debug build, two 20 MB inputs (three passes each): generous, but bounded.
    assert!(
        start.elapsed() < Duration::from_secs(20),
        "{:?}",
        start.elapsed()
    );
}

#[test]
fn utf16_is_a_clear_error() {
    for bom in [&[0xFF, 0xFE][..], &[][..]] {
        let mut bytes = bom.to_vec();
        bytes.extend(
            "G1 X10 Y10 E1\nG1 X20\n"
                .encode_utf16()
                .flat_map(u16::to_le_bytes),
        );
        let e = lenient(&bytes).expect_err("utf-16");
        assert_eq!(e.kind, ErrorKind::Utf16);
        assert!(e.to_string().contains("UTF-16"));
    }
}

#[test]
fn truncated_files_analyze_up_to_the_cut() {
    let full = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../www/demo/demo.gcode"
    ))
    .expect("demo");
    let whole = lenient(&full).expect("demo");
    let mut previous_moves = 0;
    for cut in [full.len() / 4, full.len() / 2, full.len() - 7] {
        let part = &full[..cut];
        let r = lenient(part).expect("a truncated file still analyzes");
        assert!(r.moves >= previous_moves && r.moves <= whole.moves);
        previous_moves = r.moves;
        assert!(apply_edits(part, &[]) == part);
    }
}

#[test]
fn absurd_geometry_and_feeds_stay_finite() {
    let input = b"G1 X1e15 Y-1e15 F600\nG1 F0.0000001\nG1 X0 Y0\nG2 X1 Y0 I1e15 J0\nG3 X0 Y0 R1e-300\nG1 F1e300 X5\nG2 X5 Y0 I0 J0 P100000000\n";
    let r = lenient(input).expect("lenient");
    for v in [r.time_s, r.distance_mm, r.filament_mm] {
        assert!(v.is_finite(), "{v}");
    }
    assert!(!r.warnings.is_empty());
    serde_json::to_string(&r).expect("a report always serialises");
}

#[test]
fn vanishing_times_do_not_make_nan_energy_shares() {
    // Found by the property tests: a hot heater and a subnormal E move. The whole print lasts
    // next to nothing, and auxiliary energy must still be shared out without 0/0.
    let r = lenient(b"M104 S11196.13267578347\nG0 E2.2250738585072014e-308\n").expect("lenient");
    let json = serde_json::to_string(&r).expect("serialises");
    assert!(!json.contains("null,\"time_s\"") && r.features.iter().all(|f| f.energy_j.is_finite()));
    assert!(r.energy.total_j.is_finite());
}
