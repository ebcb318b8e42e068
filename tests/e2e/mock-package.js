// @ts-check
// A stand-in for www/pkg/quietpath.js in the job-UI browser test (playground.test.mjs): it
// re-exports the real package and replaces vtg, infill, smooth and vibration with quick,
// deterministic results (real analyze reports for before/after; the output is the input plus a
// `; mock <job>` line). Every result is typed with the declarations generated from the Rust
// types, and `make typecheck` runs tsc over this file (tests/e2e/tsconfig.json), so the
// stand-in cannot drift from the real shapes: a field the Rust side renames or adds fails there.
//
// Served in place of pkg/quietpath.js, it reaches the real module as `./quietpath.js?real`
// (the test's route matches only the bare path).

/** @typedef {import('../../www/pkg/quietpath.js')} Package */
/** @typedef {import('../../www/pkg/quietpath.js').Report} Report */
/** @typedef {import('../../www/pkg/quietpath.js').Comparison} Comparison */
/** @typedef {import('../../www/pkg/quietpath.js').OrientationMetrics} OrientationMetrics */
/** @typedef {import('../../www/pkg/quietpath.js').InfillCandidate} InfillCandidate */
/** @typedef {import('../../www/pkg/quietpath.js').ToolpathMetrics} ToolpathMetrics */
/** @typedef {import('../../www/pkg/quietpath.js').ProgressCallback} ProgressCallback */
/** @typedef {string | Uint8Array | ArrayBuffer} Input */

// @ts-expect-error: resolved in the browser only (the query string selects the real module).
import init, * as untyped from './quietpath.js?real';
// @ts-expect-error: as above.
export * from './quietpath.js?real';
export default init;

/** @type {Package} */
const real = untyped;
const enc = new TextEncoder();

// The worker prefers Session methods: route them to the stand-ins below too.
export class Session extends real.Session {
  /** @param {import('../../www/pkg/quietpath.js').VtgOptions} [o] @param {ProgressCallback} [p] */
  vtg(o, p) {
    return vtg(this.input(), o, p);
  }
  /** @param {import('../../www/pkg/quietpath.js').InfillOptions} [o] */
  infill(o) {
    return infill(this.input(), o);
  }
  smooth() {
    return smooth(this.input());
  }
  /** @param {import('../../www/pkg/quietpath.js').VibrationOptions} [o] @param {ProgressCallback} [p] */
  vibration(o, p) {
    return vibration(this.input(), o, p);
  }
}

/** @param {Input} input */
const bytesOf = (input) => (typeof input === 'string' ? enc.encode(input) : new Uint8Array(input));

/** The input with a `; mock <tag>` line appended. @param {Input} input @param {string} tag */
function optimized(input, tag) {
  const a = bytesOf(input);
  const b = enc.encode('; mock ' + tag + '\n');
  const out = new Uint8Array(a.length + b.length);
  out.set(a);
  out.set(b, a.length);
  return out;
}

/** @param {number} before @param {number} after @returns {Comparison} */
const cmp = (before, after) => ({ before, after, change_pct: before ? (100 * (after - before)) / before : 0 });

/** @param {Report} r @returns {ToolpathMetrics} */
const toolpath = (r) => r.toolpath;

/**
 * `options_seen` (the options as the job got them) is the test's own addition, to check that
 * the form's fields reach the job.
 * @param {Input} input
 * @param {import('../../www/pkg/quietpath.js').VtgOptions} [options]
 * @param {ProgressCallback} [progress]
 * @returns {import('../../www/pkg/quietpath.js').VtgResult & { options_seen: object }}
 */
