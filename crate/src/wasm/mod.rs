//! WebAssembly bindings: type conversion and error mapping only, no logic.
//!
//! Results cross the boundary as the same JSON the CLI prints (serialised by `serde_json`, then
//! parsed by the JS engine), so a report from the browser, Node and the CLI is identical.
//! Errors become JS `Error` objects carrying `line`, `column` and `kind` properties.

mod apart;
mod jobs;
mod session;

pub use apart::{ReadApart, TimingApart};
pub use jobs::{infill, smooth, vibration, vtg};
pub use session::Session;
// The threaded build's pool of Web Workers: `await initThreadPool(n)`, then `usePool(n)`.
#[cfg(feature = "threads")]
pub use wasm_bindgen_rayon::init_thread_pool;

use js_sys::{Function, Reflect, Uint8Array};
use wasm_bindgen::prelude::*;
use wasm_bindgen::JsCast;

use crate::analyze::{analyze_with_progress, AnalyzeOptions};
use crate::energy::calibrate::{self, CalibrationError, CsvRows, Observation};
use crate::error::Error;
use crate::plan::profiles::PRESETS;
use crate::plan::MachineProfile;

// The reports and options, generated from the Rust types (crate/src/ts_types.rs), so that the
// declarations cannot drift from the JSON.
#[wasm_bindgen(typescript_custom_section)]
const GENERATED_TYPES: &str = include_str!("types.generated.d.ts");

// What is not a Rust serde type: typed-array results, callbacks, thrown errors.
#[wasm_bindgen(typescript_custom_section)]
const TYPES: &str = include_str!("types.d.ts");

#[wasm_bindgen]
extern "C" {
    /// `AnalyzeOptions` in TypeScript.
    #[wasm_bindgen(typescript_type = "AnalyzeOptions")]
    #[derive(Debug)]
    pub type JsAnalyzeOptions;
    /// `ProgressCallback` in TypeScript.
    #[wasm_bindgen(typescript_type = "ProgressCallback")]
    #[derive(Debug)]
    pub type JsProgress;
}

/// Installs the panic hook so that a bug shows its message in the console instead of an
/// anonymous `unreachable`.
#[wasm_bindgen(start)]
pub fn start() {
    console_error_panic_hook::set_once();
}

/// Runs the parallel maps (VTG's paths, the infill search's candidates, the dynamics model's
/// layers) on the `workers` pool workers from now on; call it once `initThreadPool(workers)`
/// has resolved. Threaded build only.
#[cfg(feature = "threads")]
#[wasm_bindgen(js_name = usePool)]
pub fn use_pool(workers: usize) {
    crate::parallel::use_pool(workers);
}

/// Threads the parallel maps use: the pool's workers, or 1 (the plain build, or before
/// `usePool`).
#[wasm_bindgen]
pub fn threads() -> usize {
    crate::parallel::threads()
}

/// The library version.
#[wasm_bindgen]
pub fn version() -> String {
    crate::VERSION.to_string()
}

/// The built-in machine presets (`--machine NAME`), each as its profile: name, description,
/// junction model and limits.
#[wasm_bindgen(unchecked_return_type = "MachineProfile[]")]
pub fn machines() -> Result<JsValue, JsValue> {
    let list: Vec<MachineProfile> = PRESETS
        .iter()
        .copied()
        .filter_map(MachineProfile::preset)
        .collect();
    to_js(&list)
}

/// Turns a core error into a JS `Error` with position properties. The one error helper.
fn js_error(e: &Error) -> JsValue {
    let err = js_sys::Error::new(&e.to_string());
    let set = |k: &str, v: JsValue| {
        let _ = Reflect::set(&err, &JsValue::from_str(k), &v);
    };
    // An error about the whole file or the options has no position: left unset, not 0.
    if e.line > 0 {
        set("line", JsValue::from(e.line));
    }
    if e.column > 0 {
        set("column", JsValue::from(e.column));
    }
    if let Ok(kind) = serde_json::to_string(&e.kind) {
        if let Ok(v) = js_sys::JSON::parse(&kind) {
            set("kind", v);
        }
    }
    err.into()
}

fn message_error(msg: &str) -> JsValue {
    js_sys::Error::new(msg).into()
}

/// Input bytes from a `Uint8Array`, an `ArrayBuffer` or a string.
fn input_bytes(input: &JsValue) -> Result<Vec<u8>, JsValue> {
    if let Some(s) = input.as_string() {
        return Ok(s.into_bytes());
    }
    if input.is_instance_of::<Uint8Array>() || input.is_instance_of::<js_sys::ArrayBuffer>() {
        return Ok(Uint8Array::new(input).to_vec());
    }
    Err(message_error(
        "input must be a string, a Uint8Array or an ArrayBuffer",
    ))
}

