// ── Hand-written: only what is not a Rust serde type. ──
// Every report, option and profile type (Report, AnalyzeOptions, VtgReport, MachineProfile…) is
// GENERATED from the Rust types into types.generated.d.ts (crate/src/ts_types.rs; regenerate
// with `UPDATE_TYPES=1 cargo test -p quietpath --lib ts_types`). What stays here is built by
// hand in crate/src/wasm (typed arrays set with Reflect, the rewritten file added as `output`)
// or is a JS-side shape (callbacks, thrown errors). Both files end up in each build's
// quietpath.d.ts.

/** Drawing data of one layer (Session.layer), built in crate/src/wasm/session.rs from
 *  path::LayerGeometry as typed arrays. Segment i is xy[4i..4i+4] = x0, y0, x1, y1. */
export interface LayerGeometry {
  z: number | null;
  xy: Float32Array;
  /** 0 travel, 1 outer wall, 2 inner wall, 3 sparse infill, 4 solid infill, 5 bridge,
   *  6 gap fill, 7 support, 8 adhesion, 9 other. */
  kind: Uint8Array;
  speed: Float32Array;
  curvature: Float32Array;
  /** A multi-axis file's segments in 3-D, six numbers each (x0, y0, z0, x1, y1, z1, mm),
   *  parallel to `xy`: the tool tip in the workpiece frame (where the material goes on the part),
   *  while `xy` holds the machine axes. Empty for a three-axis file. */
  xyz: Float32Array;
  /** Tool vectors of a multi-axis file (rotary words), six numbers each: tool tip x, y, z (mm)
   *  and unit tool vector i, j, k (tip towards the nozzle), both in the workpiece frame, one per
   *  extruding move. Empty for a three-axis file. */
  tool: Float32Array;
}
/** One calibration row for calibrate(): thesis terms A, B, C, H and the measured energy E
 *  (W·ms), as an array or as an Observation (the wasm side reads either, untagged). */
export type CalibrationRow = [number, number, number, number, number] | Observation;
/** An error thrown by the API: a JS Error with the position of the problem and its kind. */
export interface QuietpathError extends Error {
  line?: number;
  column?: number;
  kind?: ErrorKind;
}
/** An error thrown by calibrate(): a JS Error carrying the CalibrationError's fields. */
export type CalibrateError = Error & CalibrationError;
/** Progress callback: fraction done in [0, 1]; return false to cancel (the job throws a
 *  `cancelled` error). */
export type ProgressCallback = (fraction: number) => boolean | void;

/** vibration() result: the report with the spectrum as typed arrays (crate/src/wasm/jobs.rs). */
export interface VibrationResult extends Omit<VibrationReport, "psd"> {
  psd: Omit<Psd, "freqs" | "power"> & { freqs: Float64Array; power: Float64Array };
}
/** smooth() result: the report plus the smoothed file. A file whose rotary axes never move
 *  (3-axis) throws a QuietpathError of kind `no_rotary_motion` ({ first, second } axis letters). */
export type SmoothResult = SmoothReport & { output: Uint8Array };
/** infill() result: the report plus the rewritten file. */
export type InfillResult = InfillReport & { output: Uint8Array };
/** vtg() result: the report plus the rewritten file. */
export type VtgResult = VtgReport & { output: Uint8Array };
/** optimize() result: the report plus the optimised file. */
export type OptimizeResult = OptimizeReport & { output: Uint8Array };
