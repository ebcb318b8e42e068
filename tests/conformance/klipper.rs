//! Whole files against Klipper's own planner (`../shared/klipper/klipper-time`, the oracle):
//! every corpus file that drives Klipper and every PrusaSlicer fixture, run as if on the
//! oracle's printer (`quietpath analyze --klipper-config` with its `printer.cfg`), within
//! 0.2 % of the time Klipper plans, the median within 0.05 %; the Creality K1 family also on
//! Klipper v0.12.0 (absolute `max_accel_to_decel`, as their firmware), within 0.2 %. The
//! oracle runs each time (it sets itself up from PyPI on first use) and the test fails, saying
//! so, when it is absent. Move-by-move checks on small files: `crate/tests/klipper_oracle.rs`.

use std::path::{Path, PathBuf};
use std::process::Command;

use quietpath::plan::{JunctionModel, KlipperConfig, KlipperVersion};
use quietpath::{analyze, AnalyzeOptions};
use quietpath_conformance::{corpus, corpus_dir, fixture_gcode};

#[path = "../support/oracle_set_up.rs"]
mod oracle_set_up;
use oracle_set_up::first_alone;

/// Largest difference on any file, percent.
const FILE_BAR_PCT: f64 = 0.2;
/// Largest median difference, percent.
const MEDIAN_BAR_PCT: f64 = 0.05;

fn shared() -> PathBuf {
    corpus_dir().join("..")
}

/// The time Klipper plans for `file` (`time_s` of the oracle's report), or a failure that
/// says why.
fn klipper_time(file: &Path, version: &str) -> f64 {
    let oracle = shared().join("klipper/klipper-time");
    assert!(
        oracle.exists(),
        "Klipper oracle missing: {} (see ../shared/klipper/README.md); it is the reference \
         for quietpath's Klipper planner",
        oracle.display()
    );
    let name = file.file_name().and_then(|n| n.to_str()).unwrap_or("");
    // Kiri:Moto's file relies on its start macro for relative extrusion (oracle README).
    let preamble = if name.starts_with("kirimoto") {
        "G28;M83"
    } else {
        "G28"
    };
    let run = || {
        Command::new(&oracle)
            .arg(file)
            .env("KLIPPER_VERSION", version)
            .env("KLIPPER_JSON", "1")
            .env("KLIPPER_PREAMBLE", preamble)
            .output()
            .expect("run the Klipper oracle")
    };
    let mut out = first_alone(version, run);
    // Once in a while klippy exits before printing anything, nothing on stderr either (a
    // fresh-clone CI run on 2026-11-26; the same file ran at once by hand): run it again, at
    // most twice. A run that prints a report is never repeated.
    for _ in 0..2 {
        if !out.stdout.is_empty() {
            break;
        }
        out = run();
    }
    // klippy may crash on its way out after printing its report: the report decides.
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "{name}: no report from the oracle ({e}):\n{}",
            String::from_utf8_lossy(&out.stderr)
        )
    });
    assert_eq!(r["errors"], 0, "{name}: the oracle reports errors: {r}");
    assert_eq!(
        r["lines_read"], r["lines_file"],
        "{name}: the oracle did not read every line"
    );
    r["time_s"].as_f64().expect("time_s")
}

/// quietpath's time for `file` on the oracle's printer.
fn our_time(file: &Path, version: &str) -> f64 {
    let cfg = shared().join(format!("klipper/{version}/printer.cfg"));
    let text = std::fs::read_to_string(&cfg).expect("the oracle's printer.cfg");
    let options = AnalyzeOptions {
        klipper_config: Some(KlipperConfig::parse_text(&text).expect("printer.cfg")),
        klipper_version: Some(if version == "head" {
            KlipperVersion::Current
        } else {
            KlipperVersion::Legacy
        }),
        ..Default::default()
    };
    analyze(&std::fs::read(file).expect("file"), &options)
        .expect("analysis")
        .time_s
}

