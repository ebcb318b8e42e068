//! Energy models: closed forms of the thesis stepper model through the whole analysis, the
//! thesis's Table 3 calibration, `E_fuse` and CO₂ by hand, every corpus file, and the thesis's
//! finding on infill direction with real PrusaSlicer slices.
#![cfg(not(target_arch = "wasm32"))]

use std::path::{Path, PathBuf};
use std::process::Command;

use quietpath::analyze::{analyze, AnalyzeOptions, Report};
use quietpath::energy::calibrate::{f_upper_tail, fit, parse_csv, CalibrationError, CsvRows};
use quietpath::energy::{EnergyOptions, Material, ServoModel, ThesisCoefficients};
use quietpath::plan::{JunctionModel, Limit, MachineProfile};

const K: ThesisCoefficients = ThesisCoefficients::PUBLISHED;

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

fn corpus_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/corpus")
}

fn close(got: f64, want: f64, rel: f64) -> bool {
    (got - want).abs() <= rel * want.abs().max(1e-300)
}

/// A machine that starts and stops every move at rest (classic jerk with zero jerk) and
/// accelerates at 1000 mm/s² on every kind of move, with no per-axis limit in the way.
fn rest_to_rest() -> AnalyzeOptions {
    let mut p = MachineProfile::preset("prusa-mk3s").expect("preset");
    p.name = "rest-to-rest".into();
    p.junction = JunctionModel::ClassicJerk;
    p.limits.max_jerk = [Limit::profile(0.0); 4];
    p.limits.max_acceleration = [Limit::profile(100_000.0); 4];
    p.limits.max_feedrate = [Limit::profile(1000.0); 4];
    p.limits.acceleration = Limit::profile(1000.0);
    p.limits.travel_acceleration = Limit::profile(1000.0);
    p.limits.retract_acceleration = Limit::profile(1000.0);
    AnalyzeOptions {
        machine_profile: Some(p),
        junction_model: Some(JunctionModel::ClassicJerk),
        ..AnalyzeOptions::default()
    }
}

fn run(gcode: &str, options: &AnalyzeOptions) -> Report {
    analyze(gcode.as_bytes(), options).expect("analyze")
}

#[test]
fn single_x_move_from_rest_to_rest() {
    // 100 mm at 50 mm/s with 1000 mm/s²: t_a = t_d = 0.05 s (1.25 mm each), t_c = 1.95 s.
    let r = run("G21\nG90\nM83\nG1 X100 F3000\n", &rest_to_rest());
    let t = r.energy.thesis;
    // A = t_a·a·(0 + 50)/2 + t_d·a·(50 + 0)/2 = 0.05·1000·25 + 0.05·1000·25 = 2500 (mm/s)².
    assert!(close(t.a, 2500.0, 1e-12), "A = {}", t.a);
    assert_eq!(t.b, 0.0);
    // C = t_c·v_xm = 1.95 s·50 mm/s = 97.5 mm.
    assert!(close(t.c, 97.5, 1e-12), "C = {}", t.c);
    // Y holds for the whole move: 0.05 + 1.95 + 0.05 s.
    assert!(close(t.h, 2.05, 1e-12), "H = {}", t.h);
    assert!(close(r.time_s, 2.05, 1e-12));
    let by_hand = (K.k_a_mx * 2500.0 + K.k_c * 97.5 + K.k_h * 2.05) / 1000.0;
    assert!(close(r.energy.thesis_j, by_hand, 1e-12));
    assert!(close(t.e_wms, by_hand * 1000.0, 1e-12));
    assert_eq!(r.energy.servo_j, r.energy.thesis_j);
}

#[test]
fn pure_y_move_has_no_x_term_and_x_holds() {
    let r = run("G21\nG90\nM83\nG1 Y100 F3000\n", &rest_to_rest());
    let t = r.energy.thesis;
    assert_eq!(t.a, 0.0);
    assert!(close(t.b, 2500.0, 1e-12));
    assert!(close(t.c, 97.5, 1e-12));
    assert!(close(t.h, r.time_s, 1e-12), "H = {} vs {}", t.h, r.time_s);
    let by_hand = (K.k_a_my * 2500.0 + K.k_c * 97.5 + K.k_h * 2.05) / 1000.0;
    assert!(close(r.energy.thesis_j, by_hand, 1e-12));
}