export function vtg(input, options = {}, progress) {
  progress?.(0.5);
  const output = optimized(input, 'vtg');
  const before = real.analyze(bytesOf(input));
  const after = real.analyze(output);
  const [tb, ta] = [toolpath(before), toolpath(after)];
  return {
    tolerance_mm: options.tolerance_mm ?? 0.05,
    max_deviation_mm: 0.0421,
    critical_angle_deg: 30,
    k_cr_per_mm: 1.2,
    limits: { v_max_mm_s: 200, interpolation_period_s: 0.001, chord_tolerance_mm: 0.01, normal_accel_mm_s2: 3000, normal_jerk_mm_s3: 1e5, nozzle_radius_mm: 0.2 },
    paths: {
      candidates: 12, rewritten: 10, replaced_moves: 400, written_moves: 900, above_k_cr_segments: 30, lowered_feed_segments: 5,
      raised_caps: 2, uncapped: 1, paid_from_savings: 1, kept_for_time: 2, kept_for_lines: 3, compacted: 4, mean_speed_fluctuation_pct: 3.5, feed_cap_scale: 1,
      steps_joined: true, stretch_caps: false, arcs_written: 0, keyholes: 0,
    },
    table1: {
      l_total_mm: cmp(tb.l_total_mm, ta.l_total_mm), n_total: cmp(tb.n_total, ta.n_total), l_infill_mm: cmp(tb.l_infill_mm, ta.l_infill_mm),
      n_infill: cmp(tb.n_infill, ta.n_infill), n_turning: cmp(tb.n_turning, ta.n_turning), mean_turn_deg: cmp(tb.mean_turn_deg, ta.mean_turn_deg),
      mean_chord_error_mm: cmp(tb.mean_chord_error_mm, ta.mean_chord_error_mm),
    },
    table2: {
      deviation: { max_mm: cmp(0.05, 0.02), min_mm: cmp(0, 0), mean_mm: cmp(0.01, 0.004) },
      energy_j: cmp(before.energy.total_j, after.energy.total_j), servo_energy_j: cmp(before.energy.servo_j, after.energy.servo_j),
      material_g: cmp(before.material_g, after.material_g), co2_g: cmp(before.energy.co2_g, after.energy.co2_g), time_s: cmp(before.time_s, after.time_s),
    },
    layers: [],
    before,
    after,
    firmware: null,
    message: null,
    peak_layers_kept: [],
    feed_lines_folded: 0,
    options_seen: options,
    output,
  };
}

/**
 * Two patterns over five angles and two rotations: the chart draws one line per pattern.
 * @param {Input} input
 * @param {import('../../www/pkg/quietpath.js').InfillOptions} [_options]
 * @returns {import('../../www/pkg/quietpath.js').InfillResult}
 */
export function infill(input, _options = {}) {
  const output = optimized(input, 'infill');
  /** @type {InfillCandidate[]} */
  const candidates = [];
  for (const pattern of /** @type {const} */ (['rectilinear', 'grid'])) {
    for (const angle_deg of [0, 30, 45, 60, 90]) {
      for (const rotation_deg of [0, 90]) {
        const total_j = 5000 + 10 * Math.sin(angle_deg / 30) + (pattern === 'grid' ? 50 : 0) + rotation_deg;
        candidates.push({
          pattern, estimated: false, angle_deg, rotation_deg, thesis_j: 1000 + angle_deg, total_j, time_s: 60, length_mm: 1000, filament_mm: 300,
          infill_length_mm: 400, infill_turning_points: 80, infill_mean_turn_deg: 120,
        });
      }
    }
  }
  return {
    before: real.analyze(bytesOf(input)),
    after: real.analyze(output),
    best: {
      pattern: 'rectilinear', angle_deg: 0, rotation_deg: 0, thesis_j: 1000, total_j: 5000, time_s: 60, length_mm: 1000,
      saving_j: 25, saving_pct: 0.5, layers: null, message: null,
    },
    candidates,
    candidates_skipped: 0,
    candidates_estimated: 0,
    measured: { spacing_mm: 2, clearance_mm: 0.2, e_per_mm: 0.03, layers_regenerated: 40, blocks: 1, print_feed_mm_s: 60, travel_feed_mm_s: 150, retract_mm: 0.8 },
    rotations_skipped: [],
    output,
  };
}