/// (file, Klipper s, quietpath s, difference %) for each file, two at a time.
fn compare(files: &[PathBuf], version: &str) -> Vec<(String, f64, f64, f64)> {
    let half = files.len().div_ceil(2);
    let run = |part: &[PathBuf]| -> Vec<(String, f64, f64, f64)> {
        part.iter()
            .map(|f| {
                let (k, q) = (klipper_time(f, version), our_time(f, version));
                let name = f
                    .file_name()
                    .map(|n| n.to_string_lossy().to_string())
                    .unwrap_or_default();
                (name, k, q, 100.0 * (q - k) / k)
            })
            .collect()
    };
    std::thread::scope(|s| {
        let (a, b) = files.split_at(half);
        let other = s.spawn(|| run(b));
        let mut rows = run(a);
        rows.extend(other.join().expect("oracle thread"));
        rows
    })
}

fn check(rows: &[(String, f64, f64, f64)], version: &str, median_bar: Option<f64>) {
    println!("| file | Klipper {version}, s | quietpath, s | difference |");
    println!("|---|---:|---:|---:|");
    for (name, k, q, d) in rows {
        println!("| {name} | {k:.3} | {q:.3} | {d:+.4} % |");
    }
    for (name, _, _, d) in rows {
        assert!(
            d.abs() <= FILE_BAR_PCT,
            "{name}: {d:+.4} % from Klipper {version}"
        );
    }
    if let Some(bar) = median_bar {
        let mut abs: Vec<f64> = rows.iter().map(|r| r.3.abs()).collect();
        abs.sort_by(f64::total_cmp);
        let median = abs[abs.len() / 2];
        assert!(median <= bar, "median {median:.4} % from Klipper {version}");
    }
}

/// The corpus files quietpath runs on Klipper by themselves (their own commands or flavour),
/// the 34 MB file aside.
fn klipper_corpus() -> Vec<PathBuf> {
    corpus()
        .into_iter()
        .filter(|c| !c.name.contains("large"))
        .filter(|c| {
            analyze(&c.read(), &AnalyzeOptions::default())
                .is_ok_and(|r| r.machine.junction_model == JunctionModel::Klipper)
        })
        .map(|c| c.path())
        .collect()
}

#[test]
fn klipper_files_and_fixtures_agree_with_klipper() {
    let mut files = klipper_corpus();
    assert!(
        files.len() >= 4,
        "only {} corpus files drive Klipper",
        files.len()
    );
    files.extend(fixture_gcode());
    check(&compare(&files, "head"), "head", Some(MEDIAN_BAR_PCT));
}

#[test]
fn k1_family_agrees_with_klipper_v0_12() {
    let files: Vec<PathBuf> = klipper_corpus()
        .into_iter()
        .filter(|p| p.to_string_lossy().contains("_k1"))
        .collect();
    assert_eq!(files.len(), 3, "the K1, K1 SE and K1C files");
    check(&compare(&files, "v0.12.0"), "v0.12.0", None);
}

/// `vtg` folds feed-only lines into the moves that read them (`quietpath::vtg::feeds`): the
/// K1C benchy loses 18 368 of its 127 712 lines so, and Klipper plans the folded file to the
/// same time as the original, on the firmware version of its printer.
#[test]
fn klipper_plans_a_file_with_its_feed_lines_folded_as_the_original() {
    let file = corpus_dir().join("crealityprint-5_k1c_benchy_klipper_exclude-object.gcode");
    let original = std::fs::read(&file).expect("K1C benchy");
    let folded = quietpath::vtg::feeds::fold(&original).expect("feed lines to fold");
    assert_eq!(folded.lines(), 18_368);
    let path = std::env::temp_dir().join(format!("qp-folded-{}.gcode", std::process::id()));
    std::fs::write(&path, &folded.bytes).expect("write the folded file");
    let (before, after) = (
        klipper_time(&file, "v0.12.0"),
        klipper_time(&path, "v0.12.0"),
    );
    let _ = std::fs::remove_file(&path);
    assert!(
        (after - before).abs() <= 1e-9 * before,
        "Klipper plans {before} s for the original, {after} s folded"
    );
}