#[test]
fn diagonal_move_splits_equally() {
    // 45°: each axis moves at v/√2 and accelerates at a/√2, so each gets half of v² = 2500.
    let r = run("G21\nG90\nM83\nG1 X100 Y100 F3000\n", &rest_to_rest());
    let t = r.energy.thesis;
    assert!(close(t.a, 1250.0, 1e-12), "A = {}", t.a);
    assert!(close(t.b, 1250.0, 1e-12), "B = {}", t.b);
    // Both axes coast: C = t_c·(v/√2 + v/√2) = cruise distance·√2.
    let d = 100.0 * std::f64::consts::SQRT_2;
    assert!(close(t.c, (d - 2.5) * std::f64::consts::SQRT_2, 1e-12));
    assert_eq!(t.h, 0.0);
}

#[test]
fn extruder_only_moves_and_dwells_hold_both_axes() {
    let r = run("G21\nG90\nM83\nG1 E-2 F1800\nG4 P1500\n", &rest_to_rest());
    let t = r.energy.thesis;
    assert_eq!([t.a, t.b, t.c], [0.0; 3]);
    // Retraction: 2 mm at 30 mm/s, 1000 mm/s²; t_a = t_d = 0.03 s, 1.1 mm cruising.
    let retract = 0.06 + (2.0 - 0.9) / 30.0;
    assert!(close(t.h, 2.0 * (retract + 1.5), 1e-12), "H = {}", t.h);
    assert!(close(r.time_s, retract + 1.5, 1e-12));
}

#[test]
fn features_and_layers_share_servo_and_aux_energy() {
    let gcode = "G21\nG90\nM83\nM140 S60\nM104 S215\nM106 S255\n;LAYER:0\n;TYPE:WALL-OUTER\n\
                 G1 X50 Y0 E2 F1800\nG1 X50 Y50 E2\n;TYPE:FILL\nG1 X0 Y0 E3\nG0 X10 Y20 F6000\n";
    let r = run(gcode, &rest_to_rest());
    let e = &r.energy;
    let features: f64 = r.features.iter().map(|f| f.energy_j).sum();
    let layers: f64 = r.layer_list.iter().map(|l| l.energy_j).sum();
    // No dwells and every move in a feature and a layer: the shares add up.
    assert!(
        close(features, e.servo_j + e.aux_j, 1e-12),
        "{features} vs {e:?}"
    );
    assert!(close(layers, e.servo_j + e.aux_j, 1e-12));
    let wall = r
        .features
        .iter()
        .find(|f| f.name == "WALL-OUTER")
        .expect("wall");
    assert!(wall.energy_j > 0.0);
}

#[test]
fn fuse_energy_by_hand() {
    // 10 mm of 1.75 mm PLA at 1.24 g/cm³, printed at 215 °C from 25 °C.
    let r = run(
        "M83\nM104 S215\nG1 X20 E10 F1200\n",
        &AnalyzeOptions::default(),
    );
    let mass_g = 10.0 * std::f64::consts::PI * 0.875 * 0.875 * 1.24 / 1000.0;
    assert!(close(r.energy.material_g, mass_g, 1e-12));
    let heat_per_g = 1.7 * (215.0 - 25.0) + 93.0 * 0.1;
    assert!(close(r.energy.fuse_j, mass_g * heat_per_g / 0.9, 1e-12));
    assert_eq!(r.energy.fuse.print_temp_c, 215.0);
    // PETG is amorphous: no latent heat; and the options' temperature is used when the file
    // sets none.
    let petg = AnalyzeOptions {
        energy: Some(EnergyOptions {
            material: Some(Material::Petg),
            heater_efficiency: 1.0,
            ..EnergyOptions::default()
        }),
        ..AnalyzeOptions::default()
    };
    let r = run("M83\nG1 X20 E10 F1200\n", &petg);
    assert!(close(r.energy.fuse_j, mass_g * 1.6 * (240.0 - 25.0), 1e-12));
}

