//! Print time against the slicers' own estimates.
//!
//! PrusaSlicer's estimator (its `GCodeProcessor`) simulates a Marlin-style planner with the
//! machine limits the file carries (`M201`/`M203`/`M204`/`M205`), so on PrusaSlicer output
//! `time_s` must agree with its "estimated printing time (normal mode)": within 2 % on every
//! file and within 1 % at the median. The files are the fixtures sliced here
//! (`tests/fixtures/make_prusaslicer.sh`), the PrusaSlicer files of the shared corpus and the
//! playground's demo. Other slicers estimate with models of their own, so for them the
//! comparison is only printed, with a loose sanity bound.
//!
//! PrusaSlicer's estimate leaves `G4` dwells out (the fixture `cube_dwell_slow-z` has a
//! `G4 S30` in its start G-code and PrusaSlicer gives it the same estimate as without), while
//! `time_s` counts them, as the printer does: the comparison is of `time_s − dwell_s`.
//!
//! `cargo test -p quietpath-conformance slicer_times:: -- --nocapture` shows the tables.
#![allow(clippy::unwrap_used)]

use std::cmp::Ordering;
use std::path::{Path, PathBuf};

use quietpath::analyze::{analyze, AnalyzeOptions, Report};
use quietpath::plan::{LimitSource, Limits};
use quietpath_conformance::{corpus, corpus_dir, fixtures_dir};

/// Every file must be within this of PrusaSlicer's estimate, %.
const MAX_DEVIATION_PCT: f64 = 2.0;
/// The median absolute deviation must be within this, %.
const MAX_MEDIAN_DEVIATION_PCT: f64 = 1.0;
/// Other slicers: our time within this factor of theirs.
const OTHER_SLICERS_FACTOR: f64 = 3.0;

/// The fixtures `tests/fixtures/make_prusaslicer.sh` writes (all of them must be there).
const FIXTURES: [&str; 8] = [
    "prusaslicer-2.5.0_cube_marlin2_defaults.gcode",
    "prusaslicer-2.5.0_cylinder_gyroid_accel1000.gcode",
    "prusaslicer-2.5.0_vase_marlin-legacy_absE.gcode",
    "prusaslicer-2.5.0_bracket_honeycomb_absE.gcode",
    "prusaslicer-2.5.0_star_fast_jerk15.gcode",
    "prusaslicer-2.5.0_tower_slowdown_minfeed.gcode",
    "prusaslicer-2.5.0_plate_long-moves_accel800.gcode",
    "prusaslicer-2.5.0_cube_dwell_slow-z.gcode",
];

/// PrusaSlicer files of the shared corpus that carry their machine limits.
const CORPUS_PRUSASLICER: [&str; 3] = [
    "prusaslicer-2.6.1_benchy_marlin2.gcode",
    "prusaslicer-2.7.4_screw_arcfit.gcode",
    "prusaslicer-2.7.4_spiral-vase.gcode",
];

fn demo_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../www/demo/demo.gcode")
}

/// Every PrusaSlicer-family file: (label, path).
fn prusaslicer_files() -> Vec<(String, PathBuf)> {
    let mut files: Vec<(String, PathBuf)> = FIXTURES
        .iter()
        .map(|n| {
            (
                format!("fixtures/{n}"),
                fixtures_dir().join("gcode").join(n),
            )
        })
        .collect();
    files.extend(
        CORPUS_PRUSASLICER
            .iter()
            .map(|n| (format!("corpus/{n}"), corpus_dir().join(n))),
    );
    files.push(("www/demo/demo.gcode".to_string(), demo_path()));
    files
}

