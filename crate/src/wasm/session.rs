//! `Session`: one file kept in wasm memory for several jobs and for drawing.

use js_sys::{Float32Array, Object, Reflect, Uint8Array};
use wasm_bindgen::prelude::*;

use super::{input_bytes, js_error, options, progress_fn, to_js, JsAnalyzeOptions, JsProgress};
use crate::analyze::{analyze_with_progress, AnalyzeOptions};
use crate::orient::{self, SmoothOptions};
use crate::path::{self, LayerGeometry};

/// A G-code file loaded once: jobs run on it without copying it across the boundary again,
/// and its layers are ready to draw.
#[wasm_bindgen]
#[derive(Debug)]
pub struct Session {
    bytes: Vec<u8>,
    options: AnalyzeOptions,
    layers: Option<Vec<LayerGeometry>>,
}

#[wasm_bindgen]
impl Session {
    /// Loads `input` (string, `Uint8Array` or `ArrayBuffer`) with analyze options.
    #[wasm_bindgen(constructor)]
    pub fn new(
        #[wasm_bindgen(unchecked_param_type = "string | Uint8Array | ArrayBuffer")] input: JsValue,
        options_value: Option<JsAnalyzeOptions>,
    ) -> Result<Session, JsValue> {
        Ok(Session {
            bytes: input_bytes(&input)?,
            options: options(options_value.as_deref())?,
            layers: None,
        })
    }

    /// Size of the file, bytes.
    #[wasm_bindgen(getter)]
    pub fn bytes(&self) -> usize {
        self.bytes.len()
    }

    /// The file's text (for a download of the loaded file, or a chained job).
    #[wasm_bindgen(js_name = input)]
    pub fn input(&self) -> Uint8Array {
        Uint8Array::from(&self.bytes[..])
    }

    /// `analyze` of the session's file.
    #[wasm_bindgen(unchecked_return_type = "Report")]
    pub fn analyze(&self, on_progress: Option<JsProgress>) -> Result<JsValue, JsValue> {
        let mut progress = progress_fn(on_progress);
        let report = analyze_with_progress(&self.bytes, &self.options, &mut progress)
            .map_err(|e| js_error(&e))?;
        to_js(&report)
    }

    /// Number of layers (reads the moves on first use).
    #[wasm_bindgen(js_name = layerCount)]
    pub fn layer_count(&mut self) -> Result<usize, JsValue> {
        Ok(self.layers()?.len())
    }

    /// Drawing data of layer `index`: `{ z, xy: Float32Array, kind: Uint8Array,
    /// speed: Float32Array, curvature: Float32Array, xyz: Float32Array, tool: Float32Array }`
    /// (see `path::LayerGeometry`).
    #[wasm_bindgen(unchecked_return_type = "LayerGeometry")]
    pub fn layer(&mut self, index: usize) -> Result<JsValue, JsValue> {
        let empty = LayerGeometry::default();
        let g = self.layers()?.get(index).unwrap_or(&empty);
        let out = Object::new();
        let set = |k: &str, v: JsValue| Reflect::set(&out, &JsValue::from_str(k), &v);
        set("z", g.z.map_or(JsValue::NULL, JsValue::from_f64))?;
        set("xy", Float32Array::from(&g.xy[..]).into())?;
        set("kind", Uint8Array::from(&g.kind[..]).into())?;
        set("speed", Float32Array::from(&g.speed[..]).into())?;
        set("curvature", Float32Array::from(&g.curvature[..]).into())?;
        set("xyz", Float32Array::from(&g.xyz[..]).into())?;
        set("tool", Float32Array::from(&g.tool[..]).into())?;
        Ok(out.into())
    }
}

impl Session {
    /// The file, for the job methods.
    pub(super) fn input_ref(&self) -> &[u8] {
        &self.bytes
    }

    /// The session's analyze options, for the job methods.
    pub(super) fn analyze_options(&self) -> &AnalyzeOptions {
        &self.options
    }

    fn layers(&mut self) -> Result<&Vec<LayerGeometry>, JsValue> {
        if self.layers.is_none() {
            // The move list is large; keep only the compact drawing arrays. The workpiece-frame
            // path and tool vectors of a multi-axis file are read with the smoothing's default
            // kinematics, as the playground's smooth job reads them.
            let p = path::extract(&self.bytes, &self.options, true).map_err(|e| js_error(&e))?;
            let smooth = SmoothOptions::default();
            self.layers = Some(orient::layer_geometries(
                &p,
                &smooth.kinematics,
                smooth.coordinates,
            ));
        }
        Ok(self.layers.get_or_insert_with(Vec::new))
    }
}