#[test]
fn co2_is_grid_times_energy_plus_material_factor_times_mass() {
    let r = run(
        "M83\nM140 S60\nM104 S215\nG1 X20 E10 F1200\nG1 X0 Y30 E10\n",
        &AnalyzeOptions::default(),
    );
    let e = &r.energy;
    let by_hand = 0.475 * e.total_j / 3.6e6 * 1000.0 + 2.0 * e.material_g;
    assert!(close(e.co2_g, by_hand, 1e-12));
    let custom = AnalyzeOptions {
        energy: Some(EnergyOptions {
            grid_kg_co2_per_kwh: 0.1,
            material_kg_co2_per_kg: Some(5.0),
            ..EnergyOptions::default()
        }),
        ..AnalyzeOptions::default()
    };
    let c = run(
        "M83\nM140 S60\nM104 S215\nG1 X20 E10 F1200\nG1 X0 Y30 E10\n",
        &custom,
    );
    let by_hand = 0.1 * c.energy.total_j / 3.6e6 * 1000.0 + 5.0 * c.energy.material_g;
    assert!(close(c.energy.co2_g, by_hand, 1e-12));
    assert!(close(
        c.energy.co2_g,
        c.energy.co2.energy_g + c.energy.co2.material_g,
        1e-12
    ));
}

#[test]
fn table3_calibration_reproduces_the_published_coefficients() {
    let text = std::fs::read_to_string(data("thesis_table3.csv")).expect("csv");
    let CsvRows::Terms(rows) = parse_csv(&text).expect("parse") else {
        panic!("Table 3 has A,B,C,H,E rows");
    };
    assert_eq!(rows.len(), 10);
    let cal = fit(&rows).expect("fit");
    // Six significant digits.
    for (got, want) in [
        (cal.k_a_mx, 0.134857071),
        (cal.k_a_my, 0.131575661),
        (cal.k_c, 69.14025683),
        (cal.k_h, 832.7358875),
    ] {
        assert!(close(got, want, 5e-7), "{got} vs {want}");
    }
    // The thesis's regression statistics: R² 0.9989 (multiple R 0.999460), F 1388.569474.
    assert!((cal.r2 - 0.9989).abs() < 5e-5, "{}", cal.r2);
    assert!((cal.r2.sqrt() - 0.999460).abs() < 5e-7);
    assert!(
        close(cal.f_statistic, 1388.569474, 1e-9),
        "{}",
        cal.f_statistic
    );
    // Its p-value 8.48532e-8 is Excel's, with n − 5 residual degrees of freedom.
    assert!(close(
        f_upper_tail(cal.f_statistic, 4.0, 5.0),
        8.48532e-8,
        1e-5
    ));
    assert!(cal.p_value < 8.48532e-8);
    assert_eq!(cal.n, 10);
    assert_eq!(cal.residuals.len(), 10);
    assert_eq!(
        cal.residuals[0].row, 2,
        "rows are CSV lines (after the header)"
    );
    let ss: f64 = cal.residuals.iter().map(|r| r.residual * r.residual).sum();
    assert!(close(cal.rmse, (ss / 10.0).sqrt(), 1e-12));
    assert_eq!(cal.coefficients().k_c, cal.k_c);
}