fn options<T: serde::de::DeserializeOwned + Default>(
    value: Option<&JsValue>,
) -> Result<T, JsValue> {
    let Some(value) = value.filter(|v| !v.is_undefined() && !v.is_null()) else {
        return Ok(T::default());
    };
    // Through JSON rather than serde-wasm-bindgen: the options then read exactly like the
    // CLI's JSON files, and unknown fields (typos) are refused instead of silently ignored.
    let text = js_sys::JSON::stringify(value)
        .ok()
        .and_then(|s| s.as_string())
        .ok_or_else(|| message_error("invalid options: not JSON-serialisable"))?;
    serde_json::from_str(&text).map_err(|e| message_error(&format!("invalid options: {e}")))
}

fn to_js<T: serde::Serialize>(value: &T) -> Result<JsValue, JsValue> {
    let json = serde_json::to_string(value).map_err(|e| message_error(&e.to_string()))?;
    js_sys::JSON::parse(&json)
}

/// Progress adapter: calls `f(fraction)`; a callback returning `false` cancels the job.
fn progress_fn(f: Option<JsProgress>) -> impl FnMut(f64) -> bool {
    let f: Option<Function> = f.map(|f| f.unchecked_into());
    move |fraction| match &f {
        Some(f) => match f.call1(&JsValue::NULL, &JsValue::from_f64(fraction)) {
            Ok(v) => v.as_bool() != Some(false),
            Err(_) => true,
        },
        None => true,
    }
}

/// Analyzes G-code (`string`, `Uint8Array` or `ArrayBuffer`); same report as
/// `quietpath analyze --json`.
#[wasm_bindgen(js_name = analyze, unchecked_return_type = "Report")]
pub fn analyze_js(
    #[wasm_bindgen(unchecked_param_type = "string | Uint8Array | ArrayBuffer")] input: JsValue,
    options_value: Option<JsAnalyzeOptions>,
    on_progress: Option<JsProgress>,
) -> Result<JsValue, JsValue> {
    let bytes = input_bytes(&input)?;
    let opts: AnalyzeOptions = options(options_value.as_deref())?;
    let mut progress = progress_fn(on_progress);
    let report = analyze_with_progress(&bytes, &opts, &mut progress).map_err(|e| js_error(&e))?;
    to_js(&report)
}

/// A calibration error as a JS `Error` with `kind` and the error's fields (`row`, `column`...).
fn calibration_error(e: &CalibrationError) -> JsValue {
    let err = js_sys::Error::new(&e.to_string());
    if let Ok(fields) = to_js(e) {
        let _ = js_sys::Object::assign(&err, &fields.into());
    }
    err.into()
}

/// One calibration row from JS: `[A, B, C, H, E]` or `{a, b, c, h, e}` (E in W·ms).
#[derive(serde::Deserialize)]
#[serde(untagged)]
enum RowInput {
    Array([f64; 5]),
    Object(Observation),
}

/// Fits the thesis energy model (`quietpath calibrate --json`): `rows` is an array of
/// `[A, B, C, H, E]` or `{a, b, c, h, e}` rows, or CSV text with `A,B,C,H,E` rows (G-code rows
/// need files, so only the CLI takes them). Rows are numbered from 1 in errors and residuals.
#[wasm_bindgen(unchecked_return_type = "CalibrationFit")]
pub fn calibrate(
    #[wasm_bindgen(unchecked_param_type = "CalibrationRow[] | string")] rows: JsValue,
) -> Result<JsValue, JsValue> {
    let observations = if let Some(text) = rows.as_string() {
        match calibrate::parse_csv(&text).map_err(|e| calibration_error(&e))? {
            CsvRows::Terms(rows) => rows,
            CsvRows::Gcode(_) => {
                return Err(message_error(
                    "G-code rows need the files: use the CLI, or give A,B,C,H,E rows",
                ))
            }
        }
    } else {
        let input: Vec<RowInput> = serde_wasm_bindgen::from_value(rows)
            .map_err(|e| message_error(&format!("invalid rows: {e}")))?;
        input
            .into_iter()
            .enumerate()
            .map(|(i, r)| match r {
                RowInput::Array([a, b, c, h, e]) => Observation {
                    row: i + 1,
                    a,
                    b,
                    c,
                    h,
                    e,
                },
                RowInput::Object(o) => Observation {
                    row: if o.row == 0 { i + 1 } else { o.row },
                    ..o
                },
            })
            .collect()
    };
    let fit = calibrate::fit(&observations).map_err(|e| calibration_error(&e))?;
    to_js(&fit)
}
