//! Conformance of `vtg` on real slicer output: our PrusaSlicer slices and two corpus files.
//!
//! Each rewrite is checked independently of the optimiser: both files are read back as moves
//! ([`quietpath::path::extract`]) and every printing move of the output, sampled finely, must
//! lie within the tolerance of the original's printing moves of the same layer. Filament is
//! conserved, every line that is not a replaced move is kept, and sharp corners fall.
#![allow(clippy::unwrap_used)]

use quietpath::gcode::{parse_line, Lines};
use quietpath::path::extract;
use quietpath::vtg::deviation::file_deviation;
use quietpath::vtg::{vtg, VtgOptions};
use quietpath_conformance::{corpus_dir, fixtures_dir};

/// Lines that are not `G0`/`G1` moves, in order.
fn non_motion_lines(bytes: &[u8]) -> Vec<Vec<u8>> {
    Lines::new(bytes)
        .filter(|l| {
            parse_line(l.text).map_or(true, |p| {
                !p.code()
                    .is_some_and(|c| c.letter == b'G' && c.number <= 1 && c.sub.is_none())
            })
        })
        .map(|l| l.text.to_vec())
        .collect()
}

struct Outcome {
    turning_change_pct: f64,
    time_change_pct: f64,
}

fn check(bytes: &[u8], name: &str, options: &VtgOptions) -> Outcome {
    let r = vtg(bytes, options).unwrap();
    let tol = options.tolerance_mm;
    assert!(r.paths.rewritten > 0, "{name}: nothing rewritten");
    assert!(
        r.max_deviation_mm <= tol,
        "{name}: reported deviation {}",
        r.max_deviation_mm
    );
    // Independent measurement on the two files (coordinates are written to 0.001 mm).
    let before = extract(bytes, &options.analyze, false).unwrap();
    let after = extract(&r.output, &options.analyze, false).unwrap();
    let measured = file_deviation(&before, &after, tol / 10.0);
    assert!(
        measured <= tol + 0.001,
        "{name}: measured deviation {measured} over {tol}"
    );
    // Filament conserved (to 0.5 %; in practice to rounding).
    let (fb, fa) = (r.before.filament_mm, r.after.filament_mm);
    assert!(
        ((fa - fb) / fb).abs() < 0.005,
        "{name}: filament {fb} -> {fa}"
    );
    // Every non-motion line is kept, in order.
    assert_eq!(
        non_motion_lines(bytes)
            .into_iter()
            .filter(|l| !l.is_empty())
            .count(),
        non_motion_lines(&r.output)
            .into_iter()
            .filter(|l| !l.is_empty())
            .count(),
        "{name}: non-motion lines"
    );
    assert_eq!(r.before.layers, r.after.layers, "{name}: layers");
    Outcome {
        turning_change_pct: r.table1.n_turning.change_pct,
        time_change_pct: r.table2.time_s.change_pct,
    }
}

fn options(tolerance_mm: f64, limit_feed: bool) -> VtgOptions {
    VtgOptions {
        tolerance_mm,
        limit_feed,
        ..VtgOptions::default()
    }
}

#[test]
fn prusaslicer_cube_within_tolerance_with_fewer_sharp_corners() {
    let bytes =
        std::fs::read(fixtures_dir().join("gcode/prusaslicer-2.5.0_cube_marlin2_defaults.gcode"))
            .unwrap();
    let o = check(&bytes, "cube", &options(0.1, true));
    assert!(o.turning_change_pct <= -40.0, "{}", o.turning_change_pct);
    assert!(o.time_change_pct <= 1.0, "{}", o.time_change_pct);
}

#[test]
fn prusaslicer_absolute_e_tower_keeps_later_lines_valid() {
    let bytes =
        std::fs::read(fixtures_dir().join("gcode/prusaslicer-2.5.0_tower_slowdown_minfeed.gcode"))
            .unwrap();
    let o = check(&bytes, "tower", &options(0.1, true));
    assert!(o.turning_change_pct <= -40.0, "{}", o.turning_change_pct);
    assert!(o.time_change_pct <= 1.0, "{}", o.time_change_pct);
}

#[test]
fn prusaslicer_vase_absolute_e() {
    let bytes =
        std::fs::read(fixtures_dir().join("gcode/prusaslicer-2.5.0_vase_marlin-legacy_absE.gcode"))
            .unwrap();
    let o = check(&bytes, "vase", &options(0.05, true));
    assert!(o.turning_change_pct < 0.0, "{}", o.turning_change_pct);
}

#[test]
fn corpus_slic3r_and_cura() {
    for name in [
        "slic3r-1.3.1-dev_multi-object.gcode",
        "cura-4.10.0_multi-object.gcode",
    ] {
        let bytes = std::fs::read(corpus_dir().join(name)).unwrap();
        let o = check(&bytes, name, &options(0.1, false));
        assert!(
            o.turning_change_pct < 0.0,
            "{name}: {}",
            o.turning_change_pct
        );
        // Without feed lowering the rounded corners only speed the machine up.
        assert!(o.time_change_pct <= 1.0, "{name}: {}", o.time_change_pct);
    }
}