#[test]
fn calibration_errors_name_the_row() {
    let e = parse_csv("A,B,C,H,E\n1,2,3,4,5\n\n1,2,3,4,nan\n").expect_err("nan");
    assert!(
        matches!(
            e,
            CalibrationError::OutOfRange {
                row: 4,
                column: 5,
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().starts_with("row 4, column 5"));
    let e = parse_csv("1;2;3\n").expect_err("3 fields");
    assert!(matches!(
        e,
        CalibrationError::Columns {
            row: 1,
            found: 3,
            ..
        }
    ));
    let rows = match parse_csv("1,2,3,4,5\n2,3,4,5,6\n").expect("parse") {
        CsvRows::Terms(r) => r,
        CsvRows::Gcode(_) => panic!("terms"),
    };
    assert!(matches!(
        fit(&rows),
        Err(CalibrationError::TooFewRows {
            needed: 5,
            found: 2
        })
    ));
}

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_quietpath"))
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("quietpath-energy-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

#[test]
fn calibrate_cli_on_table3() {
    let out = bin()
        .args(["calibrate", "--json"])
        .arg(data("thesis_table3.csv"))
        .output()
        .expect("run");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    for key in [
        "k_a_mx",
        "k_a_my",
        "k_c",
        "k_h",
        "r2",
        "adjusted_r2",
        "rmse",
        "f_statistic",
        "n",
        "residuals",
    ] {
        assert!(v.get(key).is_some(), "missing {key}");
    }
    assert!(close(v["k_h"].as_f64().expect("k_h"), 832.7358875, 5e-7));
    assert_eq!(v["n"], 10);

    let dir = scratch("bad");
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "A,B,C,H,E\n1,2,3,4,5\n1,2,oops,4,5\n").expect("write");
    let out = bin().arg("calibrate").arg(&bad).output().expect("run");
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("row 3, column 3"), "{err}");
}

#[test]
fn calibrate_cli_from_gcode_files_recovers_known_coefficients() {
    // Energies made with known coefficients for real files; the fit must find them again.
    let truth = ThesisCoefficients {
        k_a_mx: 0.2,
        k_a_my: 0.1,
        k_c: 50.0,
        k_h: 1500.0,
    };
    let dir = scratch("gcode");
    let files: Vec<PathBuf> = [
        "rect_infill_0.gcode",
        "rect_infill_45.gcode",
        "rect_infill_90.gcode",
    ]
    .iter()
    .map(|n| data(n))
    .chain(
        [
            "prusaslicer-2.7.4_screw_arcfit.gcode",
            "superslicer-2.3.56_klipper_arcwelder.gcode",
            "kirimoto-3.0_voron.gcode",
        ]
        .iter()
        .map(|n| corpus_dir().join(n)),
    )
    .collect();
    let mut csv = String::from("gcode_path,energy_j\n");
    for (i, f) in files.iter().enumerate() {
        let name = format!("print {i}.gcode");
        std::fs::copy(f, dir.join(&name)).expect("copy");
        let r =
            analyze(&std::fs::read(f).expect("read"), &AnalyzeOptions::default()).expect("analyze");
        let t = r.energy.thesis;
        let e_j = truth.energy_j(&[t.a, t.b, t.c, t.h]);
        csv += &format!("\"{name}\",{e_j:.17e}\n");
    }
    let csv_path = dir.join("measured.csv");
    std::fs::write(&csv_path, csv).expect("write");
    let out = bin()
        .args(["calibrate", "--json"])
        .arg(&csv_path)
        .output()
        .expect("run");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    for (key, want) in [
        ("k_a_mx", truth.k_a_mx),
        ("k_a_my", truth.k_a_my),
        ("k_c", truth.k_c),
        ("k_h", truth.k_h),
    ] {
        let got = v[key].as_f64().expect(key);
        assert!(close(got, want, 1e-6), "{key}: {got} vs {want}");
    }
    // A missing file is reported with its row.
    std::fs::write(&csv_path, "gcode_path,energy_j\nnope.gcode,1\n").expect("write");
    let out = bin().arg("calibrate").arg(&csv_path).output().expect("run");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("row 2"));
}

#[test]
fn every_corpus_file_has_finite_positive_energies_that_add_up() {
    let mut n = 0;
    for entry in std::fs::read_dir(corpus_dir()).expect("corpus") {
        let path = entry.expect("entry").path();
        if path.extension().is_none_or(|e| e != "gcode") {
            continue;
        }
        let bytes = std::fs::read(&path).expect("read");
        let r = analyze(&bytes, &AnalyzeOptions::default())
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        let e = &r.energy;
        let name = path.display();
        for (what, v) in [
            ("thesis_j", e.thesis_j),
            ("servo_j", e.servo_j),
            ("fuse_j", e.fuse_j),
            ("aux_j", e.aux_j),
            ("total_j", e.total_j),
            ("co2_g", e.co2_g),
            ("material_g", e.material_g),
        ] {
            assert!(v.is_finite() && v > 0.0, "{name}: {what} = {v}");
        }
        assert!(
            close(e.total_j, e.servo_j + e.fuse_j + e.aux_j, 1e-12),
            "{name}"
        );
        assert!(close(e.total_kwh * 3.6e6, e.total_j, 1e-12), "{name}");
        for v in [e.thesis.a, e.thesis.b, e.thesis.c, e.thesis.h] {
            assert!(v.is_finite() && v >= 0.0, "{name}: {:?}", e.thesis);
        }
        // Shares never exceed what they share out.
        let features: f64 = r.features.iter().map(|f| f.energy_j).sum();
        let layers: f64 = r.layer_list.iter().map(|l| l.energy_j).sum();
        let shared = e.servo_j + e.aux_j;
        assert!(
            features > 0.0 && features <= shared * (1.0 + 1e-9),
            "{name}"
        );
        assert!(layers <= shared * (1.0 + 1e-9), "{name}");
        assert!(r
            .layer_list
            .iter()
            .all(|l| l.energy_j.is_finite() && l.energy_j >= 0.0));
        n += 1;
    }
    assert!(n >= 10, "only {n} corpus files");
}

