// @ts-check
// quietpath playground: page logic.
//
// Reads a G-code file (picker, drag-and-drop or the bundled demo) as an
// ArrayBuffer and hands it to the job worker (jobs.js / worker.js), which keeps
// it as a wasm Session; renders the analysis report, the layer viewer
// (viewer.js), the optimization jobs' before/after tables and charts
// (charts.js). Nothing is uploaded: the only requests this page makes are for
// its own files (enforced by the Content-Security-Policy). The view state
// (layer, colouring, job options) lives in the URL hash so a view can be
// shared; the file itself never does.

import { JobClient, Cancelled } from './jobs.js';
import { LayerViewer } from './viewer.js';
import { lineChart, clearChart, alignSeries, unionSeries } from './charts.js';

/** @typedef {import('./jobs.js').LayerMessage} LayerMessage */
/** @typedef {import('./jobs.js').JobError} JobError */
/** @typedef {import('./pkg/quietpath.js').Report} Report */
/** @typedef {import('./pkg/quietpath.js').AnalyzeOptions} AnalyzeOptions */
/** @typedef {import('./pkg/quietpath.js').MachineInfo} MachineInfo */
/** @typedef {import('./pkg/quietpath.js').MachineProfile} MachineProfile */
/** @typedef {import('./pkg/quietpath.js').Limit} Limit */
/** @typedef {import('./pkg/quietpath.js').OptimizeStage} OptimizeStage */
/** @typedef {import('./pkg/quietpath.js').VibrationReport} VibrationReport */
/** @typedef {import('./view3d.js').PartView} PartView */
/** @typedef {import('./view3d.js').PartLayer} PartLayer */
/**
 * A job's result as plain JSON (plain()): a VtgReport, InfillReport, OptimizeReport, SmoothReport
 * or VibrationReport, by the job. The page reads it field by field, defensively and whatever the
 * job (`r.after?.time_s`, `Array.isArray(r.candidates)`, …), so it is left loose: `any`.
 * @typedef {Record<string, any>} JobResult
 */
/** @typedef {'input' | 'output'} Target the file a job runs on: the loaded one or the output */
/** @typedef {{ kind: 'load' | 'job', name: string, startedAt: number, posted?: boolean }} Run the run in flight */
/** @typedef {{ name: string, load: () => Promise<ArrayBuffer> }} Source a file to analyze */
/** @typedef {{ name: string, report: Report }} Loaded the analyzed file */
/** @typedef {{ name: string, text: string, key: 'klipper_config' | 'machine_gcode' }} PrinterSettings */
/**
 * A row of the before/after table.
 * @typedef {{ name: string, before: number | null | undefined, after: number | null | undefined, format: (v: number) => string, explain?: string, noChange?: boolean }} CompareRow
 */
/**
 * A job run, kept for the job list.
 * @typedef {{ id: number, job: string, result: JobResult, target: Target, ms: number, file: string | undefined, bytes: ArrayBuffer | null }} JobEntry
 */

/**
 * The element with this id: index.html has every one this file asks for.
 * @param {string} id
 * @returns {HTMLElement}
 */
const $ = (id) => /** @type {HTMLElement} */ (document.getElementById(id));

const els = {
  status: $('status'),
  filename: $('filename'),
  elapsed: $('elapsed'),
  progress: /** @type {HTMLProgressElement} */ ($('progress')),
  cancel: /** @type {HTMLButtonElement} */ ($('cancel')),
  error: $('error'),
  file: /** @type {HTMLInputElement} */ ($('file')),
  demo: /** @type {HTMLButtonElement} */ ($('demo')),
  optionsForm: /** @type {HTMLFormElement} */ ($('options-form')),
  results: $('results'),
  stats: $('stats'),
  summary: /** @type {HTMLTableElement} */ ($('summary')),
  features: /** @type {HTMLTableElement} */ ($('features')),
  featuresEmpty: $('features-empty'),
  extraPanel: $('extra-panel'),
  extra: $('extra'),
  warnings: $('warnings'),
  warningsCount: $('warnings-count'),
  warningsEmpty: $('warnings-empty'),
  reportJson: $('report-json'),
  download: /** @type {HTMLButtonElement} */ ($('download')),
  version: $('version'),
  dropOverlay: $('drop-overlay'),
  // viewer
  canvas: /** @type {HTMLCanvasElement} */ ($('viewer')),
  legend: $('legend'),
  layerSlider: /** @type {HTMLInputElement} */ ($('layer-slider')),
  layerNumber: /** @type {HTMLOutputElement} */ ($('layer-number')),
  layerInfo: $('layer-info'),
  colorBy: /** @type {HTMLSelectElement} */ ($('color-by')),
  showTravel: /** @type {HTMLInputElement} */ ($('show-travel')),
  viewMode: /** @type {HTMLSelectElement} */ ($('view-mode')),
  fit: /** @type {HTMLButtonElement} */ ($('fit')),
  // jobs
  actionForms: [...document.querySelectorAll('form.action')].map((f) => /** @type {HTMLFormElement} */ (f)),
  resultPanel: $('result-panel'),
  resultJob: $('result-job'),
  resultLine: $('result-line'),
  compareTable: /** @type {HTMLTableElement} */ ($('compare-table')),
  paperTables: $('paper-tables'),
  downloadGcode: /** @type {HTMLButtonElement} */ ($('download-gcode')),
  chartInfill: $('chart-infill'),
  chartPsd: $('chart-psd'),
  chartLayers: $('chart-layers'),
  chartOrientation: $('chart-orientation'),
};

const DEMO_URL = 'demo/demo.gcode';
const MAX_WARNINGS_SHOWN = 500;
/** @type {Record<string, string>} */
const JOB_NAMES = { optimize: 'optimize', vtg: 'VTG', infill: 'infill search', smooth: 'orientation smoothing', vibration: 'vibration analysis' };
const LAYER_CACHE = 32;

// Fields rendered by dedicated views; everything else goes to "More".
const KNOWN_FIELDS = new Set([
  'time_s', 'moves', 'layers', 'distance_mm', 'filament_mm', 'material_g',
  'warnings', 'file', 'extrusion', 'features', 'bounds',
  'machine', 'layer_list', 'version', // the limits table, the per-layer charts, the footer
]);

// ── State ──────────────────────────────────────────────────────────────────

/** @type {Run | null} */
let current = null; // the run in flight: { kind: 'load'|'job', name, startedAt }
/** @type {Source | null} */
let lastSource = null; // { name, load: () => Promise<ArrayBuffer> }
/** @type {Loaded | null} */
let loaded = null; // the analyzed file: { name, report }
/** @type {{ job: string, bytes: ArrayBuffer } | null} */
let output = null; // the latest optimized G-code: { job, bytes: ArrayBuffer }
/** @type {{ value: unknown, filename: string } | null} */
let lastJson = null; // what report-json shows: { value, filename }
/** @type {Set<string>} */
let capabilities = new Set();
let fileToken = 0; // bumps with every new file or output: stale layer data is dropped
/** @type {Record<string, VibrationReport>} */
const vibrationRuns = {}; // target → vibration result, for the before/after charts
/** @type {Record<string, string>} */
const downloadUrls = {};

const client = new JobClient('./worker.js', {
  onHello(version, caps, presets, threads) {
    els.version.textContent = version ? `v${version}` : '';
    els.version.title = threads > 1 ? `jobs run on ${threads} threads` : 'jobs run on one thread';
    capabilities = new Set(caps);
    document.body.dataset.capabilities = caps.join(' '); // for tests and curious users
    document.body.dataset.threads = String(threads);
    machines = Array.isArray(presets) ? presets : [];
    renderMachinePicker();
    updateActions();
  },
  onCrash(detail, wasLoaded, hadPending) {
    // A crash while a request was pending is reported by that request.
    if (hadPending) return;
    showError({ message: wasLoaded ? `The analyzer crashed: ${detail}` : `The analyzer could not be started: ${detail}` }, { keepResults: true });
    setStatus('error');
  },
});

/** @param {string} text */
function setStatus(text) {
  els.status.textContent = text;
  els.status.dataset.state = text;
}

/**
 * @param {'load' | 'job'} kind
 * @param {string} name
 */
function startRun(kind, name) {
  // A file loaded over a running job: the progress goes back under the file picker.
  if (kind === 'load' && runState.classList.contains('in-job')) placeRunState(null);
  current = { kind, name, startedAt: performance.now() };
  hideError();
  els.elapsed.textContent = '';
  delete els.elapsed.dataset.ms;
  els.progress.value = 0;
  els.cancel.disabled = false;
  document.body.classList.add('busy');
  updateActions();
}

// The status, progress and Cancel move beside a running job's button (and stay in view while
// it runs: sticky), and back under the file picker afterwards.
const runState = /** @type {HTMLElement} */ (document.querySelector('.run-state'));
const runStateHome = /** @type {HTMLElement} */ (runState.parentElement);
const runStateNext = runState.nextElementSibling;

// Scrolled away from the running job's form, the progress floats at the bottom of the window.
const runFormObserver = new IntersectionObserver((entries) => {
  for (const e of entries) runState.classList.toggle('floating', runState.classList.contains('in-job') && !e.isIntersecting);
});

/** @param {HTMLFormElement | null} form */
function placeRunState(form) {
  for (const f of els.actionForms) f.classList.toggle('running', f === form);
  runFormObserver.disconnect();
  runState.classList.remove('floating');
  if (form) {
    submitOf(form).after(runState);
    runFormObserver.observe(form);
  } else runStateHome.insertBefore(runState, runStateNext);
  runState.classList.toggle('in-job', !!form);
}

/** @param {string} status */
function finishRun(status) {
  if (current && status !== 'ready') els.elapsed.textContent = `${formatMs(performance.now() - current.startedAt)} total`;
  if (current?.kind === 'job') placeRunState(null);
  current = null;
  els.cancel.disabled = true;
  document.body.classList.remove('busy');
  setStatus(status);
  updateActions();
}

/** @param {number} fraction */
const onProgress = (fraction) => {
  els.progress.value = Math.max(els.progress.value, Math.min(1, fraction));
};

/**
 * A failed request: cancelled (quietly), superseded (ignored) or an error.
 * @param {unknown} err
 * @param {{ keepResults: boolean }} opts
 */
function failRun(err, { keepResults }) {
  if (err instanceof Cancelled) {
    if (err.reason === 'superseded') return;
    finishRun('cancelled');
    els.elapsed.textContent = '';
    return;
  }
  showError(/** @type {JobError} */ (err), { keepResults });
  finishRun('error');
}

// ── Loading a file ─────────────────────────────────────────────────────────

// The printer's own settings, uploaded: { name, text, key } with key `klipper_config` (a
// printer.cfg, recognised by its [printer] section) or `machine_gcode` (Marlin's M503 text).
// Kept in localStorage (on this computer only) with the printer choice, so a visit later
// times files for the same printer.
const STORE_MACHINE = 'quietpath.machine';
const STORE_SETTINGS = 'quietpath.printer-settings';
const store = {
  /** @param {string} key */
  get(key) {
    try {
      return localStorage.getItem(key);
    } catch {
      return null; // storage disabled: nothing is remembered
    }
  },
  /**
   * @param {string} key
   * @param {string | null} value
   */
  set(key, value) {
    try {
      if (value === null) localStorage.removeItem(key);
      else localStorage.setItem(key, value);
    } catch {
      // full or disabled: the choice holds for this visit only
    }
  },
};
/** @type {PrinterSettings | null} */
let printerSettings = (() => {
  try {
    const v = JSON.parse(store.get(STORE_SETTINGS) ?? 'null');
    return v && typeof v.text === 'string' && typeof v.name === 'string' && ['klipper_config', 'machine_gcode'].includes(v.key) ? v : null;
  } catch {
    return null;
  }
})();
// The printer picked: '' (from the file: the default preset for its flavour, under the limits
// the file itself sets), a preset name, or 'upload' (the uploaded printer settings).
let machineChoice = store.get(STORE_MACHINE) ?? '';
if (machineChoice === 'upload' && !printerSettings) machineChoice = '';
/** @type {MachineProfile[]} */
let machines = []; // the package's presets (machines()), from the worker's hello

/** @type {Record<string, string>} */
const LIMIT_SOURCES = {
  profile: 'the printer preset',
  slicer_settings: "the slicer's settings in the file",
  printer_config: 'your printer.cfg',
  machine_settings: 'your M503 settings',
  command: 'a command in the file (M201…, SET_VELOCITY_LIMIT)',
  option: 'an option of this page',
};
/** @type {Record<string, [string, string]>} */
const LIMIT_NAMES = {
  max_feedrate: ['Top speed per axis (X, Y, Z, E)', 'mm/s'],
  max_acceleration: ['Top acceleration per axis (X, Y, Z, E)', 'mm/s²'],
  acceleration: ['Printing acceleration', 'mm/s²'],
  retract_acceleration: ['Retraction acceleration', 'mm/s²'],
  travel_acceleration: ['Travel acceleration', 'mm/s²'],
  max_jerk: ['Jerk per axis (X, Y, Z, E): speed change taken without slowing', 'mm/s'],
  junction_deviation: ['Junction deviation (Marlin 2 cornering)', 'mm'],
  square_corner_velocity: ['Square-corner velocity (Klipper cornering)', 'mm/s'],
  minimum_cruise_ratio: ['Minimum cruise ratio (Klipper)', ''],
  accel_to_decel: ['Acceleration to deceleration (Klipper)', 'mm/s²'],
  min_feedrate: ['Lowest printing speed', 'mm/s'],
  min_travel_feedrate: ['Lowest travel speed', 'mm/s'],
  arc_segment_mm: ['Arc segment length', 'mm'],
  instantaneous_corner_velocity: ['Extruder corner velocity (Klipper)', 'mm/s'],
};

