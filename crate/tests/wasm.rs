//! The same parser and analysis, compiled to wasm32 and run in Node (`wasm-pack test --node`).
#![cfg(target_arch = "wasm32")]

use js_sys::Reflect;
use wasm_bindgen::{JsCast, JsValue};
use wasm_bindgen_test::wasm_bindgen_test;

use quietpath::analyze::{analyze, AnalyzeOptions, LayerSource};
use quietpath::gcode::{apply_edits, parse_line};

/// A real SuperSlicer + ArcWelder file from the shared corpus (read at compile time).
const SUPERSLICER: &[u8] =
    include_bytes!("../../../shared/corpus/superslicer-2.3.56_klipper_arcwelder.gcode");
/// A real Kiri:Moto file that never says M82/M83.
const KIRIMOTO: &[u8] = include_bytes!("../../../shared/corpus/kirimoto-3.0_voron.gcode");

#[wasm_bindgen_test]
fn analyzes_a_real_file_like_native() {
    let r = analyze(SUPERSLICER, &AnalyzeOptions::default()).expect("analyze");
    assert_eq!(r.layers, 25);
    assert!(matches!(r.layer_source, LayerSource::Markers(_)));
    // SuperSlicer's own summary: filament used [mm] = 264.59
    assert!(
        (r.filament_mm - 264.59).abs() < 0.01 * 264.59,
        "{}",
        r.filament_mm
    );
    assert!(r.time_s > 0.0);
}

#[wasm_bindgen_test]
fn infers_relative_extrusion() {
    let r = analyze(KIRIMOTO, &AnalyzeOptions::default()).expect("analyze");
    assert_eq!(r.layers, 25);
    assert!(
        (r.filament_mm - 225.03).abs() < 0.05 * 225.03,
        "{}",
        r.filament_mm
    );
}

#[wasm_bindgen_test]
fn round_trips_byte_identically() {
    assert!(apply_edits(SUPERSLICER, &[]) == SUPERSLICER);
}

#[wasm_bindgen_test]
fn parser_rejects_non_finite_numbers() {
    let e = parse_line(b"G1 X1e999").expect_err("1e999 overflows");
    assert_eq!(e.column, 5);
    let l = parse_line(b"g1x.5e1").expect("compact lower case");
    assert_eq!(l.params.get(b'X'), Some(0.5));
    assert_eq!(l.params.get(b'E'), Some(1.0));
}

#[wasm_bindgen_test]
fn binding_returns_plain_objects_and_js_errors() {
    let report =
        quietpath::wasm::analyze_js(JsValue::from_str("M83\nG1 X10 E1 F600\n"), None, None)
            .expect("report");
    let moves = Reflect::get(&report, &JsValue::from_str("moves")).expect("moves");
    assert_eq!(moves.as_f64(), Some(1.0));
    let strict = js_sys::JSON::parse(r#"{"strict": true}"#).expect("json");
    let err = quietpath::wasm::analyze_js(
        JsValue::from_str("G1 X1\nG1 X1e999\n"),
        Some(strict.unchecked_into()),
        None,
    )
    .expect_err("strict");
    assert!(err.is_instance_of::<js_sys::Error>());
    let line = Reflect::get(&err, &JsValue::from_str("line")).expect("line");
    assert_eq!(line.as_f64(), Some(2.0));
    let bad_opts = js_sys::JSON::parse(r#"{"filament_diameter_mm": -1}"#).expect("json");
    assert!(quietpath::wasm::analyze_js(
        JsValue::from_str("G1 X1"),
        Some(bad_opts.unchecked_into()),
        None
    )
    .is_err());
}

/// The thesis's Table 3, read at compile time from the committed fixture.
const TABLE3: &str = include_str!("data/thesis_table3.csv");

#[wasm_bindgen_test]
fn calibrate_reproduces_table_3_in_wasm() {
    let fit = quietpath::wasm::calibrate(JsValue::from_str(TABLE3)).expect("fit");
    let get = |k: &str| {
        Reflect::get(&fit, &JsValue::from_str(k))
            .expect(k)
            .as_f64()
            .expect(k)
    };
    for (k, published) in [
        ("k_a_mx", 0.134857071),
        ("k_a_my", 0.131575661),
        ("k_c", 69.14025683),
        ("k_h", 832.7358875),
    ] {
        let v = get(k);
        assert!(((v - published) / published).abs() < 5e-7, "{k}: {v}");
    }
    let bad = quietpath::wasm::calibrate(JsValue::from_str("A,B,C,H,E\n1,2,3,4,x\n"))
        .expect_err("bad row");
    assert!(bad.is_instance_of::<js_sys::Error>());
}