fn analyze_file(path: &Path) -> Report {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    analyze(&bytes, &AnalyzeOptions::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// One row of a comparison table.
#[derive(Debug)]
struct Row {
    name: String,
    ours_s: f64,
    slicer_s: f64,
}

impl Row {
    /// Signed deviation of our time from the slicer's, %.
    fn deviation_pct(&self) -> f64 {
        (self.ours_s / self.slicer_s - 1.0) * 100.0
    }
}

fn print_table(title: &str, rows: &[Row]) {
    let width = rows.iter().map(|r| r.name.len()).max().unwrap_or(4).max(4);
    eprintln!("\n{title}");
    eprintln!(
        "{:<width$}  {:>10}  {:>10}  {:>8}",
        "file", "ours, s", "slicer, s", "diff, %"
    );
    for r in rows {
        eprintln!(
            "{:<width$}  {:>10.1}  {:>10.1}  {:>+8.2}",
            r.name,
            r.ours_s,
            r.slicer_s,
            r.deviation_pct()
        );
    }
}

fn median(mut values: Vec<f64>) -> f64 {
    values.sort_by(f64::total_cmp);
    let n = values.len();
    assert!(n > 0, "median of nothing");
    if n % 2 == 1 {
        values[n / 2]
    } else {
        (values[n / 2 - 1] + values[n / 2]) / 2.0
    }
}

#[test]
fn prusaslicer_estimates_are_matched_within_two_percent() {
    let mut rows = Vec::new();
    for (name, path) in prusaslicer_files() {
        let report = analyze_file(&path);
        let slicer_s = report
            .file
            .slicer_time_s
            .unwrap_or_else(|| panic!("{name}: no PrusaSlicer estimate found in the file"));
        rows.push(Row {
            name,
            ours_s: report.time_s - report.dwell_s,
            slicer_s,
        });
    }
    print_table(
        "quietpath time_s - dwell_s vs PrusaSlicer's estimated printing time (normal mode)",
        &rows,
    );
    let med = median(rows.iter().map(|r| r.deviation_pct().abs()).collect());
    eprintln!(
        "median |diff|: {med:.2} % (bound {MAX_MEDIAN_DEVIATION_PCT} %); \
         every file within {MAX_DEVIATION_PCT} %"
    );

    let outside: Vec<String> = rows
        .iter()
        // NaN (no usable estimate) counts as outside.
        .filter(|r| {
            !matches!(
                r.deviation_pct().abs().partial_cmp(&MAX_DEVIATION_PCT),
                Some(Ordering::Less | Ordering::Equal)
            )
        })
        .map(|r| format!("{} ({:+.2} %)", r.name, r.deviation_pct()))
        .collect();
    assert!(
        outside.is_empty(),
        "outside {MAX_DEVIATION_PCT} % of PrusaSlicer's estimate: {outside:?}"
    );
    assert!(
        med <= MAX_MEDIAN_DEVIATION_PCT,
        "median |diff| {med:.2} % is over {MAX_MEDIAN_DEVIATION_PCT} %"
    );
}

#[test]
fn other_slicers_estimates_are_reported() {
    let mut rows = Vec::new();
    let mut without = Vec::new();
    for f in corpus() {
        let report = analyze(&f.read(), &AnalyzeOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", f.name));
        let Some(slicer_s) = report.file.slicer_time_s else {
            without.push(f.name);
            continue;
        };
        rows.push(Row {
            name: f.name,
            ours_s: report.time_s,
            slicer_s,
        });
    }
    print_table(
        "quietpath time_s vs every corpus file's own slicer estimate (informative)",
        &rows,
    );
    eprintln!("no slicer estimate in: {}", without.join(", "));
    assert!(
        rows.len() >= 10,
        "only {} corpus files carry an estimate",
        rows.len()
    );
    for r in &rows {
        assert!(
            r.ours_s.is_finite() && r.ours_s > 0.0,
            "{}: time_s {}",
            r.name,
            r.ours_s
        );
        assert!(
            r.slicer_s.is_finite() && r.slicer_s > 0.0,
            "{}: slicer estimate {}",
            r.name,
            r.slicer_s
        );
        let ratio = r.ours_s / r.slicer_s;
        assert!(
            (1.0 / OTHER_SLICERS_FACTOR..=OTHER_SLICERS_FACTOR).contains(&ratio),
            "{}: {:.1} s vs the slicer's {:.1} s, not within a factor of {OTHER_SLICERS_FACTOR}",
            r.name,
            r.ours_s,
            r.slicer_s
        );
    }
}

/// Creality Print 4.x (CXEngine) estimates for Klipper with the accelerations it writes
/// (`M204 S5000`…`S20000` per feature), which Klipper takes as the toolhead's `max_accel` with no
/// per-axis limit. Planned that way, the K1 benchy and the K1 SE accessory come within 2 % of
/// the slicer's `;TIME:` (capped at the Klipper preset's 3000 mm/s² per axis, as before, they
/// read 41 % and 13 % long).
#[test]
fn creality_print_klipper_estimates_are_matched_within_two_percent() {
    for (name, slicer_s) in [
        ("crealityprint-4.3.4_k1_benchy_m83_arcs.gcode", 1000.0),
        (
            "crealityprint-4.3.8_k1se_accessory_m82_arcs_exclude-object.gcode",
            1489.564061,
        ),
    ] {
        let report = analyze_file(&corpus_dir().join(name));
        assert_eq!(report.file.slicer_time_s, Some(slicer_s), "{name}");
        let pct = (report.time_s / slicer_s - 1.0) * 100.0;
        eprintln!(
            "{name}: {:.1} s vs {slicer_s} s ({pct:+.2} %)",
            report.time_s
        );
        assert!(pct.abs() <= MAX_DEVIATION_PCT, "{name}: {pct:+.2} %");
    }
}

/// Asserts that `limit` holds `value` and was read from a command in the file.
fn assert_command(what: &str, limit: quietpath::plan::Limit, value: f64) {
    assert_eq!(
        (limit.value, limit.source),
        (value, LimitSource::Command),
        "{what}"
    );
}

/// The limits in force at the first printing move are the ones given to PrusaSlicer
/// (`make_prusaslicer.sh`), read from the `M201`/`M203`/`M204`/`M205` lines it emitted.
#[test]
fn emitted_machine_limits_are_read() {
    let check = |name: &str, expect: &dyn Fn(&Limits)| {
        let report = analyze_file(&fixtures_dir().join("gcode").join(name));
        let limits = &report.machine.limits;
        eprintln!("{name}: {limits:?}");
        expect(limits);
    };
    // --machine-max-acceleration-extruding 4000 --machine-max-acceleration-travel 5000
    // --machine-max-feedrate-x/y 300 --machine-max-jerk-x/y 15; the rest PrusaSlicer's
    // defaults (retracting 1500, X/Y 9000, Z 500/12, E 10000/120, E jerk 2.5).
    check("prusaslicer-2.5.0_star_fast_jerk15.gcode", &|l| {
        assert_command("acceleration (M204 P)", l.acceleration, 4000.0);
        assert_command(
            "travel acceleration (M204 T)",
            l.travel_acceleration,
            5000.0,
        );
        assert_command(
            "retract acceleration (M204 R)",
            l.retract_acceleration,
            1500.0,
        );
        let axes = ["X", "Y", "Z", "E"];
        for (i, v) in [300.0, 300.0, 12.0, 120.0].into_iter().enumerate() {
            assert_command(&format!("M203 {}", axes[i]), l.max_feedrate[i], v);
        }
        for (i, v) in [9000.0, 9000.0, 500.0, 10000.0].into_iter().enumerate() {
            assert_command(&format!("M201 {}", axes[i]), l.max_acceleration[i], v);
        }
        for (i, v) in [15.0, 15.0, 0.2, 2.5].into_iter().enumerate() {
            assert_command(&format!("M205 {}", axes[i]), l.max_jerk[i], v);
        }
    });
    // --machine-min-extruding-rate 8 --machine-min-travel-rate 20 --machine-max-jerk-e 5.
    check("prusaslicer-2.5.0_tower_slowdown_minfeed.gcode", &|l| {
        assert_command("M205 S", l.min_feedrate, 8.0);
        assert_command("M205 T", l.min_travel_feedrate, 20.0);
        assert_command("M205 E", l.max_jerk[3], 5.0);
    });
    // --machine-max-acceleration-x/y 2000 below --machine-max-acceleration-extruding 2500.
    check("prusaslicer-2.5.0_bracket_honeycomb_absE.gcode", &|l| {
        assert_command("M201 X", l.max_acceleration[0], 2000.0);
        assert_command("M201 Y", l.max_acceleration[1], 2000.0);
        assert_command("M204 P", l.acceleration, 2500.0);
        assert_command("M203 X", l.max_feedrate[0], 200.0);
        assert_command("M205 X", l.max_jerk[0], 7.0);
    });
}
