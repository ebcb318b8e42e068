// @ts-check
// quietpath job worker (module worker).
//
// Created by jobs.js as: new Worker('./worker.js', { type: 'module' })
// It loads the wasm package and runs every job off the
// main thread, so the page stays responsive on big files. It keeps two
// sessions: `input` (the loaded file) and `output` (the latest optimized
// G-code), so jobs and layer drawing never copy the file across again.
//
// ── Protocol ────────────────────────────────────────────────────────────────
// Requests are handled strictly one after another (the wasm calls are
// synchronous). To cancel, the page terminates the worker and starts a new
// one; the new worker holds no session, so the page sends `load` again first.
//
// page → worker
//   { id, type: 'load', which?: 'input'|'output', bytes: ArrayBuffer, name,
//     options, analyze?: boolean }
//       Creates the `which` session (default 'input') from `bytes` (transfer
//       it) with analyze `options` ({ strict?, filament_diameter_mm?, … }).
//       Creating the input session drops the output session.
//       With analyze !== false (the default for 'input'), runs analyze().
//       → { id, type: 'result', report?, ms?, totalMs, workers? }
//         report: the analysis report (same JSON as the CLI's --json), only
//         when analyzed; ms: analyze() wall time; totalMs: the whole request;
//         workers: 2 when a large file's moves were planned in timing-worker.js
//         while this worker read it (as the CLI plans on a second thread), else 1.
//   { id, type: 'job', job: 'vtg'|'infill'|'smooth'|'vibration'|'analyze',
//     options, target?: 'input'|'output' }
//       Runs the capability on a session (default 'input'), as a Session
//       method when the package has one, else as the free function on the
//       session's bytes.
//       → { id, type: 'result', result, ms, output: ArrayBuffer | null }
//         result: the function's result without its `output` bytes;
//         output: those bytes (transferred). When present they also become
//         the new `output` session (for the viewer's "after").
//   { id, type: 'layer', which: 'before'|'after', index, z? }
//       Drawing data of one layer of the input ('before') or output ('after')
//       session. With a number `z`, the layer nearest that height instead of
//       `index` (how "after" follows "before": a rewrite may change the count).
//       → { id, type: 'layer', which, index, count, z, xy, kind, speed,
//           curvature, xyz, tool }   (typed arrays transferred; see types.d.ts
//           LayerGeometry; xyz: the segments of a multi-axis file in the
//           workpiece frame, tool: its tool vectors, both empty otherwise;
//           count: the session's number of layers)
//
// worker → page
//   { type: 'hello', version, capabilities: string[], machines: MachineProfile[],
//     threads: number }
//       once, when the wasm is loaded; capabilities lists the jobs this build
//       has (e.g. ['analyze', 'vtg']): the page disables the others;
//       machines: the built-in presets (machines(); [] in a build without it);
//       threads: the threads the jobs' parallel maps run on (1: the plain build).
//   { id, type: 'progress', fraction }   0 ≤ fraction ≤ 1, increasing,
//                                        throttled (≈ every 1 % / 50 ms)
//   { id, type: 'error', message, line, column, excerpt, kind, fatal }
//       message: human-readable, from the Error thrown by the wasm;
//       line/column: 1-based position of the problem, or null when unknown;
//       excerpt: the text of that line (≤ 200 chars) or null;
//       kind: the Error's `kind` property (e.g. { kind: 'invalid_number',
//       letter: 'X' }) or null;
//       fatal: true when the wasm instance may be broken (a panic / trap, or
//       the package failed to load): the page should terminate this worker
//       and start a new one for the next request.
// An uncaught failure shows up as the Worker's `error` event on the page.
// ────────────────────────────────────────────────────────────────────────────

import * as qp from './pkg/quietpath.js';

const PROGRESS_STEP = 0.01;
const PROGRESS_INTERVAL_MS = 50;
const EXCERPT_MAX = 200;
const JOBS = ['analyze', 'optimize', 'vtg', 'infill', 'smooth', 'vibration'];

/** @typedef {(...args: any[]) => any} AnyFunction */
/**
 * The package's exports, or a Session's methods, by name: the jobs are looked up by name, since
 * a build may lack some.
 * @param {object} o
 */
const byName = (o) => /** @type {Record<string, AnyFunction | undefined>} */ (o);

