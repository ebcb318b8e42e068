//! `quietpath vtg` from outside: output file, JSON report, refusal to overwrite the input.
#![cfg(not(target_arch = "wasm32"))]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The thesis square, and a scratch directory named after `tag` for its output.
fn square(tag: &str) -> (PathBuf, PathBuf) {
    let input = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/gcode/prusaslicer-2.5.0_thesis_square.gcode");
    let dir = std::env::temp_dir().join(format!("quietpath-vtg-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    (input, dir)
}

/// `quietpath vtg INPUT -o OUT ARGS…`.
fn vtg(input: &Path, out: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_quietpath"))
        .arg("vtg")
        .arg(input)
        .arg("-o")
        .arg(out)
        .args(args)
        .output()
        .expect("run quietpath")
}

#[test]
fn vtg_writes_the_file_and_reports_json() {
    let (input, dir) = square("cli");
    let out_path = dir.join("square.vtg.gcode");
    // Rounding the square's corners adds lines: allowed here (the default is tested below).
    let args = ["--tolerance", "0.1", "--critical-angle", "30", "--json"];
    let out = vtg(
        &input,
        &out_path,
        &[&args[..], &["--allow-more-lines", "1000"]].concat(),
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(json["tolerance_mm"], 0.1);
    let dev = json["max_deviation_mm"].as_f64().expect("deviation");
    assert!(dev > 0.0 && dev <= 0.1, "{dev}");
    for key in ["n_turning", "n_total", "l_total_mm", "mean_chord_error_mm"] {
        assert!(json["table1"][key]["before"].is_number(), "{key}");
    }
    assert!(json["table2"]["energy_j"]["after"].is_number());
    // Table 2's deviation rows come from the dynamics model, run on both files by default.
    for row in ["max_mm", "min_mm", "mean_mm"] {
        assert!(
            json["table2"]["deviation"][row]["after"]
                .as_f64()
                .expect(row)
                >= 0.0,
            "{row}"
        );
    }
    assert!(json["before"]["toolpath"]["n_turning"].as_u64().expect("n") > 0);
    let written = std::fs::read(&out_path).expect("output");
    assert!(!written.is_empty());

    // The closed loop kept scale 1 and the keyhole loops: its first retry, without keyholes,
    // leaves the wedges' tips sharp, and with lines to spare the keyholes with the steps as
    // walked round them (where the joined ones rang more, or peaked higher: see
    // `paths.steps_joined`).
    assert_eq!(json["paths"]["feed_cap_scale"], 1.0);
    assert!(json["paths"]["keyholes"].as_u64().expect("keyholes") > 0);
    let joined = json["paths"]["steps_joined"]
        .as_bool()
        .expect("steps_joined");
    // --no-dynamics skips the simulation (and the closed loop): the same file, deviation rows
    // null.
    let fast = vtg(
        &input,
        &out_path,
        &[
            "--no-dynamics",
            "--force",
            "--json",
            "--allow-more-lines",
            "1000",
        ],
    );
    assert!(fast.status.success());
    let fast: serde_json::Value = serde_json::from_slice(&fast.stdout).expect("json");
    assert!(fast["table2"]["deviation"].is_null());
    // --no-dynamics keeps the first rewrite, steps joined up to the segment budget: the same
    // file as the closed loop where that kept it too, else no more lines than its retry.
    assert_eq!(fast["paths"]["steps_joined"], true);
    let first = std::fs::read(&out_path).expect("output");
    if joined {
        assert_eq!(first, written);
    } else {
        let lines = |b: &[u8]| b.iter().filter(|&&c| c == b'\n').count();
        assert!(
            lines(&first) < lines(&written),
            "{} vs {}",
            lines(&first),
            lines(&written)
        );
    }

    // Refuses to overwrite its input without --force.
    let again = vtg(&input, &input, &[]);
    assert!(!again.status.success());
    let _ = std::fs::remove_dir_all(&dir);
}

/// By default the file gains no lines: the square's corners would each take several, so most
/// stay sharp, and the table says why and what to pass to round them. The few it rounds are
/// paid for by its feed-only lines, folded into the moves after them.
#[test]
fn vtg_adds_no_lines_by_default_and_says_so() {
    let (input, dir) = square("lines");
    let out_path = dir.join("square.vtg.gcode");
    let out = vtg(&input, &out_path, &["--no-dynamics"]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let lines = |b: &[u8]| b.iter().filter(|&&c| c == b'\n').count();
    let (before, after) = (
        std::fs::read(&input).expect("input"),
        std::fs::read(&out_path).expect("output"),
    );
    assert!(lines(&after) <= lines(&before));
    let table = String::from_utf8_lossy(&out.stdout);
    assert!(
        table.contains("kept sharp for lines") && table.contains("--allow-more-lines"),
        "{table}"
    );
    // `G1 F1800` and nothing else.
    let feed_lines = |b: &[u8]| {
        b.split(|&c| c == b'\n')
            .filter_map(|l| l.strip_prefix(b"G1 F"))
            .filter(|f| f.iter().all(|c| c.is_ascii_digit() || *c == b'.'))
            .count()
    };
    assert!(feed_lines(&before) > 0 && feed_lines(&after) < feed_lines(&before));
    assert!(
        after != before && table.contains("feed-only lines folded"),
        "{table}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
