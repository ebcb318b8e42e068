//! The optimisers and the dynamics report as JS functions and `Session` methods. Each returns
//! the CLI's `--json` object; rewriting jobs add the new file as `output` (a `Uint8Array`),
//! which the JSON leaves out.

use js_sys::{Float64Array, Reflect, Uint8Array};
use wasm_bindgen::prelude::*;

use super::{input_bytes, js_error, options, progress_fn, to_js, JsProgress, Session};
use crate::analyze::AnalyzeOptions;
use crate::dynamics::{vibration_with_progress, VibrationOptions};
use crate::infill::{infill_with_progress, InfillOptions};
use crate::optimize::{optimize_with_progress, OptimizeOptions};
use crate::orient::{smooth_with_progress, SmoothOptions};
use crate::vtg::{vtg_with_progress, VtgOptions};

#[wasm_bindgen]
extern "C" {
    /// `VtgOptions` in TypeScript.
    #[wasm_bindgen(typescript_type = "VtgOptions")]
    #[derive(Debug)]
    pub type JsVtgOptions;
    /// `InfillOptions` in TypeScript.
    #[wasm_bindgen(typescript_type = "InfillOptions")]
    #[derive(Debug)]
    pub type JsInfillOptions;
    /// `SmoothOptions` in TypeScript.
    #[wasm_bindgen(typescript_type = "SmoothOptions")]
    #[derive(Debug)]
    pub type JsSmoothOptions;
    /// `VibrationOptions` in TypeScript.
    #[wasm_bindgen(typescript_type = "VibrationOptions")]
    #[derive(Debug)]
    pub type JsVibrationOptions;
    /// `OptimizeOptions` in TypeScript.
    #[wasm_bindgen(typescript_type = "OptimizeOptions")]
    #[derive(Debug)]
    pub type JsOptimizeOptions;
}

/// The report as JS, with the rewritten file as `output`.
fn with_output<T: serde::Serialize>(report: &T, output: &[u8]) -> Result<JsValue, JsValue> {
    let value = to_js(report)?;
    Reflect::set(
        &value,
        &JsValue::from_str("output"),
        &Uint8Array::from(output),
    )?;
    Ok(value)
}

/// A job's options; in a session, the session's analyze options apply unless the job's
/// options name their own `analyze`.
fn job_options<T, F>(
    value: Option<&JsValue>,
    session: Option<&Session>,
    set: F,
) -> Result<T, JsValue>
where
    T: serde::de::DeserializeOwned + Default,
    F: FnOnce(&mut T, AnalyzeOptions),
{
    let mut o: T = options(value)?;
    let named = value.is_some_and(|v| {
        v.is_object() && Reflect::has(v, &JsValue::from_str("analyze")).unwrap_or(false)
    });
    if let (Some(s), false) = (session, named) {
        set(&mut o, s.analyze_options().clone());
    }
    Ok(o)
}

fn run_vtg(bytes: &[u8], o: &VtgOptions, p: Option<JsProgress>) -> Result<JsValue, JsValue> {
    let r = vtg_with_progress(bytes, o, &mut progress_fn(p)).map_err(|e| js_error(&e))?;
    with_output(&r, &r.output)
}

fn run_infill(bytes: &[u8], o: &InfillOptions, p: Option<JsProgress>) -> Result<JsValue, JsValue> {
    let r = infill_with_progress(bytes, o, &mut progress_fn(p)).map_err(|e| js_error(&e))?;
    with_output(&r, &r.output)
}

fn run_optimize(
    bytes: &[u8],
    o: &OptimizeOptions,
    p: Option<JsProgress>,
) -> Result<JsValue, JsValue> {
    let r = optimize_with_progress(bytes, o, &mut progress_fn(p)).map_err(|e| js_error(&e))?;
    with_output(&r, &r.output)
}

fn run_smooth(bytes: &[u8], o: &SmoothOptions, p: Option<JsProgress>) -> Result<JsValue, JsValue> {
    let r = smooth_with_progress(bytes, o, &mut progress_fn(p)).map_err(|e| js_error(&e))?;
    with_output(&r, &r.output)
}

fn run_vibration(
    bytes: &[u8],
    o: &VibrationOptions,
    p: Option<JsProgress>,
) -> Result<JsValue, JsValue> {
    let r = vibration_with_progress(bytes, o, &mut progress_fn(p)).map_err(|e| js_error(&e))?;
    let value = to_js(&r)?;
    // The spectrum as typed arrays (ready for a chart, and no boxing of thousands of numbers).
    let psd = Reflect::get(&value, &JsValue::from_str("psd"))?;
    Reflect::set(
        &psd,
        &JsValue::from_str("freqs"),
        &Float64Array::from(&r.psd.freqs[..]),
    )?;
    Reflect::set(
        &psd,
        &JsValue::from_str("power"),
        &Float64Array::from(&r.psd.power[..]),
    )?;
    Ok(value)
}

/// Vibration-suppressed toolpath (`quietpath vtg --json`, plus `output`).
#[wasm_bindgen(unchecked_return_type = "VtgResult")]
pub fn vtg(
    #[wasm_bindgen(unchecked_param_type = "string | Uint8Array | ArrayBuffer")] input: JsValue,
    options_value: Option<JsVtgOptions>,
    on_progress: Option<JsProgress>,
) -> Result<JsValue, JsValue> {
    let o = job_options(options_value.as_deref(), None, |o: &mut VtgOptions, a| {
        o.analyze = a
    })?;
    run_vtg(&input_bytes(&input)?, &o, on_progress)
}