// Which jobs this build offers: a Session method or a free function.
function capabilities() {
  const proto = byName(pkg.Session?.prototype ?? {});
  return JOBS.filter((j) => typeof byName(pkg)[j] === 'function' || typeof proto[j] === 'function');
}

/**
 * A request of the page (the protocol above).
 * @typedef {{ id: number, type: 'load' | 'analyze', which?: 'input' | 'output', bytes: ArrayBuffer, name?: string, options?: qp.AnalyzeOptions, analyze?: boolean }} LoadRequest
 * @typedef {{ id: number, type: 'job', job: string, options?: any, target?: 'input' | 'output' }} JobRequest
 * @typedef {{ id: number, type: 'layer', which: 'before' | 'after', index: number, z?: number | null }} LayerRequest
 */

/**
 * The package the jobs run on. Where the page is cross-origin isolated (scripts/serve.mjs sends
 * COOP and COEP) and the machine has more than one core, the threaded build in ./pkg-threads/:
 * its parallel maps (VTG's paths, the infill search's candidates, the dynamics model's sampled
 * layers) run on a pool of workers that share its memory, one thread per core (at most 8) as the
 * CLI uses, so the results are the CLI's. Elsewhere the plain build in ./pkg/, on one thread.
 * Its initialisers (which differ: the threaded one takes the shared memory) are called in load().
 * @type {Omit<typeof qp, 'default' | 'initSync'>}
 */
let pkg = qp;
/** Threads the package's parallel maps use (the `hello` message says). */
let threads = 1;

/**
 * How long the pool may take to start before the plain build is used instead: a pool worker that
 * fails to load (its script missing from an offline cache, say) never says it is ready, and the
 * pool's start would wait for ever. Starting takes a fraction of a second here.
 */
const POOL_START_MS = 10_000;

/** Loads the threaded build where it can run, else the plain one. */
async function load() {
  const cores = Math.min(navigator.hardwareConcurrency || 1, 8);
  if (self.crossOriginIsolated && cores > 1) {
    try {
      const threaded = await import('./pkg-threads/quietpath.js');
      await threaded.default();
      // A worker per core: the maps run on the pool while this worker waits (and runs the
      // half of a join that reports progress).
      /** @type {ReturnType<typeof setTimeout> | undefined} */
      let timer;
      const late = new Promise((_, reject) => {
        timer = setTimeout(() => reject(new Error(`the pool did not start in ${POOL_START_MS} ms`)), POOL_START_MS);
      });
      try {
        await Promise.race([threaded.initThreadPool(cores), late]);
      } finally {
        clearTimeout(timer);
      }
      threaded.usePool(cores);
      pkg = threaded;
      threads = threaded.threads();
      return;
    } catch (err) {
      console.warn('quietpath: the threaded build did not start; running on one thread', err);
    }
  }
  await qp.default();
}

/** @type {unknown} */
let loadError = null;
const ready = load().then(
  () => {
    let v = null;
    try {
      v = pkg.version();
    } catch {
      // version() is informational only
    }
    /** @type {qp.MachineProfile[]} */
    let machines = [];
    try {
      machines = typeof pkg.machines === 'function' ? pkg.machines() : [];
    } catch {
      // an older build without the preset list: the picker offers "from the file" only
    }
    self.postMessage({ type: 'hello', version: v, capabilities: capabilities(), machines, threads });
  },
  (err) => {
    loadError = err;
  },
);

// ── The timing worker ──────────────────────────────────────────────────────
// analyze of a large file reads it here while timing-worker.js plans its moves, as the CLI
// plans on a second thread (a worker has one): same report, less wall time.
const APART_MIN_BYTES = 1 << 20;
/** @type {Worker | null} */
let timingWorker = null;
let timingRun = 0;
/** Whether the timing worker is there and loaded (false: analyze here alone). */
const timingUp = ready.then(
  () =>
    new Promise((resolve) => {
      if (loadError || typeof Worker !== 'function' || typeof pkg.TimingApart !== 'function') return resolve(false);
      try {
        timingWorker = new Worker(new URL('./timing-worker.js', import.meta.url), { type: 'module' });
      } catch {
        return resolve(false);
      }
      timingWorker.onmessage = (e) => resolve(e.data?.type === 'ready');
      timingWorker.onerror = () => resolve(false);
    }),
);

