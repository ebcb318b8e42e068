#![cfg(not(target_arch = "wasm32"))]
//! Replays every input in `crate/fuzz/regressions/` (crashes found by the fuzzers and hand-made
//! hostile files) through the checks of the fuzz targets: `parse_line` on every line, `analyze`
//! lenient and strict, and lossless rewriting. See `crate/fuzz/regressions/README.md`.

#![allow(clippy::unwrap_used)]

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

use quietpath::analyze::{analyze, AnalyzeOptions};
use quietpath::gcode::{apply_edits, parse_line, Lines};
use quietpath::ErrorKind;

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

/// The `parse_line` fuzz target's checks.
fn check_lines(data: &[u8]) {
    for raw in Lines::new(data) {
        match parse_line(raw.text) {
            Ok(line) => {
                for (letter, value) in line.params.iter() {
                    if let Some(v) = value {
                        assert!(
                            v.is_finite(),
                            "line {}: word {} = {v}",
                            raw.number,
                            letter as char
                        );
                    }
                }
            }
            Err(e) => {
                assert!(e.column >= 1, "line {}: column 0: {e:?}", raw.number);
                assert!(
                    e.column as usize <= raw.text.len() + 1,
                    "line {}: column past the end: {e:?}",
                    raw.number
                );
            }
        }
    }
}

/// The `analyze` fuzz target's checks: `Ok` or a typed error, never a panic.
fn check_analyze(data: &[u8]) {
    let lenient = analyze(data, &AnalyzeOptions::default());
    let strict = analyze(
        data,
        &AnalyzeOptions {
            strict: true,
            ..AnalyzeOptions::default()
        },
    );
    match &lenient {
        Ok(report) => {
            let json = serde_json::to_string(report).expect("a report always serialises");
            if let Ok(strict) = &strict {
                let strict_json =
                    serde_json::to_string(strict).expect("a report always serialises");
                assert_eq!(
                    json, strict_json,
                    "strict and lenient reports differ on a file strict mode accepts"
                );
            }
        }
        Err(e) => {
            assert!(
                matches!(e.kind, ErrorKind::Utf16),
                "lenient analysis failed: {e}"
            );
            assert!(strict.is_err(), "strict accepted what lenient refused");
        }
    }
    if let Err(e) = &strict {
        // A typed error with a position inside the file (line 0 / column 0 only for file-level
        // errors).
        assert!(
            e.line as usize <= Lines::new(data).count().max(1),
            "error line {} past the end",
            e.line
        );
        assert!(!e.to_string().is_empty());
    }
}

/// The `rewrite` fuzz target's checks.
fn check_rewrite(data: &[u8]) {
    assert!(
        apply_edits(data, &[]) == data,
        "rewriting with no edits changed the input"
    );
    let mut concat = Vec::with_capacity(data.len());
    for raw in Lines::new(data) {
        concat.extend_from_slice(raw.text);
        concat.extend_from_slice(raw.terminator);
    }
    assert!(concat == data, "lines do not concatenate to the input");
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
            ("parse_line", check_lines as fn(&[u8])),
            ("analyze", check_analyze),
            ("rewrite", check_rewrite),
        ] {
            if catch_unwind(AssertUnwindSafe(|| check(&data))).is_err() {
                failures.push(format!("{} ({what})", path.display()));
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
