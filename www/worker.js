// quietpath analysis worker (module worker).
//
// Created by app.js as: new Worker('./worker.js', { type: 'module' })
// It loads the wasm package from ./pkg/quietpath.js and runs analyze() off the
// main thread, so the page stays responsive on big files.
//
// ── Protocol ────────────────────────────────────────────────────────────────
// page → worker
//   { id, type: 'analyze', bytes: ArrayBuffer, name: string, options }
//       `bytes` should be transferred (postMessage(msg, [bytes])).
//       `options` is passed to analyze() as is, e.g.
//       { strict?: boolean, filament_diameter_mm?: number, density_g_cm3?: number }.
//       One request at a time: analyze() is synchronous, so a second request
//       waits until the first is done. To cancel, terminate the worker.
//
// worker → page
//   { type: 'hello', version }                 once, when the wasm is loaded
//   { id, type: 'progress', fraction }         0 ≤ fraction ≤ 1, increasing,
//                                              throttled (≈ every 1 % / 50 ms)
//   { id, type: 'result', report, ms }         report: the analysis report
//                                              (same JSON as the CLI's --json),
//                                              ms: analyze() wall time
//   { id, type: 'error', message, line, column, excerpt, kind, fatal }
//       message: human-readable, from the Error thrown by analyze();
//       line/column: 1-based position of the problem, or null when unknown;
//       excerpt: the text of that line (≤ 200 chars) or null;
//       kind: the Error's `kind` property (e.g. { kind: 'invalid_number',
//       letter: 'X' }) or null;
//       fatal: true when the wasm instance may be broken (a panic / trap, or
//       the package failed to load): the page should terminate this worker
//       and start a new one for the next request.
// An uncaught failure shows up as the Worker's `error` event on the page.
// ────────────────────────────────────────────────────────────────────────────

import init, { analyze, version } from './pkg/quietpath.js';

const PROGRESS_STEP = 0.01;
const PROGRESS_INTERVAL_MS = 50;
const EXCERPT_MAX = 200;

let loadError = null;
const ready = init().then(
  () => {
    let v = null;
    try {
      v = version();
    } catch {
      // version() is informational only
    }
    self.postMessage({ type: 'hello', version: v });
  },
  (err) => {
    loadError = err;
  },
);

// Text of 1-based line `line` in `bytes`, or null.
function lineExcerpt(bytes, line) {
  if (!Number.isInteger(line) || line < 1) return null;
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

function positionOf(err, key) {
  const v = err !== null && typeof err === 'object' ? err[key] : undefined;
  return typeof v === 'number' && Number.isFinite(v) ? v : null;
}

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
function plainKind(err) {
  const k = err !== null && typeof err === 'object' ? err.kind : undefined;
  if (k === undefined || k === null) return null;
  try {
    return JSON.parse(JSON.stringify(k));
  } catch {
    return null;
  }
}

async function handleAnalyze(msg) {
  const { id, bytes, options } = msg;
  await ready;
  if (loadError) {
    self.postMessage({
      id,
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
  const data = new Uint8Array(bytes);
  let lastFraction = -1;
  let lastTime = 0;
  const onProgress = (fraction) => {
    const now = performance.now();
    if (fraction >= 1 || fraction - lastFraction >= PROGRESS_STEP || now - lastTime >= PROGRESS_INTERVAL_MS) {
      if (fraction <= lastFraction) return;
      lastFraction = fraction;
      lastTime = now;
      self.postMessage({ id, type: 'progress', fraction });
    }
  };
  const t0 = performance.now();
  try {
    const report = analyze(data, options ?? {}, onProgress);
    const ms = performance.now() - t0;
    if (lastFraction < 1) self.postMessage({ id, type: 'progress', fraction: 1 });
    self.postMessage({ id, type: 'result', report, ms });
  } catch (err) {
    const line = positionOf(err, 'line');
    const column = positionOf(err, 'column');
    self.postMessage({
      id,
      type: 'error',
      message: describe(err),
      line,
      column,
      excerpt: lineExcerpt(data, line),
      kind: plainKind(err),
      // A trap (e.g. a Rust panic → "unreachable") leaves the instance unusable.
      fatal: err instanceof WebAssembly.RuntimeError || !(err instanceof Error),
    });
  }
}

// Requests are handled strictly one after another.
let queue = Promise.resolve();
self.onmessage = (event) => {
  const msg = event.data;
  if (!msg || msg.type !== 'analyze') return;
  queue = queue.then(() => handleAnalyze(msg)).catch((err) => {
    self.postMessage({
      id: msg.id,
      type: 'error',
      message: describe(err),
      line: null,
      column: null,
      excerpt: null,
      kind: null,
      fatal: true,
    });
  });
};