/** How the firmware cuts arcs into segments (the limits' `arc_rule`, left out for Prusa's rule). */
const ARC_RULES = {
  chord_deviation: "Prusa's firmware: chords within 0.02 mm of the arc",
  circle_segments: 'upstream Marlin 2.1: at least 72 segments a circle, 0.1 mm to the arc segment length',
};

/**
 * Limits the file itself sets (commands or the slicer's settings block).
 * @param {Report | undefined} report
 */
function fileLimitCount(report) {
  let n = 0;
  for (const v of Object.values(report?.machine?.limits ?? {})) {
    for (const l of Array.isArray(v) ? v : [v]) if (l && typeof l === 'object' && ['command', 'slicer_settings'].includes(l.source)) n++;
  }
  return n;
}

function renderMachinePicker() {
  const sel = /** @type {HTMLSelectElement} */ ($('machine'));
  const report = loaded?.report;
  const fromFile = fileLimitCount(report);
  const auto = report?.machine?.profile && machineChoice === '' ? report.machine.profile : null;
  const fileLabel = !report
    ? 'from the file'
    : fromFile > 0
      ? `from the file (its ${fromFile} limits${auto ? `, the rest from ${auto}` : ''})`
      : `from the file (it sets no limits: ${auto ?? 'the default preset'})`;
  const opts = [el('option', { value: '', text: fileLabel })];
  for (const m of machines) opts.push(el('option', { value: m.name, text: `${m.name}: ${m.description ?? ''}`.replace(/: $/, '') }));
  if (printerSettings) opts.push(el('option', { value: 'upload', text: `${printerSettings.name} (your ${printerSettings.key === 'klipper_config' ? 'Klipper printer.cfg' : 'Marlin M503 settings'})` }));
  sel.replaceChildren(...opts);
  const known = opts.some((o) => o.value === machineChoice);
  // Presets arrive with the worker: an unknown name from an older visit falls back to the file.
  if (!known && machines.length) machineChoice = '';
  sel.value = known ? machineChoice : '';
  sel.dataset.fileLimits = String(fromFile);
}

/**
 * @param {HTMLInputElement} input
 * @param {string} message
 */
function optionError(input, message) {
  input.setAttribute('aria-invalid', 'true');
  return `${input.closest('label')?.firstChild?.textContent?.trim() || input.name}: ${message}`;
}

/**
 * A number field against its min/max: the number, '' when empty, or an error message.
 * @param {HTMLInputElement} input
 * @returns {{ value: number | '', error?: undefined } | { error: string, value?: undefined }}
 */
function checkNumber(input) {
  input.removeAttribute('aria-invalid');
  const raw = String(input.value ?? '').trim();
  // A number field holding text reads as '' with badInput set.
  if (raw === '' && !input.validity?.badInput) return { value: '' };
  const v = Number(raw);
  const unit = input.closest('label')?.lastChild?.textContent?.trim() ?? '';
  const u = unit && unit.length < 8 ? ` ${unit}` : '';
  if (raw === '' || !Number.isFinite(v)) return { error: optionError(input, `"${raw || input.value}" is not a number`) };
  if (input.min !== '' && v < Number(input.min)) return { error: optionError(input, `${raw}${u} is too small: at least ${input.min}${u}`) };
  if (input.max !== '' && v > Number(input.max)) return { error: optionError(input, `${raw}${u} is too large: at most ${input.max}${u}`) };
  if (input.step && input.step !== 'any' && Number(input.step) === 1 && !Number.isInteger(v)) return { error: optionError(input, `${raw} is not a whole number`) };
  return { value: v };
}

/** The analyze options of the Options panel and the printer picker: { options, errors }. */
function readOptions() {
  const form = new FormData(els.optionsForm);
  /** @type {AnalyzeOptions} */
  const options = {};
  const errors = [];
  if (form.get('strict')) options.strict = true;
  if (machineChoice === 'upload' && printerSettings) options[printerSettings.key] = printerSettings.text;
  else if (machineChoice && machineChoice !== 'upload') options.machine = machineChoice;
  for (const key of /** @type {const} */ (['filament_diameter_mm', 'density_g_cm3'])) {
    const r = checkNumber(/** @type {HTMLFormControlsCollection & Record<string, HTMLInputElement>} */ (els.optionsForm.elements)[key]);
    if (r.error) errors.push(r.error);
    else if (r.value !== '') options[key] = r.value;
  }
  const box = $('options-error');
  box.textContent = errors.join(' ');
  box.hidden = errors.length === 0;
  if (errors.length) /** @type {HTMLDetailsElement} */ ($('options')).open = true;
  return { options, errors };
}

/**
 * What a file is when it is not G-code text, from its first bytes; null when it may be G-code.
 * @param {ArrayBuffer} bytes
 */
function notGcode(bytes) {
  const b = new Uint8Array(bytes, 0, Math.min(bytes.byteLength, 65536));
  if (b.length === 0) return 'The file is empty (0 bytes): there is nothing to analyze.';
  /** @param {...(string | number)} sig */
  const starts = (...sig) => sig.every((v, i) => b[i] === (typeof v === 'string' ? v.charCodeAt(0) : v));
  /** @type {[(string | number)[], string][]} */
  const kinds = [
    [[0x89, 'P', 'N', 'G'], 'a PNG image'],
    [[0xff, 0xd8, 0xff], 'a JPEG image'],
    [['G', 'I', 'F', '8'], 'a GIF image'],
    [['%', 'P', 'D', 'F'], 'a PDF document'],
    [['P', 'K', 3, 4], 'a ZIP archive (a 3MF project is one: export G-code from the slicer)'],
    [['G', 'C', 'D', 'E'], 'a binary G-code file (.bgcode): export plain-text G-code from the slicer'],
    [[0x1f, 0x8b], 'a gzip archive (unpack it first)'],
  ];
  for (const [sig, what] of kinds) if (starts(...sig)) return `This is ${what}, not G-code text.`;
  // UTF-16 is the analyzer's to explain; other binary data: control bytes a text never has.
  if ((b[0] === 0xff && b[1] === 0xfe) || (b[0] === 0xfe && b[1] === 0xff)) return null;
  let control = 0;
  for (const x of b) if (x === 0 || (x < 32 && x !== 9 && x !== 10 && x !== 13 && x !== 12 && x !== 27) || x === 127) control++;
  if (control > Math.max(2, b.length / 200)) return `This is binary data, not G-code text: ${formatCount(control)} of its first ${formatCount(b.length)} bytes are control characters no text file holds.`;
  return null;
}

// The printer bed's outline, [[x, y], …] in mm, from the slicer's settings in the file
// (PrusaSlicer/SuperSlicer `; bed_shape = 0x0,180x0,…`, Orca/Creality `; printable_area = …`) or
// an uploaded Klipper printer.cfg ([stepper_x]/[stepper_y] position_min/max); null if unknown.
/**
 * @param {ArrayBuffer} bytes
 * @returns {number[][] | null}
 */