/** @param {number} jerk @returns {OrientationMetrics} */
const orientation = (jerk) => ({
  roughness: jerk / 10, mean_second_difference: jerk / 20, max_second_difference: jerk / 5,
  mean_angle_change_deg: jerk / 4, max_angle_change_deg: jerk, mean_angle_change_per_mm_deg: jerk / 8, max_angle_change_per_mm_deg: jerk / 2,
  rotary: [],
});

/**
 * A smoothing of B and C (the demo file has no rotary axes, so the real smooth would refuse it).
 * @param {Input} input
 * @returns {import('../../www/pkg/quietpath.js').SmoothResult}
 */
export function smooth(input) {
  const n = 500;
  const point = Array.from({ length: n }, (_, i) => i);
  const b = point.map((i) => 20 * Math.sin(i / 20) + (i % 7));
  return {
    format: 'gcode', kinematics: 'table-bc', coordinates: 'machine', filter: 'zero-phase-moving-average', window: { points: 15 }, cone_deg: 60,
    motion_lines: n, points: n, runs: 1, corrected: 321, changed: 400, max_angle_to_original_deg: 2.5, mean_angle_to_original_deg: 0.8,
    before: orientation(4), after: orientation(1), roughness_reduction: 0.75, max_tip_deviation_mm: 0.01,
    planned_time_before_s: 100, planned_time_after_s: 98,
    series: {
      axes: ['B', 'C'], point, first_before: b, first_after: point.map((i) => 20 * Math.sin(i / 20)),
      second_before: b.map((v) => v * 2), second_after: point.map((i) => 40 * Math.sin(i / 20)), angle_to_original_deg: point.map(() => 0.5),
    },
    warnings: [],
    output: optimized(input, 'smooth'),
  };
}

/**
 * The optimised output (it ends in `; mock …`) vibrates half as much. `fs_hz: 999` makes a
 * slow job to cancel.
 * @param {Input} input
 * @param {import('../../www/pkg/quietpath.js').VibrationOptions} [options]
 * @param {ProgressCallback} [progress]
 * @returns {import('../../www/pkg/quietpath.js').VibrationResult}
 */
export function vibration(input, options = {}, progress) {
  if (options.fs_hz === 999) {
    const t0 = Date.now();
    while (Date.now() - t0 < 10000) progress?.((Date.now() - t0) / 10000);
  }
  const after = new TextDecoder().decode(bytesOf(input).subarray(-16)).includes('mock');
  const freqs = Float64Array.from({ length: 256 }, (_, i) => i * 2);
  const deviation = { max: after ? 0.02 : 0.05, min: 0, mean: after ? 0.004 : 0.01, max_at: /** @type {[number, number, number]} */ ([10, 20, 0.2]), samples: 1000 };
  return {
    machine: 'prusa-mk3s', dynamics: 'desktop-belt', ts_ms: 1,
    natural_frequencies_hz: [41.2, 57.9], damping_ratios: [0.05, 0.05],
    axes: [{ axis: 'x', position_mm: 100, modes: [{ frequency_hz: 41.2, damping_ratio: 0.05 }] }],
    deviation_mm: deviation, printing_deviation_mm: deviation,
    layers: Array.from({ length: 50 }, (_, i) => ({ layer: i, z: 0.2 * (i + 1), amplitude: (after ? 0.5 : 1) * (1 + Math.sin(i / 5)), printing_amplitude: (after ? 0.4 : 0.8) * (1 + Math.sin(i / 5)), printing_mean: 0.4, printing_samples: 1000, mean: 0.5, acceleration_rms: 1 })),
    psd: {
      fs_hz: 512, window: 256, window_kind: 'hamming', overlap: 128, segments: 8,
      freqs, power: freqs.map((f) => (after ? 0.3 : 1) / (1 + Math.abs(f - 41) / 5)), peaks: [{ hz: 41.2, power: 1 }],
    },
    simulated_s: 60, steps: 60000,
  };
}
