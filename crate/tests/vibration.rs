//! `quietpath vibration` from outside: the JSON is the library's report; `--compare`.
#![cfg(not(target_arch = "wasm32"))]

use std::path::{Path, PathBuf};
use std::process::Command;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../tests/fixtures/gcode")
        .join(name)
}

#[test]
fn json_is_the_library_report_and_compare_adds_the_change() {
    let path = fixture("prusaslicer-2.5.0_cube_marlin2_defaults.gcode");
    let out = Command::new(env!("CARGO_BIN_EXE_quietpath"))
        .args(["vibration", "--ts-ms", "5", "--json"])
        .arg(&path)
        .output()
        .expect("run");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&path).expect("read");
    let options = quietpath::dynamics::VibrationOptions {
        ts_ms: 5.0,
        ..Default::default()
    };
    let lib = quietpath::dynamics::vibration(&bytes, &options).expect("vibration");
    let expected = serde_json::to_string_pretty(&lib).expect("json") + "\n";
    assert!(
        out.stdout == expected.as_bytes(),
        "CLI JSON differs from the library report"
    );

    let out = Command::new(env!("CARGO_BIN_EXE_quietpath"))
        .args(["vibration", "--ts-ms", "5", "--json", "--compare"])
        .arg(&path)
        .arg(&path)
        .output()
        .expect("run");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(v["change"]["mean_deviation"], 0.0);
    assert!(v["before"]["deviation_mm"]["mean"].as_f64().unwrap_or(0.0) > 0.0);

    // Text output and a bad option.
    let out = Command::new(env!("CARGO_BIN_EXE_quietpath"))
        .args(["vibration", "--ts-ms", "5"])
        .arg(&path)
        .output()
        .expect("run");
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("deviation (eq. 15)"));
    let out = Command::new(env!("CARGO_BIN_EXE_quietpath"))
        .args(["vibration", "--fs", "5000"])
        .arg(&path)
        .output()
        .expect("run");
    assert!(!out.status.success());
}