/// Infill regeneration and the search over pattern, angle and orientation
/// (`quietpath infill --json`, plus `output`).
#[wasm_bindgen(unchecked_return_type = "InfillResult")]
pub fn infill(
    #[wasm_bindgen(unchecked_param_type = "string | Uint8Array | ArrayBuffer")] input: JsValue,
    options_value: Option<JsInfillOptions>,
    on_progress: Option<JsProgress>,
) -> Result<JsValue, JsValue> {
    let o = job_options(
        options_value.as_deref(),
        None,
        |o: &mut InfillOptions, a| o.analyze = a,
    )?;
    run_infill(&input_bytes(&input)?, &o, on_progress)
}

/// The recommended pipeline: infill when asked, VTG, arcs where the firmware runs them, true
/// time estimates (`quietpath optimize --json`, plus `output`).
#[wasm_bindgen(unchecked_return_type = "OptimizeResult")]
pub fn optimize(
    #[wasm_bindgen(unchecked_param_type = "string | Uint8Array | ArrayBuffer")] input: JsValue,
    options_value: Option<JsOptimizeOptions>,
    on_progress: Option<JsProgress>,
) -> Result<JsValue, JsValue> {
    let o = job_options(
        options_value.as_deref(),
        None,
        |o: &mut OptimizeOptions, a| o.analyze = a,
    )?;
    run_optimize(&input_bytes(&input)?, &o, on_progress)
}

/// Tool-orientation smoothing of a multi-axis file (`quietpath smooth --json`, plus `output`).
#[wasm_bindgen(unchecked_return_type = "SmoothResult")]
pub fn smooth(
    #[wasm_bindgen(unchecked_param_type = "string | Uint8Array | ArrayBuffer")] input: JsValue,
    options_value: Option<JsSmoothOptions>,
    on_progress: Option<JsProgress>,
) -> Result<JsValue, JsValue> {
    let o = job_options(
        options_value.as_deref(),
        None,
        |o: &mut SmoothOptions, a| o.analyze = a,
    )?;
    run_smooth(&input_bytes(&input)?, &o, on_progress)
}

/// Axis dynamics, trajectory deviation and vibration spectrum (`quietpath vibration --json`,
/// with the spectrum's `freqs` and `power` as `Float64Array`s).
#[wasm_bindgen(unchecked_return_type = "VibrationResult")]
pub fn vibration(
    #[wasm_bindgen(unchecked_param_type = "string | Uint8Array | ArrayBuffer")] input: JsValue,
    options_value: Option<JsVibrationOptions>,
    on_progress: Option<JsProgress>,
) -> Result<JsValue, JsValue> {
    let o = job_options(
        options_value.as_deref(),
        None,
        |o: &mut VibrationOptions, a| o.analyze = a,
    )?;
    run_vibration(&input_bytes(&input)?, &o, on_progress)
}

#[wasm_bindgen]
impl Session {
    /// `vtg` of the session's file.
    #[wasm_bindgen(unchecked_return_type = "VtgResult")]
    pub fn vtg(
        &self,
        options_value: Option<JsVtgOptions>,
        on_progress: Option<JsProgress>,
    ) -> Result<JsValue, JsValue> {
        let o = job_options(
            options_value.as_deref(),
            Some(self),
            |o: &mut VtgOptions, a| o.analyze = a,
        )?;
        run_vtg(self.input_ref(), &o, on_progress)
    }

    /// `infill` of the session's file.
    #[wasm_bindgen(unchecked_return_type = "InfillResult")]
    pub fn infill(
        &self,
        options_value: Option<JsInfillOptions>,
        on_progress: Option<JsProgress>,
    ) -> Result<JsValue, JsValue> {
        let o = job_options(
            options_value.as_deref(),
            Some(self),
            |o: &mut InfillOptions, a| o.analyze = a,
        )?;
        run_infill(self.input_ref(), &o, on_progress)
    }

    /// `optimize` of the session's file.
    #[wasm_bindgen(unchecked_return_type = "OptimizeResult")]
    pub fn optimize(
        &self,
        options_value: Option<JsOptimizeOptions>,
        on_progress: Option<JsProgress>,
    ) -> Result<JsValue, JsValue> {
        let o = job_options(
            options_value.as_deref(),
            Some(self),
            |o: &mut OptimizeOptions, a| o.analyze = a,
        )?;
        run_optimize(self.input_ref(), &o, on_progress)
    }

    /// `smooth` of the session's file.
    #[wasm_bindgen(unchecked_return_type = "SmoothResult")]
    pub fn smooth(
        &self,
        options_value: Option<JsSmoothOptions>,
        on_progress: Option<JsProgress>,
    ) -> Result<JsValue, JsValue> {
        let o = job_options(
            options_value.as_deref(),
            Some(self),
            |o: &mut SmoothOptions, a| o.analyze = a,
        )?;
        run_smooth(self.input_ref(), &o, on_progress)
    }

    /// `vibration` of the session's file.
    #[wasm_bindgen(unchecked_return_type = "VibrationResult")]
    pub fn vibration(
        &self,
        options_value: Option<JsVibrationOptions>,
        on_progress: Option<JsProgress>,
    ) -> Result<JsValue, JsValue> {
        let o = job_options(
            options_value.as_deref(),
            Some(self),
            |o: &mut VibrationOptions, a| o.analyze = a,
        )?;
        run_vibration(self.input_ref(), &o, on_progress)
    }
}