/**
 * analyze with the timing side in the timing worker: this worker reads and sends it the
 * batches, then joins its results. Falls back to analyze here if that worker fails.
 * @param {qp.Session} session
 * @param {(fraction: number) => void} progress
 * @returns {Promise<{ report: qp.Report, workers: number }>}
 */
async function analyzeApart(session, progress) {
  const helper = /** @type {Worker} */ (timingWorker);
  const run = ++timingRun;
  /** @type {Promise<Uint8Array>} */
  const results = new Promise((resolve, reject) => {
    helper.onmessage = (e) => {
      const m = e.data;
      if (m?.run !== run) return;
      if (m.type === 'timing') resolve(new Uint8Array(m.bytes));
      else reject(new Error(m.message ?? 'the timing worker failed'));
    };
    helper.onerror = (e) => reject(new Error(e.message || 'the timing worker failed'));
  });
  helper.postMessage({ type: 'begin', run });
  const read = session.readApart(progress, (batch) => helper.postMessage({ type: 'batch', run, bytes: batch.buffer }, [batch.buffer]));
  helper.postMessage({ type: 'finish', run });
  try {
    return { report: session.reportApart(read, await results), workers: 2 };
  } catch (err) {
    console.warn(`analyzing without the timing worker: ${describe(err)}`);
    timingWorker = null;
    helper.terminate();
    return { report: session.analyze(progress), workers: 1 };
  } finally {
    read.free();
  }
}

/**
 * A file the worker holds: its wasm Session, its bytes and the analyze options it was read with.
 * @typedef {{ session: qp.Session, bytes: Uint8Array, options: qp.AnalyzeOptions }} Held
 */

/** @type {{ input: Held | null, output: Held | null }} */
const sessions = { input: null, output: null };

/**
 * Text of 1-based line `line` in `bytes`, or null.
 * @param {Uint8Array | null} bytes
 * @param {number | null} line
 * @returns {string | null}
 */
function lineExcerpt(bytes, line) {
  if (!bytes || typeof line !== 'number' || !Number.isInteger(line) || line < 1) return null;
  let start = 0;
  for (let n = 1; n < line; n++) {
    const nl = bytes.indexOf(10, start);
    if (nl < 0) return null;
    start = nl + 1;
  }
  let end = bytes.indexOf(10, start);
  if (end < 0) end = bytes.length;
  const slice = bytes.subarray(start, Math.min(end, start + EXCERPT_MAX * 4));
  // Control characters (NUL in binary or UTF-16 data, …) are shown as '·'.
  // eslint-disable-next-line no-control-regex
  let text = new TextDecoder('utf-8').decode(slice).replace(/\r$/, '').replace(/[\u0000-\u0008\u000b-\u001f\u007f]/g, '·');
  if (text.length > EXCERPT_MAX) text = text.slice(0, EXCERPT_MAX) + '…';
  // Not worth showing when it is mostly noise (binary or UTF-16 data).
  const noise = (text.match(/[·\ufffd]/g) ?? []).length;
  if (text.length > 0 && noise / text.length > 0.3) return null;
  return text;
}

/**
 * @param {unknown} err
 * @param {'line' | 'column'} key
 * @returns {number | null}
 */
function positionOf(err, key) {
  const v = err !== null && typeof err === 'object' ? /** @type {Record<string, unknown>} */ (err)[key] : undefined;
  return typeof v === 'number' && Number.isFinite(v) ? v : null;
}

/**
 * @param {unknown} err
 * @returns {string}
 */
function describe(err) {
  if (err instanceof Error) return err.message || err.name;
  if (typeof err === 'string') return err;
  try {
    return JSON.stringify(err);
  } catch {
    return String(err);
  }
}

// The analyzer's machine-readable error kind (e.g. { kind: 'invalid_number', letter: 'X' }), if any.
/** @param {unknown} err */
function plainKind(err) {
  const k = err !== null && typeof err === 'object' ? /** @type {{ kind?: unknown }} */ (err).kind : undefined;
  if (k === undefined || k === null) return null;
  try {
    return JSON.parse(JSON.stringify(k));
  } catch {
    return null;
  }
}

/**
 * @param {number} id
 * @param {unknown} err
 * @param {Uint8Array | null} bytes the file, for the excerpt of the line at fault
 */
