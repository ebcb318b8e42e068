//! The `quietpath` binary from outside: JSON contract, rewrite, errors and exit codes.
#![cfg(not(target_arch = "wasm32"))]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_quietpath"))
}

fn corpus(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/corpus")
        .join(name)
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("quietpath-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir.join(name)
}

fn run(cmd: &mut Command) -> Output {
    cmd.output().expect("run quietpath")
}

#[test]
fn analyze_json_is_the_library_report() {
    let path = corpus("prusaslicer-2.7.4_screw_arcfit.gcode");
    let out = run(bin().arg("analyze").arg(&path).arg("--json"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let bytes = std::fs::read(&path).expect("read");
    let lib = quietpath::analyze(&bytes, &Default::default()).expect("analyze");
    let expected = serde_json::to_string_pretty(&lib).expect("to json") + "\n";
    assert!(
        out.stdout == expected.as_bytes(),
        "CLI JSON differs from the library's report"
    );
    let cli: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    for key in [
        "time_s",
        "moves",
        "layers",
        "distance_mm",
        "filament_mm",
        "material_g",
        "energy",
        "toolpath",
        "warnings",
    ] {
        assert!(cli.get(key).is_some(), "missing {key}");
    }
    assert_eq!(cli["layers"], 139);
}

#[test]
fn analyze_table_is_human_readable() {
    let out = run(bin()
        .arg("analyze")
        .arg(corpus("superslicer-2.3.56_klipper_arcwelder.gcode")));
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).expect("utf8");
    assert!(text.contains("SuperSlicer 2.3.56"), "{text}");
    assert!(text.contains("layers") && text.contains("25"), "{text}");
    assert!(text.contains("External perimeter"), "{text}");
}

#[test]
fn rewrite_is_byte_identical_and_atomic() {
    let input = corpus("crealityprint-4.3.4_k1_benchy_m83_arcs.gcode");
    // A directory of its own: the other tests write (atomically, through temporary files)
    // into the shared one at the same time.
    let output = scratch("atomic/benchy.gcode");
    std::fs::create_dir_all(output.parent().expect("dir")).expect("atomic dir");
    let out = run(bin().arg("rewrite").arg(&input).arg("-o").arg(&output));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(std::fs::read(&input).expect("in") == std::fs::read(&output).expect("out"));
    // No temporary file is left behind.
    let leftovers = std::fs::read_dir(output.parent().expect("dir"))
        .expect("list")
        .filter(|e| {
            e.as_ref()
                .is_ok_and(|e| e.file_name().to_string_lossy().ends_with(".tmp"))
        })
        .count();
    assert_eq!(leftovers, 0);
}

#[test]
fn rewrite_refuses_to_overwrite_its_input_unless_forced() {
    let file = scratch("self.gcode");
    std::fs::write(&file, "G1 X1\r\nG1 X2").expect("write");
    let out = run(bin().arg("rewrite").arg(&file).arg("-o").arg(&file));
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--force"));
    let out = run(bin()
        .arg("rewrite")
        .arg(&file)
        .arg("-o")
        .arg(&file)
        .arg("--force"));
    assert!(out.status.success());
    assert_eq!(std::fs::read(&file).expect("read"), b"G1 X1\r\nG1 X2");
}

#[test]
fn errors_name_the_file_line_and_column() {
    let file = scratch("bad.gcode");
    std::fs::write(&file, "G1 X1\nG1 X2\nG1 Y1e999\n").expect("write");
    let out = run(bin().arg("analyze").arg(&file).arg("--strict"));
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("bad.gcode: line 3, column 5"), "{err}");
    // Lenient by default: a warning with the line, and the report still comes.
    let out = run(bin().arg("analyze").arg(&file).arg("--json"));
    assert!(out.status.success());
    let r: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(r["warnings"][0]["line"], 3);
    assert_eq!(r["moves"], 2);
}

#[test]
fn missing_file_and_bad_usage_fail_cleanly() {
    let out = run(bin().arg("analyze").arg("/nonexistent/x.gcode"));
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("/nonexistent/x.gcode"));
    let out = run(bin().arg("frobnicate"));
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn utf16_input_is_a_clear_error() {
    let file = scratch("utf16.gcode");
    let bytes: Vec<u8> = "\u{feff}G1 X1\n"
        .encode_utf16()
        .flat_map(u16::to_le_bytes)
        .collect();
    std::fs::write(&file, bytes).expect("write");
    let out = run(bin().arg("analyze").arg(&file));
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("UTF-16"));
}

/// A Marlin printer's own settings as `M503` prints them set the limits the file is timed
/// with (a slower acceleration makes the print longer), each limit says so, and a line that is
/// not G-code is an error naming its line.
#[test]
fn machine_gcode_sets_the_printers_limits() {
    let dir = std::env::temp_dir().join(format!("quietpath-m503-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let m503 = dir.join("m503.txt");
    std::fs::write(
        &m503,
        "echo:; Maximum Acceleration (units/s2):\necho:  M201 X500 Y500 Z100 E1000\n\
         echo:; Acceleration (units/s2): P<print_accel> R<retract_accel> T<travel_accel>\n\
         echo:  M204 P400.00 R1000.00 T400.00\necho:  M92 X80.00 Y80.00 Z400.00 E93.00\nok\n",
    )
    .unwrap();
    // A Marlin file without limit commands of its own (they would win, as on the printer).
    let file = corpus("slic3r-pe-1.33.3_benchy_arcwelder.gcode");
    let run = |extra: &[&std::ffi::OsStr]| {
        let out = Command::new(env!("CARGO_BIN_EXE_quietpath"))
            .arg("analyze")
            .arg(&file)
            .arg("--json")
            .args(extra)
            .output()
            .unwrap();
        (
            out.status.success(),
            out.stdout,
            String::from_utf8_lossy(&out.stderr).to_string(),
        )
    };
    let (ok, plain, err) = run(&[]);
    assert!(ok, "{err}");
    let (ok, slow, err) = run(&["--machine-gcode".as_ref(), m503.as_os_str()]);
    assert!(ok, "{err}");
    let (plain, slow): (serde_json::Value, serde_json::Value) = (
        serde_json::from_slice(&plain).unwrap(),
        serde_json::from_slice(&slow).unwrap(),
    );
    assert!(slow["time_s"].as_f64() > plain["time_s"].as_f64());
    let accel = &slow["machine"]["limits"]["max_acceleration"][0];
    assert_eq!(accel["value"], 500.0);
    assert_eq!(accel["source"], "machine_settings");
    std::fs::write(&m503, "Recv: echo:  M201 X500\nG1 X1..5\n").unwrap();
    let (ok, _, err) = run(&["--machine-gcode".as_ref(), m503.as_os_str()]);
    assert!(!ok);
    assert!(err.contains("machine settings, line 2"), "{err}");
}