#[test]
fn servo_preset_uses_the_physical_model() {
    let bytes = std::fs::read(data("rect_infill_0.gcode")).expect("read");
    let options = AnalyzeOptions {
        machine: Some("vtg-ldam-servo".into()),
        ..AnalyzeOptions::default()
    };
    let r = analyze(&bytes, &options).expect("analyze");
    let e = &r.energy;
    assert_eq!(e.servo_model, ServoModel::Physical);
    let parts = e.physical_servo.expect("physical parts");
    assert!(close(e.servo_j, parts.total_j(), 1e-12));
    assert!(parts.kinetic_j > 0.0 && parts.friction_j > 0.0 && parts.standby_j > 0.0);
    assert!(e.thesis_j > 0.0 && e.thesis_j != e.servo_j);
    assert!(close(e.total_j, e.servo_j + e.fuse_j + e.aux_j, 1e-12));
    // And the thesis model on request.
    let thesis = AnalyzeOptions {
        energy: Some(EnergyOptions {
            servo_model: ServoModel::Thesis,
            ..EnergyOptions::default()
        }),
        ..options
    };
    let t = analyze(&bytes, &thesis).expect("analyze");
    assert_eq!(t.energy.servo_j, t.energy.thesis_j);
    assert!(t.energy.physical_servo.is_none());
}

#[test]
fn invalid_energy_options_are_rejected() {
    let bad = AnalyzeOptions {
        energy: Some(EnergyOptions {
            grid_kg_co2_per_kwh: f64::NAN,
            ..EnergyOptions::default()
        }),
        ..AnalyzeOptions::default()
    };
    assert!(analyze(b"G1 X1\n", &bad).is_err());
    let json = r#"{"energy": {"material": "abs", "aux": {"fan_w": 5}}}"#;
    let o: AnalyzeOptions = serde_json::from_str(json).expect("options");
    assert_eq!(
        o.energy.as_ref().and_then(|e| e.material),
        Some(Material::Abs)
    );
    assert!(serde_json::from_str::<AnalyzeOptions>(r#"{"energy": {"nope": 1}}"#).is_err());
}

/// The thesis's finding (Somade 2023, Fig. 11 and strategy 2): for a rectangular part,
/// rectilinear infill at 45° costs more X/Y stepper energy than at 0° or 90°. Checked on real
/// PrusaSlicer slices (`tests/data/make_rect.sh`).
#[test]
fn infill_at_45_degrees_costs_the_most_stepper_energy() {
    let report = |angle: u32| {
        let bytes = std::fs::read(data(&format!("rect_infill_{angle}.gcode"))).expect("read");
        analyze(&bytes, &AnalyzeOptions::default()).expect("analyze")
    };
    let (r0, r45, r90) = (report(0), report(45), report(90));
    let (e0, e45, e90) = (r0.energy.thesis_j, r45.energy.thesis_j, r90.energy.thesis_j);
    assert!(
        e45 > e0 && e45 > e90,
        "0°: {e0} J, 45°: {e45} J, 90°: {e90} J"
    );
    // Why: diagonal lines make both axes coast (C up by up to √2) and accelerate, while
    // axis-aligned lines let one axis hold (H down at 45°).
    let (t0, t45) = (r0.energy.thesis, r45.energy.thesis);
    assert!(t45.c > t0.c && t45.h < t0.h, "{t0:?} vs {t45:?}");
}