function postError(id, err, bytes) {
  const line = positionOf(err, 'line');
  const column = positionOf(err, 'column');
  self.postMessage({
    id,
    type: 'error',
    message: describe(err),
    line,
    column,
    excerpt: lineExcerpt(bytes, line),
    kind: plainKind(err),
    // A trap (e.g. a Rust panic → "unreachable") leaves the instance unusable.
    fatal: err instanceof WebAssembly.RuntimeError || !(err instanceof Error),
  });
}

/**
 * A progress callback for the wasm that posts throttled, increasing fractions; `finish()`
 * posts the last one.
 * @param {number} id
 */
function progressFor(id) {
  let lastFraction = -1;
  let lastTime = 0;
  /** @param {number} fraction */
  const fn = (fraction) => {
    const now = performance.now();
    if (fraction >= 1 || fraction - lastFraction >= PROGRESS_STEP || now - lastTime >= PROGRESS_INTERVAL_MS) {
      if (fraction <= lastFraction) return;
      lastFraction = fraction;
      lastTime = now;
      self.postMessage({ id, type: 'progress', fraction });
    }
  };
  fn.finish = () => {
    if (lastFraction < 1) self.postMessage({ id, type: 'progress', fraction: 1 });
  };
  return fn;
}

/** @param {'input' | 'output'} which */
function dropSession(which) {
  const s = sessions[which];
  sessions[which] = null;
  try {
    s?.session.free?.();
  } catch {
    // already freed
  }
}

/** @param {LoadRequest} msg */
async function handleLoad(msg) {
  const { id, options } = msg;
  const which = msg.which === 'output' ? 'output' : 'input';
  const t0 = performance.now();
  const bytes = new Uint8Array(msg.bytes);
  dropSession(which);
  if (which === 'input') dropSession('output');
  try {
    const session = new pkg.Session(bytes, options ?? {});
    sessions[which] = { session, bytes, options: options ?? {} };
    const analyze = msg.analyze ?? which === 'input';
    if (!analyze) {
      self.postMessage({ id, type: 'result', totalMs: performance.now() - t0 });
      return;
    }
    const progress = progressFor(id);
    const apart = bytes.length >= APART_MIN_BYTES && navigator.hardwareConcurrency > 1 && (await timingUp) && timingWorker !== null;
    const a0 = performance.now();
    const { report, workers } = apart ? await analyzeApart(session, progress) : { report: session.analyze(progress), workers: 1 };
    const ms = performance.now() - a0;
    progress.finish();
    self.postMessage({ id, type: 'result', report, ms, totalMs: performance.now() - t0, workers });
  } catch (err) {
    postError(id, err, bytes);
  }
}

/** @param {JobRequest} msg */
function handleJob(msg) {
  const { id, job, options } = msg;
  const target = msg.target === 'output' ? 'output' : 'input';
  const s = sessions[target];
  if (!s) {
    postError(id, new Error(target === 'output' ? 'no optimized output yet: run VTG, infill or smoothing first' : 'no file loaded'), null);
    return;
  }
  if (!JOBS.includes(job)) {
    postError(id, new Error(`unknown job: ${job}`), null);
    return;
  }
  const progress = progressFor(id);
  const t0 = performance.now();
  try {
    let result;
    const method = byName(s.session)[job];
    const free = byName(pkg)[job];
    if (typeof method === 'function') {
      result = job === 'analyze' ? s.session.analyze(progress) : method.call(s.session, options ?? {}, progress);
    } else if (typeof free === 'function') {
      // The free vtg() takes the analyze options inside its own (a Session has them already).
      const opts = job === 'vtg' && Object.keys(s.options).length && !options?.analyze ? { ...options, analyze: s.options } : options ?? {};
      result = job === 'analyze' ? pkg.analyze(s.bytes, s.options, progress) : free(s.bytes, opts, progress);
    } else {
      throw new Error(`${job} is not available in this build`);
    }
    const ms = performance.now() - t0;
    progress.finish();
    let output = null;
    const out = takeOutput(result);
    if (out) {
      // The optimized file becomes the "after" session (viewer, chained jobs).
      dropSession('output');
      const copy = out.slice();
      sessions.output = { session: new pkg.Session(copy, s.options), bytes: copy, options: s.options };
      output = out.byteOffset === 0 && out.buffer.byteLength === out.byteLength ? out.buffer : out.slice().buffer;
    }
    self.postMessage({ id, type: 'result', result, ms, output }, output ? [output] : []);
  } catch (err) {
    postError(id, err, s.bytes);
  }
}

