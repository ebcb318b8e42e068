//! `analyze` in two workers: the read side on the session's worker, the timing side in a
//! second one (see [`crate::analyze::apart`]). A browser worker has one thread; this is how
//! the playground plans a file while it reads it, as the CLI does on two threads.

use js_sys::{Function, Uint8Array};
use wasm_bindgen::prelude::*;

use super::{js_error, progress_fn, to_js, JsProgress, Session};
use crate::analyze::apart::{self, ReadSide};

/// The read side of an analysis whose timing side runs elsewhere, until its results come back.
#[wasm_bindgen]
#[derive(Debug)]
pub struct ReadApart {
    side: Option<ReadSide>,
}

/// The timing side of an analysis, fed the batches `Session.readApart` sends.
#[wasm_bindgen]
#[derive(Debug, Default)]
pub struct TimingApart(apart::TimingApart);

#[wasm_bindgen]
impl TimingApart {
    /// A timing side waiting for its first batch.
    #[wasm_bindgen(constructor)]
    pub fn new() -> TimingApart {
        TimingApart::default()
    }

    /// Plans the moves of one batch (batches in the order they were sent).
    pub fn feed(&mut self, batch: &[u8]) -> Result<(), JsValue> {
        self.0.feed(batch).map_err(|e| js_error(&e))
    }

    /// End of file: the results, for `Session.reportApart`.
    pub fn finish(&mut self) -> Result<Vec<u8>, JsValue> {
        self.0.finish().map_err(|e| js_error(&e))
    }
}

#[wasm_bindgen]
impl Session {
    /// Reads the session's file for `analyze`, calling `send` with each batch of messages for
    /// a `TimingApart` (a fresh `Uint8Array`, free to transfer). Progress runs over the read.
    #[wasm_bindgen(js_name = readApart)]
    pub fn read_apart(
        &self,
        on_progress: Option<JsProgress>,
        #[wasm_bindgen(unchecked_param_type = "(batch: Uint8Array) => void")] send: &Function,
    ) -> Result<ReadApart, JsValue> {
        let mut progress = progress_fn(on_progress);
        let mut failed = None;
        let side = apart::read_apart(
            self.input_ref(),
            self.analyze_options(),
            &mut progress,
            &mut |batch| {
                if failed.is_none() {
                    failed = send.call1(&JsValue::NULL, &Uint8Array::from(batch)).err();
                }
            },
        )
        .map_err(|e| js_error(&e))?;
        match failed {
            Some(e) => Err(e),
            None => Ok(ReadApart { side: Some(side) }),
        }
    }

    /// The `analyze` report of a file read with `readApart`, from what its `TimingApart`'s
    /// `finish` returned: the same report as `analyze`'s.
    #[wasm_bindgen(js_name = reportApart, unchecked_return_type = "Report")]
    pub fn report_apart(&self, read: &mut ReadApart, timing: &[u8]) -> Result<JsValue, JsValue> {
        let side = read
            .side
            .take()
            .ok_or_else(|| JsValue::from(js_sys::Error::new("this read was reported already")))?;
        let report = apart::report_apart(self.input_ref(), self.analyze_options(), side, timing)
            .map_err(|e| js_error(&e))?;
        to_js(&report)
    }
}
