//! Klipper's own planner as the oracle, move by move: each small file of
//! `tests/fixtures/klipper/` (corners, Z hops, wipes, arcs, firmware retraction,
//! `SET_VELOCITY_LIMIT`, homing and dwells) runs through Klipper's host software in batch mode
//! (`../shared/klipper/klipper-time`, its `KLIPPER_DUMP` of every planned move) and through
//! quietpath with the same `printer.cfg`; the time of every source line's moves (an arc's
//! pieces summed) must agree within 1e-6 s. Nothing is recorded: the oracle runs each time
//! (it sets itself up from PyPI on first use), and the test fails, saying so, if it is absent.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

use quietpath::plan::KlipperConfig;
use quietpath::read::AnalyzeOptions;

#[path = "../../tests/support/oracle_set_up.rs"]
mod oracle_set_up;
use oracle_set_up::first_alone;

/// Largest difference allowed in one source line's time, s.
const TOLERANCE_S: f64 = 1e-6;

fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("workspace root")
        .to_path_buf()
}

fn oracle() -> PathBuf {
    let path = repo().join("../shared/klipper/klipper-time");
    assert!(
        path.exists(),
        "Klipper oracle missing: {} (the shared Klipper checkout, see ../shared/klipper/README.md) \
         is needed to check quietpath's Klipper planner move by move",
        path.display()
    );
    path
}

/// Klipper's planned time of each source line of `file` (summed over its moves), and the
/// whole file's moves and dwells (without the 2 ms Klipper inserts when it restarts step
/// generation after `G28`, an artefact of its MCU timing).
fn klipper_times(file: &Path, version: &str) -> (BTreeMap<u32, f64>, f64) {
    let dump = std::env::temp_dir().join(format!(
        "quietpath-klipper-{}-{}-{}.txt",
        std::process::id(),
        version,
        file.file_stem().and_then(|s| s.to_str()).unwrap_or("file")
    ));
    let out = first_alone(version, || {
        Command::new(oracle())
            .arg(file)
            .env("KLIPPER_VERSION", version)
            .env("KLIPPER_JSON", "1")
            .env("KLIPPER_DUMP", &dump)
            .output()
            .expect("run the Klipper oracle")
    });
    // klippy may crash on its way out after its report (exit 139): the report decides.
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{}: no report from the Klipper oracle ({e}); stderr:\n{}",
            file.display(),
            String::from_utf8_lossy(&out.stderr)
        )
    });
    assert_eq!(report["errors"], 0, "{}: {report}", file.display());
    assert_eq!(
        report["lines_read"],
        report["lines_file"],
        "{}: {report}",
        file.display()
    );
    let text = std::fs::read_to_string(&dump).expect("the oracle's move dump");
    let _ = std::fs::remove_file(&dump);
    let mut times = BTreeMap::new();
    for row in text.lines() {
        let mut cols = row.split_whitespace();
        let line: i64 = cols.next().and_then(|v| v.parse().ok()).expect(row);
        let secs: f64 = cols.next().and_then(|v| v.parse().ok()).expect(row);
        if let Ok(line) = u32::try_from(line) {
            *times.entry(line).or_insert(0.0) += secs;
        }
    }
    let total = |key: &str| report[key].as_f64().expect(key);
    (times, total("motion_s") + total("dwell_s"))
}

/// quietpath's planned time of each source line of `file` on the oracle's printer, and the
/// whole file's.
fn our_times(file: &Path, version: &str) -> (BTreeMap<u32, f64>, f64) {
    let cfg = repo().join(format!("../shared/klipper/{version}/printer.cfg"));
    let text = std::fs::read_to_string(&cfg).expect("the oracle's printer.cfg");
    let options = AnalyzeOptions {
        klipper_config: Some(KlipperConfig::parse_text(&text).expect("printer.cfg")),
        klipper_version: Some(if version == "head" {
            quietpath::plan::KlipperVersion::Current
        } else {
            quietpath::plan::KlipperVersion::Legacy
        }),
        ..Default::default()
    };
    let input = std::fs::read(file).expect("fixture");
    let path = quietpath::path::extract(&input, &options, true).expect("analysis");
    let mut times = BTreeMap::new();
    for m in &path.moves {
        if let Some(t) = m.timing {
            *times.entry(m.line).or_insert(0.0) += t.duration_s;
        }
    }
    (times, path.time_s)
}

/// Every line's time against Klipper's, on every fixture: the lines that differ.
fn compare(version: &str) -> Vec<String> {
    let dir = repo().join("tests/fixtures/klipper");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .expect("tests/fixtures/klipper")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "gcode"))
        .collect();
    files.sort();
    assert!(files.len() >= 7, "fixtures in {}", dir.display());
    let mut failures = Vec::new();
    for file in &files {
        let (klipper, klipper_total) = klipper_times(file, version);
        let (ours, our_total) = our_times(file, version);
        let name = file.file_name().and_then(|s| s.to_str()).unwrap_or("?");
        if (klipper_total - our_total).abs() > TOLERANCE_S {
            failures.push(format!(
                "{name}: moves and dwells Klipper {klipper_total:.9} s, quietpath {our_total:.9} s"
            ));
        }
        let lines: std::collections::BTreeSet<u32> =
            klipper.keys().chain(ours.keys()).copied().collect();
        for line in lines {
            let (k, q) = (
                klipper.get(&line).copied().unwrap_or(0.0),
                ours.get(&line).copied().unwrap_or(0.0),
            );
            if (k - q).abs() > TOLERANCE_S {
                failures.push(format!(
                    "{name}:{line}: Klipper {k:.9} s, quietpath {q:.9} s ({:+.3e})",
                    q - k
                ));
            }
        }
    }
    failures
}

#[test]
fn every_move_takes_the_time_klipper_plans() {
    let failures = compare("head");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_move_takes_the_time_klipper_v0_12_plans() {
    let failures = compare("v0.12.0");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
