//! Volumetric extrusion: E words as cubic millimetres of filament (Cura's "Marlin
//! (Volumetric)" flavour, `M200 D`). The oracle is the same part sliced twice by CuraEngine
//! with the same settings, E in millimetres and E in mm³ (`tests/data/make_volumetric.sh`):
//! both must read as the same print, and the rewriters must write each in its own units.
#![cfg(not(target_arch = "wasm32"))]
#![allow(clippy::unwrap_used)]

use std::path::Path;

use quietpath::infill::{infill, Choice, InfillOptions, Pattern};
use quietpath::vtg::{vtg, VtgOptions};
use quietpath::{analyze, AnalyzeOptions, Report};

fn data(name: &str) -> Vec<u8> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name);
    std::fs::read(path).unwrap()
}

fn read(bytes: &[u8]) -> Report {
    analyze(bytes, &AnalyzeOptions::default()).unwrap()
}

/// `a` within `share` of `b`.
fn near(a: f64, b: f64, share: f64) -> bool {
    (a / b - 1.0).abs() <= share
}

/// The two slices differ only where Cura's own start G-code primes a literal `E3` (3 mm of
/// filament in one, 3 mm³ in the other) and in the rounding of the words: 0.5 % covers both,
/// and reading mm³ as mm would be 2.4 times the filament.
const SAME_PRINT: f64 = 0.005;

#[test]
fn a_volumetric_file_reads_as_the_same_print_as_its_linear_twin() {
    let linear = read(&data("cura_plate_linear.gcode"));
    let volumetric = read(&data("cura_plate_volumetric.gcode"));
    assert!(
        near(volumetric.filament_mm, linear.filament_mm, SAME_PRINT),
        "filament {} mm against {} mm",
        volumetric.filament_mm,
        linear.filament_mm
    );
    assert!(near(volumetric.material_g, linear.material_g, SAME_PRINT));
    assert!(near(volumetric.time_s, linear.time_s, SAME_PRINT));
    assert!(near(
        volumetric.energy.total_j,
        linear.energy.total_j,
        SAME_PRINT
    ));
    let says = |r: &Report| {
        r.warnings
            .iter()
            .any(|w| w.message.contains("volumes (mm³)"))
    };
    assert!(says(&volumetric) && !says(&linear));
}

#[test]
fn an_m200_diameter_turns_volumes_into_filament() {
    let area = std::f64::consts::PI * 2.85 * 2.85 / 4.0;
    let src = format!("M83\nM200 D2.85\nG1 X10 F600 E{area}\nM200 D0\nG1 X20 E1\n");
    let r = read(src.as_bytes());
    assert!((r.filament_mm - 2.0).abs() < 1e-9, "{}", r.filament_mm);
}

/// The infill search measures the file's habit in filament and writes the new infill's words
/// in the file's units: the volumetric file's regenerated infill lays down what the linear
/// one's does.
#[test]
fn infill_writes_volumes_into_a_volumetric_file() {
    let options = InfillOptions {
        angles_deg: vec![45.0],
        patterns: vec![Pattern::Rectilinear],
        force_candidate: true,
        ..InfillOptions::default()
    };
    let run = |name: &str| {
        let input = data(name);
        let r = infill(&input, &options).unwrap();
        assert_ne!(r.best.pattern, Choice::Original, "{name}");
        (read(&input).filament_mm, read(&r.output).filament_mm)
    };
    let (linear_before, linear_after) = run("cura_plate_linear.gcode");
    let (volumetric_before, volumetric_after) = run("cura_plate_volumetric.gcode");
    let change = |before: f64, after: f64| after - before;
    let linear = change(linear_before, linear_after);
    let volumetric = change(volumetric_before, volumetric_after);
    assert!(
        (volumetric - linear).abs() <= SAME_PRINT * linear_before,
        "filament change {volumetric} mm against {linear} mm"
    );
    assert!(near(volumetric_after, linear_after, SAME_PRINT));
}

/// VTG keeps the file's E words along each rounded path: a volumetric file keeps its filament.
#[test]
fn vtg_keeps_the_filament_of_a_volumetric_file() {
    let input = data("cura_plate_volumetric.gcode");
    let options = VtgOptions {
        dynamics: false,
        allow_more_lines_pct: 1000.0,
        ..VtgOptions::default()
    };
    let r = vtg(&input, &options).unwrap();
    assert!(r.paths.rewritten > 0);
    let (before, after) = (read(&input).filament_mm, read(&r.output).filament_mm);
    assert!(near(after, before, 1e-4), "{after} mm against {before} mm");
}
