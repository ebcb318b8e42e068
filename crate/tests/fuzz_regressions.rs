#![cfg(not(target_arch = "wasm32"))]
//! Replays every input in `crate/fuzz/regressions/` (crashes found by the fuzzers and hand-made
//! hostile files) through the checks of the fuzz targets (`crate/fuzz/checks.rs`): `parse_line` on every line,
//! `analyze` lenient and strict, lossless rewriting, and the planner on the bytes as motions. See `crate/fuzz/regressions/README.md`.

#![allow(clippy::unwrap_used)]

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use quietpath::analyze::{analyze, AnalyzeOptions};
use quietpath::ErrorKind;

/// The fuzz targets' own checks (one copy, shared with `crate/fuzz/fuzz_targets/`).
#[path = "../fuzz/checks.rs"]
mod checks;

fn regressions_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz")
        .join("regressions")
}

/// Every regression input, sorted by name; documentation files are skipped.
fn inputs() -> Vec<PathBuf> {
    let dir = regressions_dir();
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|entry| entry.expect("directory entry").path())
        .filter(|p| p.is_file() && p.extension().is_none_or(|ext| ext != "md"))
        .collect();
    files.sort();
    files
}

#[test]
fn fuzz_regressions_do_not_panic() {
    let files = inputs();
    assert!(
        files.len() >= 10,
        "expected the hand-made seeds in {}, found {} files",
        regressions_dir().display(),
        files.len()
    );
    let mut failures = Vec::new();
    for path in &files {
        let data =
            std::fs::read(path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        for (what, check) in [
            ("parse_line", checks::parse_line as fn(&[u8])),
            ("analyze", checks::analyze),
            ("rewrite", checks::rewrite),
            ("planner", checks::planner),
            ("vtg", checks::vtg),
            ("infill", checks::infill),
            ("smooth", checks::smooth),
            ("vibration", checks::vibration),
        ] {
            let started = std::time::Instant::now();
            if catch_unwind(AssertUnwindSafe(|| check(&data))).is_err() {
                failures.push(format!("{} ({what})", path.display()));
            }
            // Bounded cost on hostile input: seconds per megabyte at most (debug build, with
            // room for a loaded machine).
            let limit = 20.0 * (data.len() as f64 / 1e6).max(1.0);
            let secs = started.elapsed().as_secs_f64();
            if secs > limit {
                failures.push(format!("{} ({what}): {secs:.1} s", path.display()));
            }
        }
    }
    assert!(
        failures.is_empty(),
        "regression inputs that fail (messages above):\n  {}",
        failures.join("\n  ")
    );
}

#[test]
fn hand_made_seeds_give_the_expected_outcome() {
    let read = |name: &str| {
        let path = regressions_dir().join(name);
        std::fs::read(&path).unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
    };
    let lenient = AnalyzeOptions::default();
    let strict = AnalyzeOptions {
        strict: true,
        ..AnalyzeOptions::default()
    };

    for name in [
        "utf16le-bom.gcode",
        "utf16be-bom.gcode",
        "utf16le-no-bom.gcode",
    ] {
        let e = analyze(&read(name), &lenient).expect_err(name);
        assert!(matches!(e.kind, ErrorKind::Utf16), "{name}: {e:?}");
    }

    let empty = analyze(&read("empty.gcode"), &strict).expect("empty file");
    assert_eq!((empty.moves, empty.file.lines, empty.time_s), (0, 0, 0.0));
    let crlf = analyze(&read("crlf-only.gcode"), &strict).expect("CRLF only");
    assert_eq!((crlf.moves, crlf.file.lines), (0, 1));

    let e = analyze(&read("overflowing-number.gcode"), &strict).expect_err("X1e999");
    assert!(
        matches!(e.kind, ErrorKind::NonFiniteNumber { letter: 'X' }),
        "{e:?}"
    );
    let e = analyze(&read("bad-checksum.gcode"), &strict).expect_err("N1 G1*999");
    assert!(
        matches!(e.kind, ErrorKind::ChecksumMismatch { found: 999, .. }),
        "{e:?}"
    );
    let e = analyze(&read("command-line-too-long.gcode"), &strict).expect_err("90 KB command");
    assert!(matches!(e.kind, ErrorKind::LineTooLong { .. }), "{e:?}");

    let comment = analyze(&read("one-megabyte-comment.gcode"), &strict).expect("1 MB comment");
    assert_eq!(comment.file.lines, 1);

    // Invalid arcs become warned straight moves (or nothing, when they do not move).
    let arc = analyze(&read("arc-zero-radius.gcode"), &strict).expect("R0 arc");
    assert_eq!(arc.moves, 1);
    assert!((arc.distance_mm - 2f64.sqrt()).abs() < 1e-12);
    assert!(!arc.warnings.is_empty());
    let turns = analyze(&read("arc-million-turns.gcode"), &strict).expect("P1000000 arc");
    assert!(turns.time_s.is_finite() && turns.distance_mm.is_finite());

    // Coordinates beyond `machine::MAX_COORDINATE` (1e9 mm) are corruption: the line is
    // ignored with a warning naming it, and the report stays finite and empty.
    let big = analyze(&read("extreme-values.gcode"), &strict).expect("1e15 values");
    assert_eq!(big.moves, 0);
    assert_eq!(
        (big.distance_mm, big.filament_mm, big.time_s),
        (0.0, 0.0, 0.0)
    );
    assert_eq!(big.warnings.len(), 1);
    assert_eq!(big.warnings[0].line, 1);
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(400))]

    /// The planner's invariants (see `checks::planner`) on arbitrary motion sequences: every
    /// junction model and preset, tiny to huge moves, 0.1 to 1000 mm/s.
    #[test]
    fn planner_invariants_hold_on_arbitrary_motion(data in proptest::collection::vec(proptest::prelude::any::<u8>(), 0..1500)) {
        checks::planner(&data);
    }
}