/**
 * Removes the optimized G-code from a job result and returns it as bytes, or
 * null. Accepts what a serde bridge may produce: Uint8Array (serde_bytes), an
 * array of numbers, or a string; on a plain object or a Map.
 * @param {any} result
 * @returns {Uint8Array | null}
 */
function takeOutput(result) {
  if (!result || typeof result !== 'object') return null;
  let v;
  if (result instanceof Map) {
    v = result.get('output');
    result.delete('output');
  } else {
    v = result.output;
    delete result.output;
  }
  if (v instanceof Uint8Array) return v;
  if (Array.isArray(v)) return Uint8Array.from(v);
  if (typeof v === 'string') return new TextEncoder().encode(v);
  return null;
}

/** @param {LayerRequest} msg */
function handleLayer(msg) {
  const { id, index } = msg;
  const which = msg.which === 'after' ? 'after' : 'before';
  const s = sessions[which === 'after' ? 'output' : 'input'];
  if (!s) {
    postError(id, new Error(`no ${which === 'after' ? 'optimized output' : 'file'} loaded`), null);
    return;
  }
  try {
    const count = s.session.layerCount();
    let i = Math.max(0, Math.min(count - 1, index | 0));
    let g = null;
    if (count > 0 && typeof msg.z === 'number' && Number.isFinite(msg.z)) [i, g] = nearestZ(s.session, count, msg.z, i);
    g ??= count > 0 ? s.session.layer(i) : { z: null, xy: new Float32Array(), kind: new Uint8Array(), speed: new Float32Array(), curvature: new Float32Array(), xyz: new Float32Array(), tool: new Float32Array() };
    self.postMessage(
      { id, type: 'layer', which, index: i, count, z: g.z, xy: g.xy, kind: g.kind, speed: g.speed, curvature: g.curvature, xyz: g.xyz, tool: g.tool },
      [g.xy.buffer, g.kind.buffer, g.speed.buffer, g.curvature.buffer, g.xyz.buffer, g.tool.buffer],
    );
  } catch (err) {
    postError(id, err, s.bytes);
  }
}

/**
 * The layer of `session` whose z is nearest `z`: a binary search over the layers' heights
 * (increasing in a layered print), then the neighbours; `hint` (the same index) wins ties.
 * Returns [index, geometry].
 * @param {qp.Session} session
 * @param {number} count its number of layers
 * @param {number} z
 * @param {number} hint
 * @returns {[number, qp.LayerGeometry]}
 */
function nearestZ(session, count, z, hint) {
  /** @type {Map<number, qp.LayerGeometry>} */
  const zs = new Map();
  /** @param {number} i */
  const zAt = (i) => {
    if (!zs.has(i)) zs.set(i, session.layer(i));
    const v = /** @type {qp.LayerGeometry} */ (zs.get(i)).z;
    return typeof v === 'number' ? v : NaN;
  };
  let lo = 0;
  let hi = count - 1;
  while (lo < hi) {
    const mid = (lo + hi) >> 1;
    if (zAt(mid) < z) lo = mid + 1;
    else hi = mid;
  }
  let best = hint;
  let bestErr = Math.abs(zAt(hint) - z);
  for (const i of [lo - 1, lo, lo + 1]) {
    if (i < 0 || i >= count) continue;
    const err = Math.abs(zAt(i) - z);
    if (err < bestErr || !(bestErr === bestErr)) {
      best = i;
      bestErr = err;
    }
  }
  return [best, zs.get(best) ?? session.layer(best)];
}

/** @type {Record<string, (msg: any) => void | Promise<void>>} */
const HANDLERS = { load: handleLoad, job: handleJob, layer: handleLayer, analyze: handleLoad };

// Requests are handled strictly one after another.
let queue = Promise.resolve();
self.onmessage = (event) => {
  const msg = event.data;
  const handler = msg && HANDLERS[msg.type];
  if (!handler) return;
  queue = queue
    .then(async () => {
      await ready;
      if (loadError) {
        self.postMessage({
          id: msg.id,
          type: 'error',
          message: `could not load the WebAssembly analyzer: ${describe(loadError)}`,
          line: null,
          column: null,
          excerpt: null,
          kind: null,
          fatal: true,
        });
        return;
      }
      await handler(msg);
    })
    .catch((err) => {
      self.postMessage({ id: msg.id, type: 'error', message: describe(err), line: null, column: null, excerpt: null, kind: null, fatal: true });
    });
};