function bedShape(bytes) {
  /**
   * @param {number} a
   * @param {number} b
   */
  const text = (a, b) => new TextDecoder('latin1').decode(new Uint8Array(bytes, a, b - a));
  const n = bytes.byteLength;
  const parts = [text(Math.max(0, n - 262144), n), text(0, Math.min(n, 65536))];
  for (const t of parts) {
    const m = /^;\s*(?:bed_shape|printable_area)\s*=\s*([-\d.]+x[-\d.]+(?:\s*,\s*[-\d.]+x[-\d.]+){2,})\s*$/m.exec(t);
    if (m) {
      const pts = m[1].split(',').map((p) => p.trim().split('x').map(Number));
      if (pts.every((p) => p.length === 2 && p.every(Number.isFinite))) return pts;
    }
  }
  if (machineChoice === 'upload' && printerSettings?.key === 'klipper_config') {
    /** @param {string} a */
    const axis = (a) => {
      const sec = new RegExp(`^\\[stepper_${a}\\]([\\s\\S]*?)(?=^\\[|$(?![\\s\\S]))`, 'm').exec(/** @type {PrinterSettings} */ (printerSettings).text)?.[1] ?? '';
      /** @param {string} k */
      const get = (k) => Number(new RegExp(`^\\s*${k}\\s*[:=]\\s*([-\\d.]+)`, 'm').exec(sec)?.[1]);
      const lo = Number.isFinite(get('position_min')) ? get('position_min') : 0;
      return [lo, get('position_max')];
    };
    const [x0, x1] = axis('x');
    const [y0, y1] = axis('y');
    if ([x0, x1, y0, y1].every(Number.isFinite) && x1 > x0 && y1 > y0) return [[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
  }
  return null;
}

/**
 * A report with no move at all, on a file whose lines do not read as G-code: the reason, or null.
 * @param {Report | null} report
 */
function noGcodeIn(report) {
  if (!report || report.moves > 0) return null;
  const warnings = Array.isArray(report.warnings) ? report.warnings : [];
  const lines = report.file?.lines ?? 0;
  const unread = warnings.filter((w) => w && w.line > 0).length;
  if (lines === 0) return 'The file holds no G-code lines: there is nothing to analyze.';
  const first = warnings.find((w) => w && w.line > 0);
  if (!first) return `No G-code moves found in its ${formatCount(lines)} lines (no G0/G1/G2/G3 command): nothing to time or draw. Is this a G-code file for a printer?`;
  return `No G-code moves found: ${formatCount(unread)} of ${formatCount(lines)} lines could not be read as G-code (line ${first.line}: ${first.message ?? 'unreadable'}). Is this a G-code file?`;
}

/** @param {Source} source */
async function run(source) {
  lastSource = source;
  if (current) client.cancel('superseded');
  startRun('load', source.name);
  const run = /** @type {Run} */ (current);
  run.posted = false;
  setStatus('reading');
  els.filename.textContent = source.name;

  let bytes;
  try {
    bytes = await source.load();
  } catch (err) {
    if (current !== run) return;
    showError({ message: `Could not read ${source.name}: ${/** @type {Error | undefined} */ (err)?.message ?? err}` });
    finishRun('error');
    return;
  }
  if (current !== run) return; // cancelled while reading
  const { options, errors } = readOptions();
  const problem = errors.length ? `Check the options: ${errors.join(' ')}` : notGcode(bytes);
  if (problem) {
    loaded = null;
    resetOptimized();
    showError({ message: problem });
    finishRun('error');
    renderMachinePicker();
    return;
  }
  run.posted = true;
  setStatus('analyzing');
  // The old file is gone from the worker from here on.
  loaded = null;
  resetOptimized();
  try {
    const bed = bedShape(bytes); // before the bytes go to the worker
    const msg = await client.load(bytes, source.name, options, onProgress);
    if (current !== run) return;
    const notG = noGcodeIn(plain(msg.report));
    if (notG) {
      showError({ message: notG });
      finishRun('error');
      renderMachinePicker();
      return;
    }
    loaded = { name: source.name, report: msg.report };
    viewer.bed = bed;
    renderMachinePicker();
    showReport(msg.report, source.name, msg.ms);
    els.elapsed.dataset.totalMs = String(msg.totalMs);
    els.elapsed.dataset.workers = String(msg.workers ?? 1);
    finishRun('ready');
    resetViewer();
  } catch (err) {
    if (current !== run) return;
    failRun(err, { keepResults: false });
  }
}

function cancel() {
  if (!current) return;
  const wasLoad = current.kind === 'load';
  const posted = current.posted;
  client.cancel('cancelled'); // the run's promise settles as cancelled
  if (!posted) {
    // Still reading the file: nothing is in the worker yet.
    finishRun('cancelled');
    els.elapsed.textContent = '';
  }
  // A cancelled load leaves no file behind: don't show the previous one's report.
  if (wasLoad) {
    loaded = null;
    els.results.hidden = true;
    updateActions();
  }
}

/**
 * @param {File} file
 * @returns {Source}
 */
function fileSource(file) {
  return { name: file.name, load: () => file.arrayBuffer() };
}

/** @returns {Source} */
function demoSource() {
  return {
    name: 'demo.gcode',
    load: async () => {
      const res = await fetch(DEMO_URL);
      if (!res.ok) throw new Error(`HTTP ${res.status} for ${DEMO_URL}`);
      return res.arrayBuffer();
    },
  };
}

// ── Jobs (VTG, infill, smoothing, vibration) ───────────────────────────────

/**
 * Options of an action form: empty fields are left out (the function's defaults).
 * @param {HTMLFormElement} form
 */
function jobOptions(form) {
  /** @type {Record<string, unknown>} */
  const options = {};
  for (const input of fieldsOf(form)) {
    if (!input.name || input.name === 'target') continue;
    if (input.type === 'checkbox') {
      if (input.checked) options[input.name] = true;
      continue;
    }
    const raw = String(input.value ?? '').trim();
    if (raw === '') continue;
    if (input.type === 'number') {
      const v = Number(raw);
      if (Number.isFinite(v)) options[input.name] = v;
    } else if (input.name === 'patterns') {
      options.patterns = raw.split(/[\s,;]+/).filter(Boolean);
    } else if (input.name.endsWith('_deg') && input.type === 'text') {
      const list = raw.split(/[\s,;]+/).filter(Boolean).map(Number);
      if (list.length && list.every(Number.isFinite)) options[input.name] = list;
    } else {
      options[input.name] = raw;
    }
  }
  // OptimizeOptions (types.generated.d.ts): VTG's tolerance inside vtg_options, the infill search as
  // an options object (its defaults).
  if (form.dataset.job === 'optimize') {
    if (isNum(options.tolerance_mm)) options.vtg_options = { tolerance_mm: options.tolerance_mm };
    delete options.tolerance_mm;
    if (options.infill === true) options.infill = {};
  }
  // SmoothOptions.window is { points } or { millimetres } (types.generated.d.ts).
  if (form.dataset.job === 'smooth') {
    if (isNum(options.window_mm)) options.window = { millimetres: options.window_mm };
    else if (isNum(options.window)) options.window = { points: Math.round(options.window) };
    delete options.window_mm;
  }
  return options;
}

/**
 * An action form's Run button.
 * @param {HTMLFormElement} form
 */
function submitOf(form) {
  return /** @type {HTMLButtonElement} */ (form.querySelector('button[type="submit"]'));
}

/**
 * An action form's line for notes and errors.
 * @param {HTMLFormElement} form
 */
function noteOf(form) {
  return /** @type {HTMLElement} */ (form.querySelector('.availability'));
}

/**
 * The vibration form's "On" select (its `target` field: the loaded file or the output).
 * @param {HTMLFormElement} form
 */
function targetOf(form) {
  return /** @type {HTMLSelectElement} */ (form.elements.namedItem('target'));
}

/**
 * A form's fields (inputs, selects and buttons: each has a name, a type and a value).
 * @param {HTMLFormElement} form
 */
function fieldsOf(form) {
  return /** @type {HTMLInputElement[]} */ ([...form.elements]);
}

function updateActions() {
  const busy = !!current;
  for (const form of els.actionForms) {
    const job = /** @type {string} */ (form.dataset.job); // every action form has data-job
    const button = submitOf(form);
    const note = noteOf(form);
    button.dataset.label ??= button.textContent ?? '';
    const known = capabilities.size > 0;
    const available = capabilities.has(job);
    const needsOutput = job === 'vibration' && targetOf(form).value === 'output' && !output;
    button.disabled = !available || !loaded || busy || needsOutput;
    button.textContent = known && !available ? 'Not available in this build' : button.dataset.label;
    if (note.classList.contains('field-error')) continue;
    note.textContent = !known ? '' : !available ? `${JOB_NAMES[job]} is not available in this build of the package.` : needsOutput ? 'Run VTG, infill or smoothing first.' : '';
    if (job === 'vibration') /** @type {HTMLOptionElement} */ (targetOf(form).querySelector('option[value="output"]')).disabled = !output;
  }
  els.viewMode.disabled = !output;
}

/**
 * Number fields of an action form against their min/max: the messages (empty: fine).
 * @param {HTMLFormElement} form
 */
function jobErrors(form) {
  const errors = [];
  for (const input of fieldsOf(form)) {
    if (input.type !== 'number') continue;
    const r = checkNumber(input);
    if (r.error) errors.push(r.error);
  }
  for (const input of /** @type {NodeListOf<HTMLInputElement>} */ (form.querySelectorAll('input[type="text"][name$="_deg"]'))) {
    input.removeAttribute('aria-invalid');
    const bad = String(input.value).split(/[\s,;]+/).filter(Boolean).filter((x) => !Number.isFinite(Number(x)));
    if (bad.length) errors.push(optionError(input, `${bad.map((b) => `"${b}"`).join(', ')} ${bad.length > 1 ? 'are not numbers' : 'is not a number'} (give degrees separated by commas)`));
  }
  return errors;
}

/**
 * @param {string} job
 * @param {HTMLFormElement} form
 */
async function runJob(job, form) {
  if (!loaded || current) return;
  const errors = jobErrors(form);
  const note = noteOf(form);
  if (errors.length) {
    note.textContent = errors.join(' ');
    note.classList.add('field-error');
    return;
  }
  note.classList.remove('field-error');
  const target = job === 'vibration' ? /** @type {'input' | 'output'} */ (targetOf(form).value) : 'input';
  const options = jobOptions(form);
  startRun('job', loaded.name);
  // startRun set `current` (tsc still narrows it to null from the check above).
  const run = /** @type {Run} */ (/** @type {Run | null} */ (current));
  run.posted = true;
  placeRunState(form);
  setStatus(`running ${job}`);
  try {
    const msg = await client.job(job, options, target, onProgress);
    if (current !== run) return;
    const result = plain(msg.result);
    showJobResult(job, result, msg.output, target);
    addJobEntry(job, result, msg.output, target, msg.ms);
    els.elapsed.textContent = `${JOB_NAMES[job]} in ${formatMs(msg.ms)}`;
    els.elapsed.dataset.ms = String(msg.ms);
    finishRun('ready');
  } catch (err) {
    if (current !== run) return;
    failRun(err, { keepResults: true });
  }
}

/** Forgets everything derived from an optimized output (a new file). */
function resetOptimized() {
  output = null;
  delete vibrationRuns.input;
  delete vibrationRuns.output;
  els.resultPanel.hidden = true;
  els.downloadGcode.disabled = true;
  clearChart(els.chartInfill, 'Run the infill search to see the energy of each pattern against the infill angle.');
  clearChart(els.chartPsd, 'Run the vibration analysis to see the spectrum.');
  clearChart(els.chartLayers, 'Run the vibration analysis to see the amplitude per layer.');
  clearChart(els.chartOrientation, 'Run the orientation smoothing to see the rotary axes.');
}

/**
 * Whether a job handed back the input as it was, with nothing better to download: an infill
 * search that kept the original, or a VTG rewrite whose report says why it kept the original
 * (no layers kept: those rewrite the rest).
 * @param {string} job
 * @param {JobResult} result
 */
function handedBack(job, result) {
  if (job === 'infill') return result.best?.pattern === 'original';
  return job === 'vtg' && Boolean(result.message) && !result.peak_layers_kept?.length;
}

/**
 * @param {string} job
 * @param {JobResult} result
 * @param {ArrayBuffer | null} outBytes
 * @param {Target} target
 * @param {{ fromList?: boolean }} [opts]
 */
function showJobResult(job, result, outBytes, target, { fromList = false } = {}) {
  showJson(result, `${baseName(/** @type {Loaded} */ (loaded).name)}.${job}${target === 'output' ? '.output' : ''}.json`);
  els.resultPanel.hidden = false;
  els.resultJob.textContent = `· ${JOB_NAMES[job]}${target === 'output' ? ' of the optimized output' : ''}`;
  els.resultLine.textContent = resultLine(job, result);
  const keptOriginal = handedBack(job, result);
  if (fromList) {
    // An earlier job shown again: its tables and JSON; the viewer keeps the latest output.
    if (job === 'vibration') renderCompare(vibrationCompare());
    else {
      renderCompare(compareRows(result, job));
      renderPaperTables(result);
    }
    return;
  }
  if (keptOriginal && output) {
    // The download and the after view would otherwise offer an earlier job's file as this one's.
    output = null;
    fileToken++;
    layerCache.clear();
    delete vibrationRuns.output;
    els.downloadGcode.disabled = true;
    if (els.viewMode.value !== 'before') els.viewMode.value = 'before';
    viewer.set('mode', els.viewMode.value);
    refreshLayers();
    refresh3d();
  }
  if (outBytes && !keptOriginal) {
    output = { job, bytes: outBytes };
    fileToken++;
    layerCache.clear();
    els.downloadGcode.disabled = false;
    // The optimized output changed: a vibration run on the old one is stale.
    delete vibrationRuns.output;
    if (els.viewMode.value === 'before') els.viewMode.value = 'side';
    viewer.set('mode', els.viewMode.value);
    refreshLayers();
    refresh3d();
  }
  if (job === 'vibration') {
    vibrationRuns[target] = /** @type {VibrationReport} */ (result);
    renderCompare(vibrationCompare());
    els.paperTables.replaceChildren();
  } else {
    renderCompare(compareRows(result, job));
    renderPaperTables(result);
  }
  renderCharts(job, result);
  updateActions();
  writeHash();
}

// Every job's result, kept (newest first): its line, its main changes, its JSON and its file.
/** @type {JobEntry[]} */
const jobEntries = [];

/**
 * @param {string} job
 * @param {JobResult} result
 * @param {ArrayBuffer | null} outBytes
 * @param {Target} target
 * @param {number} ms
 */
function addJobEntry(job, result, outBytes, target, ms) {
  const entry = { id: jobEntries.length + 1, job, result, target, ms, file: loaded?.name, bytes: outBytes && !handedBack(job, result) ? outBytes : null };
  jobEntries.push(entry);
  renderJobList(entry.id);
}

/** @param {number} activeId */
function renderJobList(activeId) {
  const list = $('job-list');
  /**
   * @param {unknown} a
   * @param {unknown} b
   */
  const pct = (a, b) => (isNum(a) && isNum(b) && b !== 0 ? signedPercent(a / b - 1) : null);
  list.replaceChildren(
    ...[...jobEntries].reverse().map((e) => {
      const r = e.result;
      const changes = [
        ['time', pct(r.after?.time_s, r.before?.time_s)],
        ['energy', pct(r.after?.energy?.total_j, r.before?.energy?.total_j)],
      ].filter(([, v]) => v !== null);
      const show = el('button', { type: 'button', class: 'button small', text: 'Show' });
      show.addEventListener('click', () => {
        showJobResult(e.job, e.result, null, e.target, { fromList: true });
        renderJobList(e.id);
      });
      // A file slower or dearer than the original is offered only marked as such.
      const worse = [
        ['slower', r.after?.time_s, r.before?.time_s],
        ['uses more energy', r.after?.energy?.total_j, r.before?.energy?.total_j],
      ].filter(([, a, b]) => isNum(a) && isNum(b) && a > b * 1.0005).map(([w]) => w);
      const save = el('button', { type: 'button', class: worse.length ? 'button small worse' : 'button small', text: worse.length ? `Download (${worse.join(', ')})` : 'Download G-code', 'data-testid': 'job-download' });
      save.disabled = !e.bytes;
      save.title = !e.bytes ? 'This job wrote no better file: keep your original' : worse.length ? `This file is ${worse.join(' and ')} than your original` : 'The file this job wrote';
      save.addEventListener('click', () => e.bytes && saveBlob(`gcode-${e.id}`, new Blob([e.bytes], { type: 'text/plain' }), `${baseName(e.file)}.${e.job}-${e.id}.gcode`));
      return el(
        'li',
        { class: e.id === activeId ? 'job-entry active' : 'job-entry', 'data-job': e.job, 'data-testid': 'job-entry' },
        el('span', { class: 'job-name', text: `#${e.id} ${JOB_NAMES[e.job]}${e.target === 'output' ? ' of the output' : ''}` }),
        el('span', { class: 'muted small', text: `${e.file ?? ''} · ${formatMs(e.ms)}` }),
        el('span', { class: 'job-changes', text: changes.map(([k, v]) => `${k} ${v}`).join(', ') || resultLine(e.job, r).slice(0, 120) }),
        el('span', { class: 'job-buttons' }, show, save),
      );
    }),
  );
  $('job-list-panel').hidden = jobEntries.length === 0;
}

/**
 * @param {string} job
 * @param {JobResult} r
 */
function resultLine(job, r) {
  /**
   * @param {unknown} v
   * @param {number} [d]
   */
  const n = (v, d = 3) => (isNum(v) ? String(Math.round(v * 10 ** d) / 10 ** d) : '—');
  /**
   * @param {unknown} a
   * @param {unknown} b
   */
  const pct = (a, b) => (isNum(a) && isNum(b) && b !== 0 ? signedPercent(a / b - 1) : '—');
  switch (job) {
    case 'vtg':
      if (handedBack(job, r)) return `Your file is kept as it was: ${r.message.replace(/^kept the original: /, '')}.`;
      return `Tolerance ${n(r.tolerance_mm)} mm, largest deviation from the original path ${n(r.max_deviation_mm, 4)} mm; energy ${pct(r.after?.energy?.total_j, r.before?.energy?.total_j)}, time ${pct(r.after?.time_s, r.before?.time_s)}${isNum(r.paths?.arcs_written) && r.paths.arcs_written > 0 ? `; ${r.paths.arcs_written} arcs` : ''}${isNum(r.paths?.kept_for_lines) && r.paths.kept_for_lines > 0 ? `; ${r.paths.kept_for_lines} paths kept sharp to add no lines (allow more lines to round them)` : ''}${r.peak_layers_kept?.length ? `; ${r.message}` : ''}.`;
    case 'infill': {
      const b = r.best ?? {};
      if (b.pattern === 'original') return `No candidate beats your file: it is kept as it was (${r.candidates?.length ?? '—'} candidates). ${b.message ?? ''}`;
      return `Best: ${b.pattern ?? '—'} at ${n(b.angle_deg, 1)}°${isNum(b.rotation_deg) ? ` (rotation ${n(b.rotation_deg, 1)}°)` : ''} of ${Array.isArray(r.candidates) ? r.candidates.length : '—'} candidates${r.candidates_estimated ? ` (${r.candidates_estimated} ruled out as clearly worse on a sample of layers)` : ''}; energy ${pct(r.after?.energy?.total_j, r.before?.energy?.total_j)}.`;
    }
    case 'optimize':
      return (r.stages ?? []).map((/** @type {OptimizeStage} */ s) => `${s.stage}: ${s.applied ? '' : 'not applied, '}${s.message}.`).join(' ');
    case 'smooth':
      return `${formatCount(r.points)} points, ${formatCount(r.corrected)} corrected; the smoothed orientation stays within ${n(r.max_angle_to_original_deg, 2)}° of the original.`;
    case 'vibration': {
      const f = Array.isArray(r.natural_frequencies_hz) ? r.natural_frequencies_hz.map((/** @type {number} */ v) => `${n(v, 1)} Hz`).join(', ') : '—';
      return `Natural frequencies ${f}; deviation max ${n(r.deviation_mm?.max, 4)} mm, mean ${n(r.deviation_mm?.mean, 4)} mm.`;
    }
    default:
      return '';
  }
}

// Every metric the page shows by its key: [name, unit, one-line explanation]. The names of the
// VTG paper's Tables 1 and 2 where they come from it (docs/method/ says how each is computed).
/** @type {Record<string, [string, string, string]>} */
const METRICS = {
  time_s: ['Print time', 's', 'How long the printer takes, planned with its accelerations and cornering.'],
  planned_time_s: ['Print time (planned)', 's', 'How long the printer takes, planned with its accelerations and cornering.'],
  energy_j: ['Energy', 'J', 'Electricity for the whole print: motors, heating the filament and the rest of the machine.'],
  total_j: ['Energy', 'J', 'Electricity for the whole print: motors, heating the filament and the rest of the machine.'],
  thesis_j: ['Motor energy (stepper model)', 'J', 'Energy the axis motors use, from a measured stepper-motor model.'],
  servo_energy_j: ['Motor energy (servo model)', 'J', "Energy the axis motors of the VTG paper's servo printer use."],
  fuse_j: ['Melting energy', 'J', 'Heat that melts the filament.'],
  aux_j: ['Machine upkeep energy', 'J', 'Fans, electronics and keeping the bed and nozzle hot, over the print time.'],
  co2_g: ['CO₂ emitted', 'g', "Carbon dioxide of that electricity, at the grid's average intensity."],
  material_g: ['Filament used', 'g', 'Weight of the filament the print uses.'],
  distance_mm: ['Head travel', 'mm', 'How far the nozzle moves in all, printing and travelling.'],
  filament_mm: ['Filament length', 'mm', 'How much filament goes through the extruder.'],
  l_total_mm: ['Path length L', 'mm', 'Length of the whole printed path (VTG paper, Table 1).'],
  n_total: ['Segments N', '', 'Number of straight pieces the path is cut into.'],
  l_infill_mm: ['Infill path length', 'mm', 'Length of the infill part of the path.'],
  n_infill: ['Infill segments', '', 'Number of straight pieces in the infill.'],
  n_turning: ['Sharp turns', '', 'Corners sharper than the critical angle: the head brakes there and shakes.'],
  n_corners: ['Corners', '', 'Every change of direction along the path.'],
  mean_turn_deg: ['Mean turning angle', '°', 'Average change of direction at a corner; smaller is smoother.'],
  mean_chord_error_mm: ['Mean chord error', 'mm', 'Average gap between the straight pieces and the smooth curve through them.'],
  co2: ['CO₂', 'g', ''],
  aux: ['Machine upkeep', 'J', ''],
  fuse: ['Melting the filament', 'J', ''],
  thesis: ['Stepper motor model', '', ''],
  grid_kg_per_kwh: ['Grid carbon intensity', 'kg/kWh', 'CO₂ per kWh of the electricity.'],
  material_kg_per_kg: ['Material carbon intensity', 'kg/kg', 'CO₂ of making a kilogram of the filament.'],
  print_temp_c: ['Nozzle temperature', '°C', ''],
  ambient_c: ['Room temperature', '°C', ''],
  max_mm: ['largest', 'mm', ''],
  min_mm: ['smallest', 'mm', ''],
  mean_mm: ['mean', 'mm', ''],
  deviation: ['Vibration deviation', 'mm', 'How far vibration pushes the nozzle off its path (the dynamics model).'],
  max_deviation_mm: ['Largest path change', 'mm', 'Farthest the new path goes from the original one (at most the tolerance).'],
  max_tip_deviation_mm: ['Largest nozzle-tip change', 'mm', 'Farthest the smoothed orientation moves the nozzle tip.'],
};

/**
 * [name, unit, explanation] of a key, with a readable fallback for keys not in METRICS.
 * @param {string} key
 * @returns {[string, string, string]}
 */
function metricInfo(key) {
  if (METRICS[key]) return METRICS[key];
  const m = /_(mm|s|g|j|deg|hz|pct|mm3|c|w|kwh)$/.exec(key);
  /** @type {Record<string, string>} */
  const units = { mm: 'mm', s: 's', g: 'g', j: 'J', deg: '°', hz: 'Hz', pct: '%', mm3: 'mm³', c: '°C', w: 'W', kwh: 'kWh' };
  const base = (m ? key.slice(0, -m[0].length) : key).replaceAll('_', ' ');
  return [base.charAt(0).toUpperCase() + base.slice(1), m ? units[m[1]] : '', ''];
}

// Rows of the before/after table, in the order of the VTG paper's Tables 1 and 2.
/** @type {[string, (r: Report) => number | undefined, (v: number) => string, string][]} */
const REPORT_METRICS = [
  ['Print time', (r) => r.time_s, formatDuration, METRICS.time_s[2]],
  ['Energy', (r) => r.energy?.total_j, formatEnergy, METRICS.total_j[2]],
  ['Stepper energy', (r) => r.energy?.thesis_j, formatEnergy, METRICS.thesis_j[2]],
  ['CO₂', (r) => r.energy?.co2_g, (v) => `${fmt2.format(v)} g`, METRICS.co2_g[2]],
  ['Material', (r) => r.material_g, (v) => `${fmt2.format(v)} g`, METRICS.material_g[2]],
  ['Path length', (r) => r.toolpath?.l_total_mm ?? r.distance_mm, formatLength, METRICS.l_total_mm[2]],
  ['Turning points', (r) => r.toolpath?.n_turning, formatCount, METRICS.n_turning[2]],
  ['Mean turning angle', (r) => r.toolpath?.mean_turn_deg, (v) => `${fmt1.format(v)}°`, METRICS.mean_turn_deg[2]],
  ['Mean chord error', (r) => r.toolpath?.mean_chord_error_mm, (v) => `${v.toFixed(4)} mm`, METRICS.mean_chord_error_mm[2]],
];

/**
 * @param {JobResult} result
 * @param {string} job
 * @returns {CompareRow[]}
 */
function compareRows(result, job) {
  const { before, after } = result;
  if (!before || !after) return [];
  /** @param {JobResult} r */
  const isReport = (r) => isNum(r.time_s) || isNum(r.energy?.total_j);
  /** @type {CompareRow[]} */
  const rows = [];
  if (isReport(before) && isReport(after)) {
    for (const [name, get, format, explain] of REPORT_METRICS) {
      const b = get(before);
      const a = get(after);
      if (isNum(b) || isNum(a)) rows.push({ name, before: b, after: a, format, explain });
    }
  } else {
    // Metrics objects (smoothing): every numeric field, formatted by its unit.
    const keys = [...new Set([...Object.keys(before), ...Object.keys(after)])];
    for (const k of keys) {
      if (isNum(before[k]) || isNum(after[k])) {
        const [name, , explain] = metricInfo(k);
        rows.push({ name, before: before[k], after: after[k], format: (v) => formatByKey(k, v), explain });
      }
    }
  }
  if (isNum(result.planned_time_before_s) && isNum(result.planned_time_after_s)) {
    rows.unshift({ name: 'Print time (planned)', before: result.planned_time_before_s, after: result.planned_time_after_s, format: formatDuration });
  }
  if (isNum(result.max_tip_deviation_mm)) {
    rows.push({ name: 'Tool-tip deviation (max)', before: 0, after: result.max_tip_deviation_mm, format: (v) => `${v.toFixed(4)} mm`, noChange: true, explain: METRICS.max_tip_deviation_mm[2] });
  }
  if (job === 'vtg' && isNum(result.max_deviation_mm)) {
    rows.push({ name: 'Deviation (max)', before: 0, after: result.max_deviation_mm, format: (v) => `${v.toFixed(4)} mm`, noChange: true, explain: METRICS.max_deviation_mm[2] });
  }
  return rows;
}

/** @returns {CompareRow[]} */
function vibrationCompare() {
  const b = vibrationRuns.input;
  const a = vibrationRuns.output;
  /**
   * @param {VibrationReport | undefined} r
   * @param {'amplitude' | 'acceleration_rms'} key
   */
  const meanOf = (r, key) => {
    const v = Array.isArray(r?.layers) ? r.layers.map((l) => l[key]).filter(isNum) : [];
    return v.length ? v.reduce((x, y) => x + y, 0) / v.length : null;
  };
  /** @param {VibrationReport | undefined} r */
  const mean = (r) => meanOf(r, 'amplitude');
  /** @param {VibrationReport | undefined} r */
  const peak = (r) => {
    const p = r?.psd?.peaks?.[0];
    return p ? p.hz : null;
  };
  /** @param {number} v */
  const mm = (v) => `${v.toFixed(4)} mm`;
  return [
    { name: 'Deviation (max)', before: b?.deviation_mm?.max, after: a?.deviation_mm?.max, format: mm, explain: 'Farthest vibration pushes the nozzle off its path.' },
    { name: 'Deviation (mean)', before: b?.deviation_mm?.mean, after: a?.deviation_mm?.mean, format: mm, explain: 'How far vibration pushes the nozzle off its path, on average.' },
    { name: 'Mean layer amplitude', before: mean(b), after: mean(a), format: mm, explain: 'Vibration amplitude of a layer, averaged over the layers.' },
    { name: 'Mean layer acceleration RMS', before: meanOf(b, 'acceleration_rms'), after: meanOf(a, 'acceleration_rms'), format: (/** @type {number} */ v) => `${fmt2.format(v)} m/s²`, explain: 'How hard the head shakes (root mean square acceleration), averaged over the layers.' },
    { name: 'Strongest PSD peak', before: peak(b), after: peak(a), format: (/** @type {number} */ v) => `${fmt1.format(v)} Hz`, noChange: true, explain: 'Frequency at which the machine shakes most (peak of the power spectrum).' },
  ].filter((r) => isNum(r.before) || isNum(r.after));
}

/** @param {CompareRow[]} rows */
function renderCompare(rows) {
  /**
   * @param {number | null | undefined} v
   * @param {(v: number) => string} format
   */
  const cell = (v, format) => el('td', { class: 'num', text: isNum(v) ? format(v) : '—' });
  els.compareTable.tBodies[0].replaceChildren(
    ...rows.map((r) => {
      const change = !r.noChange && isNum(r.before) && isNum(r.after) && r.before !== 0 ? signedPercent(r.after / r.before - 1) : '—';
      const explain = r.explain ?? Object.values(METRICS).find(([name]) => name === r.name)?.[2];
      const tr = el('tr', {}, el('th', { scope: 'row' }, r.name, explain ? el('small', { class: 'explain', text: explain }) : null), cell(r.before, r.format), cell(r.after, r.format), el('td', { class: 'num', text: change }));
      if (change.startsWith('−')) tr.classList.add('better');
      return tr;
    }),
  );
}

/**
 * Rows of a paper table in whatever shape the result gives it.
 * @param {unknown} t
 * @returns {Record<string, unknown>[]}
 */
function tableRows(t) {
  if (Array.isArray(t)) return t.map((r) => (r && typeof r === 'object' ? r : { value: r }));
  if (t && typeof t === 'object') {
    return Object.entries(t).map(([k, v]) => (v && typeof v === 'object' && !Array.isArray(v) ? { metric: k, ...v } : { metric: k, value: v }));
  }
  return [];
}

/** @typedef {{ key: string, name: string, unit: string, explain: string | undefined, before: unknown, after: unknown, change: unknown }} PaperRow */

/**
 * A paper table's { before, after, change_pct } rows, nested groups flattened: [{ key, name, before, after, change }].
 * @param {any} t
 * @param {string | null} [prefix]
 * @returns {PaperRow[]}
 */
function paperRows(t, prefix = null) {
  /** @type {PaperRow[]} */
  const rows = [];
  if (!t || typeof t !== 'object' || Array.isArray(t)) return rows;
  for (const [k, v] of Object.entries(t)) {
    if (!v || typeof v !== 'object') continue;
    if ('before' in v || 'after' in v) {
      const [name, unit, explain] = metricInfo(k);
      const [pname, , pexplain] = prefix ? metricInfo(prefix) : [];
      rows.push({ key: k, name: prefix ? `${pname}, ${name}` : name, unit, explain: prefix ? pexplain : explain, before: v.before, after: v.after, change: v.change_pct });
    } else rows.push(...paperRows(v, k));
  }
  return rows;
}

/** @param {JobResult} result */
function renderPaperTables(result) {
  const tables = Object.keys(result).filter((k) => /^table\d+$/.test(k));
  /** @type {Record<string, string>} */
  const titles = { table1: 'VTG paper, Table 1: the toolpath', table2: 'VTG paper, Table 2: vibration, energy and time' };
  els.paperTables.replaceChildren(
    ...tables.map((k) => {
      const flat = paperRows(result[k]);
      if (flat.length) {
        /**
         * @param {PaperRow} r
         * @param {unknown} v
         */
        const value = (r, v) => (isNum(v) ? formatByKey(r.key, v) : '—');
        return el(
          'div',
          { class: 'paper-table', 'data-table': k },
          el('h3', { text: titles[k] ?? `Paper ${k.replace('table', 'Table ')}` }),
          el(
            'div',
            { class: 'table-scroll' },
            el(
              'table',
              { class: 'grid' },
              el('thead', {}, el('tr', {}, el('th', { text: 'Metric' }), el('th', { class: 'num', text: 'Before' }), el('th', { class: 'num', text: 'After' }), el('th', { class: 'num', text: 'Change' }))),
              el(
                'tbody',
                {},
                ...flat.map((r) =>
                  el(
                    'tr',
                    {},
                    el('th', { scope: 'row' }, r.name, r.explain ? el('small', { class: 'explain', text: r.explain }) : null),
                    el('td', { class: 'num', text: value(r, r.before) }),
                    el('td', { class: 'num', text: value(r, r.after) }),
                    el('td', { class: 'num', text: isNum(r.change) ? signedPercent(r.change / 100) : '—' }),
                  ),
                ),
              ),
            ),
          ),
        );
      }
      const rows = tableRows(result[k]);
      const first = ['metric', 'name', 'quantity'];
      const cols = [...new Set(rows.flatMap((r) => Object.keys(r)))].sort((a, b) => (first.includes(b) ? 1 : 0) - (first.includes(a) ? 1 : 0));
      return el(
        'div',
        { class: 'paper-table', 'data-table': k },
        el('h3', { text: `Paper ${k.replace('table', 'Table ')}` }),
        el(
          'div',
          { class: 'table-scroll' },
          el(
            'table',
            { class: 'grid' },
            el('thead', {}, el('tr', {}, ...cols.map((c) => el('th', { class: first.includes(c) ? null : 'num', text: c.replaceAll('_', ' ') })))),
            el('tbody', {}, ...rows.map((r) => el('tr', {}, ...cols.map((c) => el('td', { class: first.includes(c) ? null : 'num', text: formatByKey(c, r[c]) }))))),
          ),
        ),
      );
    }),
  );
}

/**
 * @param {string} job
 * @param {JobResult} r
 */
function renderCharts(job, r) {
  if (job === 'infill' && Array.isArray(r.candidates) && r.candidates.length) {
    // Best rotation for each (pattern, angle): one line per pattern.
    /** @type {Map<string, Map<number, number>>} */
    const byPattern = new Map();
    for (const c of r.candidates) {
      if (!isNum(c.angle_deg) || !isNum(c.total_j)) continue;
      const m = byPattern.get(c.pattern) ?? new Map();
      if (!m.has(c.angle_deg) || c.total_j < m.get(c.angle_deg)) m.set(c.angle_deg, c.total_j);
      byPattern.set(c.pattern, m);
    }
    const list = [...byPattern].map(([pattern, m]) => {
      const x = [...m.keys()].sort((a, b) => a - b);
      return { label: String(pattern), x, y: x.map((a) => /** @type {number} */ (m.get(a))) };
    });
    if (list.length) {
      const u = unionSeries(list);
      lineChart(els.chartInfill, { x: u.x, xLabel: 'infill angle, °', yLabel: 'energy, J', points: true, series: list.map((s, i) => ({ label: s.label, values: u.values[i] })) });
    }
  }
  if (job === 'vibration') {
    const runs = /** @type {Target[]} */ (['input', 'output']).filter((t) => vibrationRuns[t]?.psd?.freqs?.length);
    if (runs.length) {
      const list = runs.map((t) => ({ label: t === 'input' ? 'before' : 'after', x: vibrationRuns[t].psd.freqs, y: vibrationRuns[t].psd.power }));
      const a = alignSeries(list);
      lineChart(els.chartPsd, { x: a.x, xLabel: 'frequency, Hz', yLabel: 'power', logY: true, points: false, series: list.map((s, i) => ({ label: s.label, values: a.values[i] })) });
    }
    const layerRuns = /** @type {Target[]} */ (['input', 'output']).filter((t) => Array.isArray(vibrationRuns[t]?.layers) && vibrationRuns[t].layers.length);
    if (layerRuns.length) {
      const list = layerRuns.map((t) => ({ label: t === 'input' ? 'before' : 'after', x: vibrationRuns[t].layers.map((l, i) => (isNum(l.layer) ? l.layer : i)), y: vibrationRuns[t].layers.map((l) => l.amplitude) }));
      const u = unionSeries(list);
      lineChart(els.chartLayers, { x: u.x, xLabel: 'layer', yLabel: 'amplitude', series: list.map((s, i) => ({ label: s.label, values: u.values[i] })) });
    }
  }
  if (job === 'smooth' && r.series) {
    // The crate's SmoothSeries (thinned to ≤ 2000 points): { axes, point, first_before,
    // first_after, second_before, second_after }.
    const s = r.series;
    const [ax1, ax2] = Array.isArray(s.axes) && s.axes.length >= 2 ? s.axes : ['B', 'C'];
    const cols = [s.first_before, s.first_after, s.second_before, s.second_after];
    const n = Math.max(...cols.map((a) => (Array.isArray(a) ? a.length : 0)));
    if (n > 0) {
      const x = Array.isArray(s.point) && s.point.length === n ? s.point : Array.from({ length: n }, (_, i) => i);
      /** @param {unknown} a */
      const pad = (a) => (Array.isArray(a) ? (a.length === n ? a : [...a, ...new Array(Math.max(0, n - a.length)).fill(null)].slice(0, n)) : new Array(n).fill(null));
      lineChart(els.chartOrientation, {
        x,
        xLabel: 'point',
        yLabel: 'angle, °',
        points: false,
        series: [
          { label: `${ax1} before`, values: pad(cols[0]), color: '#9ab8ae' },
          { label: `${ax1} after`, values: pad(cols[1]), color: '#1f6f5c' },
          { label: `${ax2} before`, values: pad(cols[2]), color: '#f2b7a6' },
          { label: `${ax2} after`, values: pad(cols[3]), color: '#e4572e' },
        ],
      });
    }
  }
}

// ── Per-layer charts ───────────────────────────────────────────────────────

// Time, energy and filament of every layer (the report's layer_list); a click shows that
// layer in the viewer (the viewer's layer at the same height).
/** @param {Report} report */
function renderLayerCharts(report) {
  const list = Array.isArray(report.layer_list) ? report.layer_list : [];
  /** @type {[string, 'time_s' | 'energy_j' | 'filament_mm', string][]} */
  const ids = [
    ['chart-layer-time', 'time_s', 'time, s'],
    ['chart-layer-energy', 'energy_j', 'energy, J'],
    ['chart-layer-filament', 'filament_mm', 'filament, mm'],
  ];
  const summary = $('layers-summary');
  if (list.length === 0) {
    for (const [id] of ids) clearChart($(id), 'No layers in this file.');
    summary.textContent = '';
    return;
  }
  const x = list.map((l, i) => (isNum(l.index) ? l.index : i) + 1);
  /** @param {number} i */
  const pick = (i) => showLayerAt(i, list[i]?.z);
  for (const [id, key, label] of ids) {
    lineChart($(id), { x, xLabel: 'layer', yLabel: label, height: 200, points: list.length <= 60, series: [{ label, values: list.map((l) => (isNum(l[key]) ? l[key] : null)) }], onPick: pick });
  }
  // Text alternative: the layers that take longest and shortest.
  const times = list.map((l) => l.time_s).filter(isNum);
  if (times.length) {
    const lo = Math.min(...times);
    const hi = Math.max(...times);
    summary.textContent = `${list.length} layers; the shortest takes ${formatDuration(lo)}, the longest ${formatDuration(hi)}.`;
  }
  layerTimes = list.map((l) => ({ z: l.z, t: l.time_s }));
  updateLayerTime();
}

/** @type {{ z: number | null, t: number }[]} */
let layerTimes = []; // [{ z, t }] of the loaded file, for the 'layer time' colouring

/**
 * The time of the report layer nearest height z.
 * @param {unknown} z
 * @returns {number | null}
 */
function layerTimeAt(z) {
  if (!isNum(z) || layerTimes.length === 0) return null;
  /** @type {{ z: number | null, t: number } | null} */
  let best = null;
  for (const l of layerTimes) if (isNum(l.z) && isNum(l.t) && (!best || Math.abs(l.z - z) < Math.abs(/** @type {number} */ (best.z) - z))) best = l; // best: a layer with a number z
  return best ? best.t : null;
}

function updateLayerTime() {
  const ts = layerTimes.map((l) => l.t).filter(isNum);
  viewer.layerTime = {
    before: layerTimeAt(viewer.before?.z),
    after: layerTimeAt(viewer.after?.z),
    lo: ts.length ? Math.min(...ts) : 0,
    hi: ts.length ? Math.max(...ts) : 1,
  };
  viewer.requestDraw();
}

/**
 * Shows the viewer's layer at height z (a report layer's), else the layer numbered i.
 * @param {number} i
 * @param {number | null | undefined} z
 */
async function showLayerAt(i, z) {
  try {
    const g = await getLayer('before', i, isNum(z) ? z : null);
    els.layerSlider.value = String(g.index);
    refreshLayers();
    writeHash();
    els.canvas.scrollIntoView({ block: 'nearest', behavior: 'smooth' });
  } catch (err) {
    if (!(err instanceof Cancelled)) els.layerInfo.textContent = `Cannot show that layer: ${/** @type {Error} */ (err).message}`;
  }
}

// ── 3-D view ───────────────────────────────────────────────────────────────

const viewKind = /** @type {HTMLSelectElement} */ ($('view-kind'));
const canvas3d = /** @type {HTMLCanvasElement} */ ($('view-3d'));
const range3d = $('range-3d');
const layerFrom = /** @type {HTMLInputElement} */ ($('layer-from'));
const layerTo = /** @type {HTMLInputElement} */ ($('layer-to'));
const showTools = /** @type {HTMLInputElement} */ ($('show-tools'));
const showToolsLabel = $('show-tools-label');
const MAX_3D_SEGMENTS = 1_500_000;
/** @type {PartView | null} */
let partView = null; // view3d.js's PartView, made the first time the 3-D view is shown
/** @type {typeof import('./view3d.js') | null} */
let view3d = null; // the module, loaded with the first PartView
let toolsAvailable = false; // whether the layers last drawn in 3-D carry tool vectors (multi-axis)
/** @type {Map<string, Map<number, LayerMessage>>} */
const part3d = new Map(); // `${fileToken}:${which}` → (index → geometry), of the current file only
let part3dRun = 0;

/**
 * Layers from..to (0-based) of `which`, every `stride`-th, fetched once per file.
 * @param {'before' | 'after'} which
 * @param {number} from
 * @param {number} to
 * @param {number} stride
 * @param {number} run
 * @returns {Promise<PartLayer[] | null>}
 */
async function partLayers(which, from, to, stride, run) {
  const key = `${fileToken}:${which}`;
  for (const k of part3d.keys()) if (!k.startsWith(`${fileToken}:`)) part3d.delete(k);
  if (!part3d.has(key)) part3d.set(key, new Map());
  const cache = /** @type {Map<number, LayerMessage>} */ (part3d.get(key)); // set just above
  const out = [];
  for (let i = from; i <= to; i += stride) {
    if (run !== part3dRun) return null;
    let g = cache.get(i);
    if (!g) {
      g = await client.layer(which, i);
      cache.set(i, g);
    }
    if (g.index !== i) break; // past the last layer of this file
    out.push({ ...g, time: layerTimeAt(g.z) });
  }
  return out;
}

/** Draws the chosen layer range in 3-D: "after" over a grey "before" when there is an output. */
async function refresh3d(refit = false) {
  if (viewKind.value !== '3d' || !loaded) return;
  const run = ++part3dRun;
  try {
    if (!partView || !view3d) {
      view3d = await import('./view3d.js');
      partView = new view3d.PartView(canvas3d);
      $('tools-swatch').style.background = view3d.TOOL_COLOR;
    }
    const first = await client.layer('before', 0);
    const count = first.count;
    layerFrom.max = layerTo.max = String(count);
    if (!layerTo.value || Number(layerTo.value) > count) layerTo.value = String(count);
    const from = Math.max(0, Math.min(count - 1, Math.round(Number(layerFrom.value) || 1) - 1));
    const to = Math.max(from, Math.min(count - 1, Math.round(Number(layerTo.value) || count) - 1));
    // Thin out the layers of a big file so the view stays quick (every k-th layer).
    const share = (to - from + 1) / Math.max(1, count);
    const stride = Math.max(1, Math.ceil(((loaded.report.moves ?? 0) * share) / MAX_3D_SEGMENTS));
    els.layerInfo.textContent = 'reading the layers for the 3-D view…';
    const mode = els.viewMode.value;
    const which = output && mode !== 'before' ? 'after' : 'before';
    const shown = await partLayers(which, from, to, stride, run);
    const ghost = which === 'after' && (mode === 'side' || mode === 'overlay') ? await partLayers('before', from, to, stride, run) : null;
    if (!shown || run !== part3dRun) return;
    const range = viewer.colorBy === 'layer-time' ? { lo: viewer.layerTime?.lo ?? 0, hi: viewer.layerTime?.hi ?? 1 } : rangeOf(shown, viewer.colorBy);
    // The tool-vector toggle is offered for a multi-axis file only (the crate sends its vectors).
    toolsAvailable = view3d.toolCount(shown) > 0;
    showToolsLabel.hidden = !toolsAvailable;
    partView.setLayers(shown, ghost, { colorBy: viewer.colorBy, showTravel: viewer.showTravel, showTools: showTools.checked, range, bed: viewer.bed }, refit);
    canvas3d.dataset.layers = String(shown.length);
    els.layerInfo.textContent = `3-D: layers ${from + 1}–${to + 1}${stride > 1 ? ` (every ${stride}th, to stay quick)` : ''} of the ${which === 'after' ? 'optimized output' : 'file'} · ${formatCount(Number(canvas3d.dataset.segments))} segments`;
    canvas3d.setAttribute('aria-label', describe3d(shown, { from, to, count, stride, which, ghost: !!ghost }));
  } catch (err) {
    if (!(err instanceof Cancelled)) els.layerInfo.textContent = `Cannot draw the 3-D view: ${/** @type {Error} */ (err).message}`;
  }
}

const KEYS_3D = 'Drag to orbit, right-drag or Shift+drag to pan, wheel or pinch to zoom, arrow keys to orbit, +/- to zoom.';

/**
 * The 3-D canvas's text alternative: which layers of which file, their heights, what is
 * drawn and in which colours, and the keys.
 * @param {{ z: number | null, xyz?: Float32Array }[]} shown the layers drawn
 * @param {{ from: number, to: number, count: number, stride: number, which: 'before' | 'after', ghost: boolean }} what
 * @returns {string}
 */
function describe3d(shown, { from, to, count, stride, which, ghost }) {
  const zs = shown.map((g) => g.z).filter(isNum);
  const heights = zs.length ? `, z = ${Math.min(...zs).toFixed(2)} to ${Math.max(...zs).toFixed(2)} mm` : '';
  const colours = { feature: 'feature', speed: 'speed', curvature: 'curvature', 'layer-time': 'layer time' }[viewer.colorBy] ?? viewer.colorBy;
  return (
    `The part in 3-D: layers ${from + 1} to ${to + 1} of ${count}${stride > 1 ? ` (every ${stride}th)` : ''}${heights}, ` +
    `of the ${which === 'after' ? 'optimized output' : 'file'}${ghost ? ' over the original in grey' : ''}` +
    `${shown.some((g) => g.xyz?.length) ? ' drawn on the workpiece (the tool tip through the rotary axes)' : ''}, ` +
    `${formatCount(Number(canvas3d.dataset.segments))} segments, coloured by ${colours}${viewer.showTravel ? ', travels shown' : ''}${toolsText()}. ${KEYS_3D}`
  );
}

/** The 3-D label's words on the tool vectors of a multi-axis file ('' for a three-axis one). */
function toolsText() {
  const n = Number(canvas3d.dataset.toolVectors);
  if (!toolsAvailable) return '';
  return n > 0 ? `, ${formatCount(n)} tool vectors (tool axis from the tip) in magenta` : ', tool vectors hidden';
}

/**
 * Colour range of speed or curvature over the layers (curvature clipped at its 95th percentile).
 * @param {PartLayer[]} layers
 * @param {string} key
 */
function rangeOf(layers, key) {
  if (key !== 'speed' && key !== 'curvature') return null;
  const values = [];
  for (const g of layers) {
    const a = g[/** @type {'speed' | 'curvature'} */ (key)];
    const step = Math.max(1, Math.floor(a.length / 500));
    for (let i = 0; i < a.length; i += step) if (g.kind[i] !== 0 && Number.isFinite(a[i])) values.push(a[i]);
  }
  if (!values.length) return { lo: 0, hi: 1 };
  values.sort((p, q) => p - q);
  const lo = key === 'speed' ? values[0] : 0;
  const hi = key === 'speed' ? values[values.length - 1] : values[Math.floor(0.95 * (values.length - 1))];
  return { lo, hi: hi > lo ? hi : lo + 1 };
}

/** @param {string} kind */
function setViewKind(kind) {
  const three = kind === '3d';
  els.canvas.hidden = three;
  canvas3d.hidden = !three;
  range3d.hidden = !three;
  els.layerSlider.disabled = three;
  els.fit.disabled = three;
  showToolsLabel.hidden = !three || !toolsAvailable;
  if (three) refresh3d(true);
  else refreshLayers();
}

viewKind.addEventListener('change', () => setViewKind(viewKind.value));
layerFrom.addEventListener('change', () => refresh3d(true));
layerTo.addEventListener('change', () => refresh3d(true));

// ── Layer viewer ───────────────────────────────────────────────────────────

const hoverInfo = $('hover-info');
const viewer = new LayerViewer(els.canvas, els.legend, {
  onHover(hit) {
    hoverInfo.textContent = hit
      ? `${hit.which ? `${hit.which}: ` : ''}${hit.kind} · ${fmt1.format(hit.speed)} mm/s · curvature ${hit.curvature.toFixed(3)} /mm · at ${fmt1.format(hit.x)}, ${fmt1.format(hit.y)} mm`
      : '';
  },
});
/** @type {Map<string, LayerMessage>} */
const layerCache = new Map(); // `${token}:${which}:${index}` → geometry
const layerCounts = { before: 0, after: 0 };
let layerLoading = false;
let layerWanted = false;

/**
 * One layer's drawing data, cached. With a number `z`, the layer nearest that height (the
 * worker finds it): how "after" shows the layer at the same height as "before", whatever the
 * output's layer count.
 * @param {'before' | 'after'} which
 * @param {number} index
 * @param {number | null} [z]
 * @returns {Promise<LayerMessage>}
 */
async function getLayer(which, index, z = null) {
  const key = `${fileToken}:${which}:${isNum(z) ? `z${z}` : index}`;
  if (layerCache.has(key)) return /** @type {LayerMessage} */ (layerCache.get(key));
  // The first layer of a file makes the worker read the whole toolpath (seconds on 34 MB).
  if (layerCounts[which] === 0) els.layerInfo.textContent = `reading the ${which === 'after' ? 'optimized ' : ''}toolpath…`;
  const g = await client.layer(which, index, isNum(z) ? z : null);
  layerCounts[which] = g.count;
  layerCache.set(key, g);
  if (layerCache.size > LAYER_CACHE) layerCache.delete(/** @type {string} */ (layerCache.keys().next().value)); // size > 0: a first key
  return g;
}

/**
 * Fetches and draws the selected layer. Calls coalesce: while one fetch is in
 * flight, moving the slider only records the wish, so a fast drag costs one
 * extra fetch rather than one per step.
 */
async function refreshLayers() {
  if (!loaded) return;
  if (layerLoading) {
    layerWanted = true;
    return;
  }
  layerLoading = true;
  try {
    do {
      layerWanted = false;
      const token = fileToken;
      const index = Number(els.layerSlider.value);
      const before = await getLayer('before', index);
      // The after layer at the before layer's height (its index may differ, and the output's
      // layer count is unknown until its first layer arrives).
      const after = output ? await getLayer('after', before.index, before.z) : null;
      if (token !== fileToken) {
        layerWanted = true;
        continue;
      }
      const count = Math.max(layerCounts.before, output ? layerCounts.after : 0);
      els.layerSlider.max = String(Math.max(0, count - 1));
      if (Number(els.layerSlider.value) > count - 1) els.layerSlider.value = String(Math.max(0, count - 1));
      els.layerNumber.textContent = `${before.index + 1} / ${count}`;
      // A multi-axis file (its layers carry a workpiece-frame path): this view is of the machine
      // axes, which for a turning table are not where the material goes; the 3-D view is.
      const machineAxes = before.xyz?.length ? ' · machine X, Y (the 3-D view draws the part)' : '';
      els.layerInfo.textContent = `${isNum(before.z) ? `z = ${before.z.toFixed(2)} mm · ` : ''}${formatCount(before.kind.length)} segments${after ? ` before, ${formatCount(after.kind.length)} after` : ''}${machineAxes}`;
      els.canvas.dataset.layer = String(before.index);
      els.canvas.dataset.z = isNum(before.z) ? before.z.toFixed(3) : '';
      if (after) els.canvas.dataset.afterZ = isNum(after.z) ? after.z.toFixed(3) : '';
      else delete els.canvas.dataset.afterZ;
      viewer.setLayers(before, after);
      updateLayerTime();
    } while (layerWanted && loaded);
  } catch (err) {
    if (!(err instanceof Cancelled)) els.layerInfo.textContent = `Cannot draw this layer: ${/** @type {Error} */ (err).message}`;
  } finally {
    layerLoading = false;
  }
}

/** A new file: empty viewer, layer from the hash (or 0), view fitted. */
function resetViewer() {
  fileToken++;
  layerCache.clear();
  layerCounts.before = 0;
  layerCounts.after = 0;
  viewer.clear();
  const b = loaded?.report?.bounds;
  viewer.bounds = b && Array.isArray(b.min) && Array.isArray(b.max) ? { minX: b.min[0], minY: b.min[1], maxX: b.max[0], maxY: b.max[1] } : null;
  const wanted = Number(hashState().get('layer'));
  // The slider's max is unknown until the first layer arrives: allow the wish.
  els.layerSlider.max = String(Math.max(Number.isInteger(wanted) ? wanted : 0, loaded?.report?.layers ?? 1));
  els.layerSlider.value = String(Number.isInteger(wanted) && wanted >= 0 ? wanted : 0);
  layerFrom.value = '1';
  layerTo.value = '';
  // A new file: its own 3-D drawing tells whether it has tool vectors.
  toolsAvailable = false;
  showToolsLabel.hidden = true;
  refreshLayers();
  refresh3d(true);
}

// ── URL hash state (never the file) ────────────────────────────────────────

function hashState() {
  return new URLSearchParams(location.hash.replace(/^#/, ''));
}

function writeHash() {
  const p = new URLSearchParams();
  p.set('layer', els.layerSlider.value);
  p.set('color', els.colorBy.value);
  if (els.showTravel.checked) p.set('travel', '1');
  p.set('view', els.viewMode.value);
  for (const form of els.actionForms) {
    for (const input of fieldsOf(form)) {
      if (input.type === 'checkbox') {
        if (input.checked) p.set(`${form.dataset.job}.${input.name}`, '1');
      } else if (input.name && String(input.value).trim() !== '' && !(input.name === 'target' && input.value === 'input')) {
        p.set(`${form.dataset.job}.${input.name}`, String(input.value).trim());
      }
    }
  }
  const hash = `#${p.toString()}`;
  if (location.hash !== hash) history.replaceState(null, '', hash);
}

/** Applies the hash to the controls (on load and when the user edits the URL). */
function readHash() {
  const p = hashState();
  const color = p.get('color');
  if (color && ['feature', 'speed', 'curvature', 'layer-time'].includes(color)) els.colorBy.value = color;
  els.showTravel.checked = p.get('travel') === '1';
  const view = p.get('view');
  if (view && ['before', 'after', 'side', 'overlay'].includes(view)) els.viewMode.value = view;
  for (const form of els.actionForms) {
    for (const input of fieldsOf(form)) {
      if (!input.name) continue;
      const v = p.get(`${form.dataset.job}.${input.name}`);
      if (input.type === 'checkbox') input.checked = v === '1';
      else if (v !== null) input.value = v;
    }
  }
  viewer.colorBy = els.colorBy.value;
  viewer.showTravel = els.showTravel.checked;
  viewer.set('mode', els.viewMode.value);
  const layer = Number(p.get('layer'));
  if (Number.isInteger(layer) && layer >= 0 && String(layer) !== els.layerSlider.value) {
    els.layerSlider.value = String(layer);
    refreshLayers();
  }
}

// ── Rendering ──────────────────────────────────────────────────────────────

/**
 * A new element with attributes (`class` and `text` set className and textContent; null or
 * undefined ones are left out) and children (nodes, or text; null and undefined left out).
 * @template {keyof HTMLElementTagNameMap} K
 * @param {K} tag
 * @param {Record<string, string | null | undefined>} [attrs]
 * @param {...(Node | string | null | undefined)} children
 * @returns {HTMLElementTagNameMap[K]}
 */
function el(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null) continue;
    if (k === 'class') node.className = v;
    else if (k === 'text') node.textContent = v;
    else node.setAttribute(k, v);
  }
  for (const c of children) {
    if (c === null || c === undefined) continue;
    node.append(c instanceof Node ? c : String(c));
  }
  return node;
}

/** @type {(v: unknown) => v is number} */
const isNum = (v) => typeof v === 'number' && Number.isFinite(v);
/** @param {number} digits */
const nf = (digits) => new Intl.NumberFormat('en-US', { maximumFractionDigits: digits, minimumFractionDigits: digits });
const fmt0 = nf(0);
const fmt1 = nf(1);
const fmt2 = nf(2);

/** @param {number} ms */
function formatMs(ms) {
  return ms < 10 ? `${fmt2.format(ms)} ms` : `${fmt0.format(ms)} ms`;
}

/** @param {unknown} s */
function formatDuration(s) {
  if (!isNum(s)) return '—';
  if (s < 60) return `${fmt1.format(s)} s`;
  const total = Math.round(s);
  const h = Math.floor(total / 3600);
  const m = Math.floor((total % 3600) / 60);
  const sec = total % 60;
  return h > 0 ? `${h} h ${m} min ${sec} s` : `${m} min ${sec} s`;
}

/** @param {unknown} mm */
function formatLength(mm) {
  if (!isNum(mm)) return '—';
  if (Math.abs(mm) >= 1000) return `${fmt2.format(mm / 1000)} m`;
  // Small lengths (deviations, chord errors): three significant digits, not "0.0 mm".
  if (mm !== 0 && Math.abs(mm) < 1) return Math.abs(mm) < 1e-4 ? '< 0.0001 mm' : `${Number(mm.toPrecision(3))} mm`;
  return `${fmt1.format(mm)} mm`;
}

/** @param {unknown} n */
function formatCount(n) {
  return isNum(n) ? fmt0.format(n) : '—';
}

/** @param {unknown} n */
function formatBytes(n) {
  if (!isNum(n)) return '—';
  if (n >= 1024 * 1024) return `${fmt2.format(n / (1024 * 1024))} MiB`;
  if (n >= 1024) return `${fmt1.format(n / 1024)} KiB`;
  return `${fmt0.format(n)} B`;
}

/** @param {unknown} v */
function formatScalar(v) {
  if (v === null || v === undefined) return '—';
  if (isNum(v)) return Number.isInteger(v) ? fmt0.format(v) : String(Math.round(v * 1e4) / 1e4);
  if (typeof v === 'boolean') return v ? 'yes' : 'no';
  return String(v);
}

// JSON.stringify that survives Map, BigInt and typed arrays (the API returns spectra as
// Float64Array): the JSON shown and downloaded is the CLI's.
/**
 * @param {unknown} value
 * @param {number} [space]
 */
function toJson(value, space) {
  return JSON.stringify(
    value,
    (_key, v) => {
      if (ArrayBuffer.isView(v)) return Array.from(/** @type {Float64Array} */ (v)); // a typed array
      if (v instanceof Map) return Object.fromEntries(v);
      if (typeof v === 'bigint') return Number.isSafeInteger(Number(v)) ? Number(v) : v.toString();
      return v;
    },
    space,
  );
}

/**
 * The value as plain JSON data (typed arrays as arrays, Maps as objects). Typed as the value:
 * the report types are JSON-shaped already (a job's result is loose anyway: JobResult).
 * @template T
 * @param {T} value
 * @returns {T}
 */
function plain(value) {
  return JSON.parse(toJson(value) ?? 'null');
}

/** @param {unknown} j */
function formatEnergy(j) {
  if (!isNum(j)) return '—';
  if (Math.abs(j) >= 3.6e5) return `${fmt2.format(j / 3.6e6)} kWh`;
  if (Math.abs(j) >= 1e3) return `${fmt1.format(j / 1e3)} kJ`;
  return `${fmt1.format(j)} J`;
}

/** @param {number} x */
function signedPercent(x) {
  const text = fmt1.format(Math.abs(x) * 100);
  // A change that rounds to nothing has no sign ("0.0 %", not "−0.0 %").
  if (Number(text.replaceAll(',', '')) === 0) return '0.0 %';
  return `${x >= 0 ? '+' : '−'}${text} %`;
}

/**
 * @param {Report} r
 * @param {string} name
 * @param {number} ms
 */
function summaryRows(r, name, ms) {
  const file = r.file ?? {};
  const extrusion = r.extrusion ?? {};
  const warnings = Array.isArray(r.warnings) ? r.warnings : [];
  const rows = [
    ['File', name],
    ['Print time', formatDuration(r.time_s)],
    ['Slicer estimate', isNum(file.slicer_time_s) ? `${formatDuration(file.slicer_time_s)} (${signedPercent(r.time_s / file.slicer_time_s - 1)})` : '—'],
    ['Timed as', r.machine ? timedAs(r.machine) : '—'],
    ['Moves', formatCount(r.moves)],
    ['Layers', formatCount(r.layers)],
    ['Distance', formatLength(r.distance_mm)],
    ['Filament', formatLength(r.filament_mm)],
    ['Material', isNum(r.material_g) ? `${fmt1.format(r.material_g)} g` : '—'],
    ['Slicer', file.slicer ?? 'unknown'],
    ['Flavor', file.flavor ?? '—'],
    ['Extrusion mode', extrusion.mode ? `${extrusion.mode}${extrusion.source ? ` (${extrusion.source})` : ''}` : '—'],
    ['Energy', isNum(r.energy?.total_j) ? `${formatEnergy(r.energy.total_j)} (stepper ${formatEnergy(r.energy.thesis_j)}, melting ${formatEnergy(r.energy.fuse_j)}, auxiliary ${formatEnergy(r.energy.aux_j)})` : '—'],
    ['CO₂', isNum(r.energy?.co2_g) ? `${fmt1.format(r.energy.co2_g)} g` : '—'],
    ['Warnings', formatCount(warnings.length)],
    ['Size', `${formatBytes(file.bytes)} · ${formatCount(file.lines)} lines`],
  ];
  const b = r.bounds;
  if (b && Array.isArray(b.min) && Array.isArray(b.max)) {
    const size = b.max.map((v, i) => v - b.min[i]);
    rows.push(['Bounds', `${size.map((v) => fmt1.format(v)).join(' × ')} mm`]);
  }
  rows.push(['Analysis time', formatMs(ms)]);
  return rows;
}

/**
 * What the file was timed as, in words: the printer, its cornering model and why.
 * @param {MachineInfo} m
 */
function timedAs(m) {
  const preset = machines.find((p) => p.name === m.profile);
  const junction = { classic_jerk: 'classic jerk cornering', junction_deviation: 'junction-deviation cornering', klipper: "Klipper's square-corner cornering" }[m.junction_model] ?? String(m.junction_model).replaceAll('_', ' ');
  const settings = machineChoice === 'upload' && printerSettings ? ` with your ${printerSettings.name}` : '';
  return `${preset?.description ?? m.profile}${settings} · ${junction} · chosen because: ${m.reason}`;
}

/**
 * The planner's limits, each with its value, unit and where it came from.
 * @param {Report} r
 */
function renderLimits(r) {
  const box = $('machine-limits');
  const limits = r.machine?.limits ?? {};
  /** @param {Limit} l */
  const source = (l) => (l.source === 'profile' ? `the ${r.machine.profile} preset` : LIMIT_SOURCES[l.source] ?? String(l.source).replaceAll('_', ' '));
  const { arc_rule: arcRule, ...values } = limits;
  const rows = Object.entries(values)
    .filter(([, v]) => v !== null && v !== undefined)
    .map(([k, v]) => {
      const [name, unit] = LIMIT_NAMES[k] ?? [k.replaceAll('_', ' '), ''];
      const list = /** @type {Limit[]} */ (Array.isArray(v) ? v : [v]); // null ones filtered out above
      const value = `${list.map((l) => formatScalar(l?.value)).join(' / ')}${unit ? ` ${unit}` : ''}`;
      const from = [...new Set(list.map(source))].join('; ');
      return el('tr', { 'data-limit': k }, el('th', { scope: 'row', text: name }), el('td', {}, value, el('small', { class: 'explain', text: `from ${from}` })));
    });
  if (arcRule) rows.push(el('tr', { 'data-limit': 'arc_rule' }, el('th', { scope: 'row', text: 'Arcs cut as' }), el('td', {}, ARC_RULES[arcRule] ?? arcRule.replaceAll('_', ' '))));
  /** @type {HTMLElement} */ (box.querySelector('tbody')).replaceChildren(...rows);
  const fromFile = fileLimitCount(r);
  /** @type {HTMLElement} */ (box.querySelector('summary')).textContent = `Printer limits and where each came from (${fromFile ? `${fromFile} set by the file` : 'none set by the file'})`;
  box.hidden = rows.length === 0;
}

/** @param {Report} r */
function renderStats(r) {
  const warnings = Array.isArray(r.warnings) ? r.warnings.length : 0;
  const cards = [
    ['Print time', formatDuration(r.time_s), isNum(r.moves) ? `${formatCount(r.moves)} moves` : ''],
    ['Filament', formatLength(r.filament_mm), isNum(r.material_g) ? `${fmt1.format(r.material_g)} g` : ''],
    ['Layers', formatCount(r.layers), r.bounds?.max ? `${fmt1.format(r.bounds.max[2] - r.bounds.min[2])} mm tall` : ''],
    ['Energy', isNum(r.energy?.total_j) ? formatEnergy(r.energy.total_j) : '—', isNum(r.energy?.co2_g) ? `${fmt1.format(r.energy.co2_g)} g CO₂` : ''],
    ['Warnings', formatCount(warnings), warnings ? 'see below' : 'clean file'],
  ];
  els.stats.replaceChildren(
    ...cards.map(([label, value, sub]) =>
      el('div', { class: 'stat' }, el('span', { class: 'label', text: label }), el('span', { class: 'value', text: value }), el('span', { class: 'sub', text: sub })),
    ),
  );
}

/** @type {Record<string, string>} */
const SUMMARY_EXPLAIN = {
  'Print time': METRICS.time_s[2],
  'Slicer estimate': "The slicer's own estimate written in the file, and how far ours is from it.",
  'Timed as': 'The printer whose limits the time, energy and vibration are computed for (change it above).',
  Moves: 'G-code moves: printing, travel and retraction.',
  Distance: METRICS.distance_mm[2],
  Filament: METRICS.filament_mm[2],
  Material: METRICS.material_g[2],
  'Extrusion mode': 'Whether E values are absolute (M82) or relative (M83), and how we know.',
  Energy: METRICS.total_j[2],
  'CO₂': METRICS.co2_g[2],
  Bounds: 'Size of the printed part: width × depth × height.',
};

/**
 * @param {Report} r
 * @param {string} name
 * @param {number} ms
 */
function renderSummary(r, name, ms) {
  const tbody = els.summary.tBodies[0];
  tbody.replaceChildren(
    ...summaryRows(r, name, ms).map(([k, v]) =>
      el(
        'tr',
        { 'data-key': k.toLowerCase().replace(/\s+/g, '-') },
        el('th', { scope: 'row' }, k, SUMMARY_EXPLAIN[k] ? el('small', { class: 'explain', text: SUMMARY_EXPLAIN[k] }) : null),
        el('td', { text: v }),
      ),
    ),
  );
}

/** @param {Report} r */
function renderFeatures(r) {
  const features = Array.isArray(r.features) ? r.features : [];
  const tbody = els.features.tBodies[0];
  const totalTime = features.reduce((a, f) => a + (isNum(f.time_s) ? f.time_s : 0), 0);
  tbody.replaceChildren(
    ...features.map((f) => {
      const share = totalTime > 0 && isNum(f.time_s) ? f.time_s / totalTime : 0;
      const bar = el('span', { class: 'bar' });
      bar.style.width = `${(share * 100).toFixed(1)}%`;
      return el(
        'tr',
        {},
        el('td', { text: f.name ?? '—' }),
        el('td', { class: 'num', text: formatDuration(f.time_s) }),
        el('td', { class: 'num share' }, el('span', { class: 'bar-track' }, bar), `${fmt1.format(share * 100)} %`),
        el('td', { class: 'num', text: formatLength(f.distance_mm) }),
        el('td', { class: 'num', text: formatLength(f.filament_mm) }),
      );
    }),
  );
  els.features.hidden = features.length === 0;
  els.featuresEmpty.hidden = features.length !== 0;
}

/** @param {Report} r */
function renderWarnings(r) {
  const warnings = Array.isArray(r.warnings) ? r.warnings : [];
  els.warningsCount.textContent = formatCount(warnings.length);
  const shown = warnings.slice(0, MAX_WARNINGS_SHOWN).map((w) =>
    el(
      'li',
      {},
      // Line 0 marks a finding about the whole file rather than one line.
      el('span', { class: 'line-no', text: isNum(w?.line) && w.line > 0 ? `line ${w.line}` : 'file' }),
      el('span', { class: 'msg', text: w?.message ?? formatScalar(w) }),
    ),
  );
  if (warnings.length > MAX_WARNINGS_SHOWN) {
    shown.push(el('li', { class: 'more', text: `… and ${formatCount(warnings.length - MAX_WARNINGS_SHOWN)} more (see the report JSON)` }));
  }
  els.warnings.replaceChildren(...shown);
  els.warningsEmpty.hidden = warnings.length !== 0;
}

/**
 * A scalar, formatted by the unit its key names (`_mm`, `_s`, `_g`, …).
 * @param {string} key
 * @param {unknown} v
 */
function formatByKey(key, v) {
  if (!isNum(v)) return formatScalar(v);
  // Compound units first: `_mm_s` is a speed, not a duration.
  /** @type {[RegExp, string][]} */
  const units = [
    [/_kg_per_kwh$/, 'kg/kWh'], [/_kg_per_kg$/, 'kg/kg'],
    [/_mm_s3$/, 'mm/s³'], [/_mm_s2$/, 'mm/s²'], [/_mm_s$/, 'mm/s'], [/_m_s2$/, 'm/s²'], [/_per_mm_deg$/, '°/mm'], [/_per_mm$/, '/mm'],
    [/_g_cm3$/, 'g/cm³'], [/_mm3$/, 'mm³'], [/_mm2$/, 'mm²'], [/_kwh$/i, 'kWh'], [/_wh$/i, 'Wh'], [/_w$/i, 'W'], [/_c$/i, '°C'],
    [/_(pct|percent)$/, '%'], [/_hz$/, 'Hz'], [/_deg$/, '°'],
  ];
  for (const [re, unit] of units) {
    if (!re.test(key)) continue;
    const n = Math.abs(v) >= 100 || Number.isInteger(v) ? formatScalar(v) : String(Number(v.toPrecision(3)));
    return `${n}${unit === '°' ? '' : ' '}${unit}`;
  }
  if (/_mm$/.test(key)) return formatLength(v);
  if (/_ms$/.test(key)) return formatMs(v);
  if (/_s$/.test(key)) return formatDuration(v);
  if (/_g$/.test(key)) return `${fmt2.format(v)} g`;
  if (/_j$/i.test(key)) return formatEnergy(v);
  return formatScalar(v);
}

/**
 * Generic rendering of anything we don't have a dedicated view for yet.
 * @param {unknown} v
 * @param {number} [depth]
 * @param {string} [key]
 * @returns {Node}
 */
function renderValue(v, depth = 0, key = '') {
  if (v === null || typeof v !== 'object') return document.createTextNode(formatByKey(key, v));
  if (Array.isArray(v)) {
    if (v.every((x) => x === null || typeof x !== 'object')) {
      return document.createTextNode(v.length > 12 ? `[${v.slice(0, 12).map(formatScalar).join(', ')}, … ${v.length} items]` : `[${v.map(formatScalar).join(', ')}]`);
    }
    return document.createTextNode(key === 'layer_list' ? `${v.length} layers (see the per-layer charts)` : `${v.length} items (in the report JSON)`);
  }
  const entries = Object.entries(v);
  if (entries.length === 0) return el('span', { class: 'muted', text: 'empty' });
  if (depth >= 2) return el('code', { text: toJson(v).slice(0, 200) });
  return el(
    'table',
    { class: 'kv nested' },
    el(
      'tbody',
      {},
      ...entries.map(([k, x]) => {
        // Inside "co2", grams are CO₂ grams: "CO₂ of the energy", not "Energy".
        const name = key === 'co2' && /_g$/.test(k) ? `CO₂ of the ${k.replace(/_g$/, '').replaceAll('_', ' ')}` : metricInfo(k)[0];
        return el('tr', {}, el('th', { scope: 'row', text: name, title: k }), el('td', {}, renderValue(x, depth + 1, k)));
      }),
    ),
  );
}

/** @param {Report} r */
function renderExtra(r) {
  const extra = Object.entries(r).filter(([k]) => !KNOWN_FIELDS.has(k));
  els.extra.replaceChildren(
    ...extra.map(([k, v]) => el('div', { class: 'extra-item', 'data-field': k }, el('h3', { text: metricInfo(k)[0], title: k }), renderValue(v, 0, k))),
  );
  els.extraPanel.hidden = extra.length === 0;
}

/**
 * @param {Report} rawReport
 * @param {string} name
 * @param {number} ms
 */
function showReport(rawReport, name, ms) {
  const report = plain(rawReport);
  renderStats(report);
  renderSummary(report, name, ms);
  renderLimits(report);
  renderFeatures(report);
  renderWarnings(report);
  renderExtra(report);
  renderLayerCharts(report);
  showJson(report, `${baseName(name)}.quietpath.json`);
  els.elapsed.textContent = `analyzed in ${formatMs(ms)}`;
  els.elapsed.dataset.ms = String(ms);
  els.results.hidden = false;
  hideError();
}

/**
 * Shows `value` as the latest report JSON (and what "Download report JSON" saves).
 * @param {unknown} value
 * @param {string} filename
 */
function showJson(value, filename) {
  lastJson = { value, filename };
  els.reportJson.textContent = toJson(value, 2);
}

/**
 * Shows a failure: its message, and where it is in the file when known (line, column, the
 * line's text with a caret).
 * @param {{ message?: string, line?: number | null, column?: number | null, excerpt?: string | null }} err
 * @param {{ keepResults?: boolean }} [opts]
 */
function showError({ message, line, column, excerpt }, { keepResults = false } = {}) {
  // After a failed load, whatever report is shown belongs to another file.
  if (!keepResults) els.results.hidden = true;
  const parts = [];
  const where = isNum(line) ? `Line ${line}${isNum(column) ? `, column ${column}` : ''}` : null;
  // The analyzer's message usually starts with its own "line N, column M:"; don't say it twice.
  const text = where ? String(message ?? '').replace(/^\s*(?:error:\s*)?line \d+(?:,?\s*col(?:umn)? \d+)?\s*:?\s*/i, '') : message;
  parts.push(el('strong', { text: where ? `${where}: ` : 'Error: ' }), el('span', { class: 'msg', text: text || message || 'unknown error' }));
  if (typeof excerpt === 'string' && excerpt.length > 0) {
    const gutter = `${line} │ `;
    const pre = el('pre', { class: 'excerpt' }, el('span', { class: 'gutter', text: gutter }), excerpt);
    if (isNum(column) && column >= 1 && column <= excerpt.length + 1) {
      const pad = excerpt.slice(0, column - 1).replace(/[^\t]/g, ' ');
      pre.append('\n', el('span', { class: 'gutter', text: ' '.repeat(gutter.length - 2) + '│ ' }), pad, el('span', { class: 'caret', text: '^' }));
    }
    parts.push(pre);
  }
  els.error.replaceChildren(...parts);
  if (isNum(line)) els.error.dataset.line = String(line);
  else delete els.error.dataset.line;
  els.error.hidden = false;
}

function hideError() {
  els.error.hidden = true;
  els.error.replaceChildren();
  delete els.error.dataset.line;
}

/** @param {string | undefined} name */
function baseName(name) {
  return String(name ?? '').replace(/\.[^.]*$/, '') || 'quietpath';
}

/**
 * @param {string} key
 * @param {Blob} blob
 * @param {string} filename
 */
function saveBlob(key, blob, filename) {
  if (downloadUrls[key]) URL.revokeObjectURL(downloadUrls[key]);
  downloadUrls[key] = URL.createObjectURL(blob);
  const a = el('a', { href: downloadUrls[key], download: filename });
  document.body.append(a);
  a.click();
  a.remove();
}

function downloadReport() {
  if (!lastJson) return;
  saveBlob('json', new Blob([toJson(lastJson.value, 2) + '\n'], { type: 'application/json' }), lastJson.filename);
}

function downloadGcode() {
  if (!output || !loaded) return;
  saveBlob('gcode', new Blob([output.bytes], { type: 'text/plain' }), `${baseName(loaded.name)}.${output.job}.gcode`);
}

// ── Wiring ─────────────────────────────────────────────────────────────────

els.file.addEventListener('change', () => {
  const file = els.file.files?.[0];
  if (file) run(fileSource(file));
  els.file.value = ''; // so picking the same file again re-runs it
});

els.demo.addEventListener('click', () => run(demoSource()));
els.cancel.addEventListener('click', () => cancel());
els.download.addEventListener('click', downloadReport);
els.downloadGcode.addEventListener('click', downloadGcode);
function showPrinterSettingsName() {
  const nameEl = $('printer-settings-name');
  nameEl.textContent = printerSettings
    ? `${printerSettings.name} (${printerSettings.key === 'klipper_config' ? 'Klipper printer.cfg' : 'Marlin M503 settings'})`
    : 'none: limits from the file and the preset';
  $('printer-settings-clear').hidden = !printerSettings;
}

/** @param {string} choice */
function setMachine(choice) {
  machineChoice = choice;
  store.set(STORE_MACHINE, choice || null);
  renderMachinePicker();
}

/** @param {File | null} file */
async function setPrinterSettings(file) {
  if (file) {
    const text = await file.text();
    const key = /^\s*\[printer\]/m.test(text) ? 'klipper_config' : 'machine_gcode';
    printerSettings = { name: file.name, text, key };
    store.set(STORE_SETTINGS, text.length < 1_000_000 ? JSON.stringify(printerSettings) : null);
    setMachine('upload');
  } else {
    printerSettings = null;
    store.set(STORE_SETTINGS, null);
    setMachine(machineChoice === 'upload' ? '' : machineChoice);
  }
  showPrinterSettingsName();
  if (lastSource && lastSource.name && !current) run(lastSource);
}

$('machine').addEventListener('change', (e) => {
  setMachine(/** @type {HTMLSelectElement} */ (e.target).value);
  if (lastSource && lastSource.name && !current) run(lastSource);
});

$('printer-settings').addEventListener('change', (e) => {
  e.stopPropagation();
  const input = /** @type {HTMLInputElement} */ (e.target);
  setPrinterSettings(input.files?.[0] ?? null);
  input.value = '';
});
$('printer-settings-clear').addEventListener('click', () => setPrinterSettings(null));
els.optionsForm.addEventListener('submit', (e) => e.preventDefault());
els.optionsForm.addEventListener('change', () => {
  if (lastSource && lastSource.name && !current) run(lastSource);
});

for (const form of els.actionForms) {
  form.addEventListener('submit', (e) => {
    e.preventDefault();
    runJob(/** @type {string} */ (form.dataset.job), form); // every action form has data-job
  });
  form.addEventListener('change', () => {
    updateActions();
    writeHash();
  });
}

els.layerSlider.addEventListener('input', () => {
  els.layerNumber.textContent = `${Number(els.layerSlider.value) + 1} / ${Number(els.layerSlider.max) + 1}`;
  refreshLayers();
  writeHash();
});
els.colorBy.addEventListener('change', () => {
  viewer.set('colorBy', els.colorBy.value);
  refresh3d();
  writeHash();
});
els.showTravel.addEventListener('change', () => {
  viewer.set('showTravel', els.showTravel.checked);
  refresh3d();
  writeHash();
});
showTools.addEventListener('change', () => refresh3d());
els.viewMode.addEventListener('change', () => {
  viewer.set('mode', els.viewMode.value);
  refresh3d();
  writeHash();
});
els.fit.addEventListener('click', () => viewer.fit());
window.addEventListener('hashchange', readHash);

let dragDepth = 0;
/** @param {DragEvent} e */
const hasFiles = (e) => Array.from(e.dataTransfer?.types ?? []).includes('Files');
window.addEventListener('dragenter', (e) => {
  if (!hasFiles(e)) return;
  e.preventDefault();
  dragDepth++;
  document.body.classList.add('dragging');
});
window.addEventListener('dragover', (e) => {
  if (!hasFiles(e)) return;
  e.preventDefault();
  /** @type {DataTransfer} */ (e.dataTransfer).dropEffect = 'copy'; // hasFiles: there is one
});
window.addEventListener('dragleave', () => {
  dragDepth = Math.max(0, dragDepth - 1);
  if (dragDepth === 0) document.body.classList.remove('dragging');
});
window.addEventListener('drop', (e) => {
  e.preventDefault();
  dragDepth = 0;
  document.body.classList.remove('dragging');
  const file = e.dataTransfer?.files?.[0];
  if (file) run(fileSource(file));
});

// Restore the shared view, start the worker right away (the wasm compiles
// while the demo downloads), then analyze the bundled demo.
readHash();
showPrinterSettingsName();
renderMachinePicker();
resetOptimized();
updateActions();
client.warm();
run(demoSource());

// Offline once loaded (sw.js: network first, cache as the fallback). Not
// essential, so a browser or context without service workers is fine.
if ('serviceWorker' in navigator && /^https?:$/.test(location.protocol)) {
  navigator.serviceWorker.register('./sw.js').catch(() => {});
}
