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

const $ = (id) => document.getElementById(id);

const els = {
  status: $('status'),
  filename: $('filename'),
  elapsed: $('elapsed'),
  progress: $('progress'),
  cancel: $('cancel'),
  error: $('error'),
  file: $('file'),
  demo: $('demo'),
  optionsForm: $('options-form'),
  results: $('results'),
  stats: $('stats'),
  summary: $('summary'),
  features: $('features'),
  featuresEmpty: $('features-empty'),
  extraPanel: $('extra-panel'),
  extra: $('extra'),
  warnings: $('warnings'),
  warningsCount: $('warnings-count'),
  warningsEmpty: $('warnings-empty'),
  reportJson: $('report-json'),
  download: $('download'),
  version: $('version'),
  dropOverlay: $('drop-overlay'),
  // viewer
  canvas: $('viewer'),
  legend: $('legend'),
  layerSlider: $('layer-slider'),
  layerNumber: $('layer-number'),
  layerInfo: $('layer-info'),
  colorBy: $('color-by'),
  showTravel: $('show-travel'),
  viewMode: $('view-mode'),
  fit: $('fit'),
  // jobs
  actionForms: [...document.querySelectorAll('form.action')],
  resultPanel: $('result-panel'),
  resultJob: $('result-job'),
  resultLine: $('result-line'),
  compareTable: $('compare-table'),
  paperTables: $('paper-tables'),
  downloadGcode: $('download-gcode'),
  chartInfill: $('chart-infill'),
  chartPsd: $('chart-psd'),
  chartLayers: $('chart-layers'),
  chartOrientation: $('chart-orientation'),
};

const DEMO_URL = 'demo/demo.gcode';
const MAX_WARNINGS_SHOWN = 500;
const JOB_NAMES = { optimize: 'optimize', vtg: 'VTG', infill: 'infill search', smooth: 'orientation smoothing', vibration: 'vibration analysis' };
const LAYER_CACHE = 32;

// Fields rendered by dedicated views; everything else goes to "More".
const KNOWN_FIELDS = new Set([
  'time_s', 'moves', 'layers', 'distance_mm', 'filament_mm', 'material_g',
  'warnings', 'file', 'extrusion', 'features', 'bounds',
]);

// ── State ──────────────────────────────────────────────────────────────────

let current = null; // the run in flight: { kind: 'load'|'job', name, startedAt }
let lastSource = null; // { name, load: () => Promise<ArrayBuffer> }
let loaded = null; // the analyzed file: { name, report }
let output = null; // the latest optimized G-code: { job, bytes: ArrayBuffer }
let lastJson = null; // what report-json shows: { value, filename }
let capabilities = new Set();
let fileToken = 0; // bumps with every new file or output: stale layer data is dropped
const vibrationRuns = {}; // target → vibration result, for the before/after charts
const downloadUrls = {};

const client = new JobClient('./worker.js', {
  onHello(version, caps) {
    els.version.textContent = version ? `v${version}` : '';
    capabilities = new Set(caps);
    document.body.dataset.capabilities = caps.join(' '); // for tests and curious users
    updateActions();
  },
  onCrash(detail, wasLoaded, hadPending) {
    // A crash while a request was pending is reported by that request.
    if (hadPending) return;
    showError({ message: wasLoaded ? `The analyzer crashed: ${detail}` : `The analyzer could not be started: ${detail}` }, { keepResults: true });
    setStatus('error');
  },
});

function setStatus(text) {
  els.status.textContent = text;
  els.status.dataset.state = text;
}

function startRun(kind, name) {
  current = { kind, name, startedAt: performance.now() };
  hideError();
  els.elapsed.textContent = '';
  delete els.elapsed.dataset.ms;
  els.progress.value = 0;
  els.cancel.disabled = false;
  document.body.classList.add('busy');
  updateActions();
}

function finishRun(status) {
  if (current && status !== 'ready') els.elapsed.textContent = `${formatMs(performance.now() - current.startedAt)} total`;
  current = null;
  els.cancel.disabled = true;
  document.body.classList.remove('busy');
  setStatus(status);
  updateActions();
}

const onProgress = (fraction) => {
  els.progress.value = Math.max(els.progress.value, Math.min(1, fraction));
};

// A failed request: cancelled (quietly), superseded (ignored) or an error.
function failRun(err, { keepResults }) {
  if (err instanceof Cancelled) {
    if (err.reason === 'superseded') return;
    finishRun('cancelled');
    els.elapsed.textContent = '';
    return;
  }
  showError(err, { keepResults });
  finishRun('error');
}

// ── Loading a file ─────────────────────────────────────────────────────────

// The printer's own settings, uploaded: { name, text, key } with key `klipper_config` (a
// printer.cfg, recognised by its [printer] section) or `machine_gcode` (Marlin's M503 text).
let printerSettings = null;

function readOptions() {
  const form = new FormData(els.optionsForm);
  const options = {};
  if (form.get('strict')) options.strict = true;
  if (printerSettings) options[printerSettings.key] = printerSettings.text;
  for (const key of ['filament_diameter_mm', 'density_g_cm3']) {
    const raw = String(form.get(key) ?? '').trim();
    if (raw === '') continue;
    const v = Number(raw);
    if (Number.isFinite(v) && v > 0) options[key] = v;
  }
  return options;
}

async function run(source) {
  lastSource = source;
  if (current) client.cancel('superseded');
  startRun('load', source.name);
  const run = current;
  run.posted = false;
  setStatus('reading');
  els.filename.textContent = source.name;

  let bytes;
  try {
    bytes = await source.load();
  } catch (err) {
    if (current !== run) return;
    showError({ message: `Could not read ${source.name}: ${err?.message ?? err}` });
    finishRun('error');
    return;
  }
  if (current !== run) return; // cancelled while reading
  run.posted = true;
  setStatus('analyzing');
  // The old file is gone from the worker from here on.
  loaded = null;
  resetOptimized();
  try {
    const msg = await client.load(bytes, source.name, readOptions(), onProgress);
    if (current !== run) return;
    loaded = { name: source.name, report: msg.report };
    showReport(msg.report, source.name, msg.ms);
    els.elapsed.dataset.totalMs = String(msg.totalMs);
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

function fileSource(file) {
  return { name: file.name, load: () => file.arrayBuffer() };
}

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

/** Options of an action form: empty fields are left out (the function's defaults). */
function jobOptions(form) {
  const options = {};
  for (const input of form.elements) {
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
  // OptimizeOptions (types.d.ts): VTG's tolerance inside vtg_options, the infill search as
  // an options object (its defaults).
  if (form.dataset.job === 'optimize') {
    if (isNum(options.tolerance_mm)) options.vtg_options = { tolerance_mm: options.tolerance_mm };
    delete options.tolerance_mm;
    if (options.infill === true) options.infill = {};
  }
  // SmoothOptions.window is { points } or { millimetres } (types.d.ts).
  if (form.dataset.job === 'smooth') {
    if (isNum(options.window_mm)) options.window = { millimetres: options.window_mm };
    else if (isNum(options.window)) options.window = { points: Math.round(options.window) };
    delete options.window_mm;
  }
  return options;
}

function updateActions() {
  const busy = !!current;
  for (const form of els.actionForms) {
    const job = form.dataset.job;
    const button = form.querySelector('button[type="submit"]');
    const note = form.querySelector('.availability');
    button.dataset.label ??= button.textContent;
    const known = capabilities.size > 0;
    const available = capabilities.has(job);
    const needsOutput = job === 'vibration' && form.elements.target.value === 'output' && !output;
    button.disabled = !available || !loaded || busy || needsOutput;
    button.textContent = known && !available ? 'Not available in this build' : button.dataset.label;
    note.textContent = !known ? '' : !available ? `${JOB_NAMES[job]} is not available in this build of the package.` : needsOutput ? 'Run VTG, infill or smoothing first.' : '';
    if (job === 'vibration') form.elements.target.querySelector('option[value="output"]').disabled = !output;
  }
  els.viewMode.disabled = !output;
}

async function runJob(job, form) {
  if (!loaded || current) return;
  const target = job === 'vibration' ? form.elements.target.value : 'input';
  const options = jobOptions(form);
  startRun('job', loaded.name);
  const run = current;
  run.posted = true;
  setStatus(`running ${job}`);
  try {
    const msg = await client.job(job, options, target, onProgress);
    if (current !== run) return;
    showJobResult(job, plain(msg.result), msg.output, target);
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

function showJobResult(job, result, outBytes, target) {
  showJson(result, `${baseName(loaded.name)}.${job}${target === 'output' ? '.output' : ''}.json`);
  els.resultPanel.hidden = false;
  els.resultJob.textContent = `· ${JOB_NAMES[job]}${target === 'output' ? ' of the optimized output' : ''}`;
  els.resultLine.textContent = resultLine(job, result);
  // An infill search that kept the original hands back the input: nothing better to download.
  const keptOriginal = job === 'infill' && result.best?.pattern === 'original';
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
  }
  if (job === 'vibration') {
    vibrationRuns[target] = result;
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

function resultLine(job, r) {
  const n = (v, d = 3) => (isNum(v) ? String(Math.round(v * 10 ** d) / 10 ** d) : '—');
  const pct = (a, b) => (isNum(a) && isNum(b) && b !== 0 ? signedPercent(a / b - 1) : '—');
  switch (job) {
    case 'vtg':
      return `Tolerance ${n(r.tolerance_mm)} mm, largest deviation from the original path ${n(r.max_deviation_mm, 4)} mm; energy ${pct(r.after?.energy?.total_j, r.before?.energy?.total_j)}, time ${pct(r.after?.time_s, r.before?.time_s)}${isNum(r.paths?.arcs_written) && r.paths.arcs_written > 0 ? `; ${r.paths.arcs_written} arcs` : ''}.`;
    case 'infill': {
      const b = r.best ?? {};
      if (b.pattern === 'original') return `No candidate beats your file: it is kept as it was (${r.candidates?.length ?? '—'} candidates). ${b.message ?? ''}`;
      return `Best: ${b.pattern ?? '—'} at ${n(b.angle_deg, 1)}°${isNum(b.rotation_deg) ? ` (rotation ${n(b.rotation_deg, 1)}°)` : ''} of ${Array.isArray(r.candidates) ? r.candidates.length : '—'} candidates; energy ${pct(r.after?.energy?.total_j, r.before?.energy?.total_j)}.`;
    }
    case 'optimize':
      return (r.stages ?? []).map((s) => `${s.stage}: ${s.applied ? '' : 'not applied, '}${s.message}.`).join(' ');
    case 'smooth':
      return `${formatCount(r.points)} points, ${formatCount(r.corrected)} corrected; the smoothed orientation stays within ${n(r.max_angle_to_original_deg, 2)}° of the original.`;
    case 'vibration': {
      const f = Array.isArray(r.natural_frequencies_hz) ? r.natural_frequencies_hz.map((v) => `${n(v, 1)} Hz`).join(', ') : '—';
      return `Natural frequencies ${f}; deviation max ${n(r.deviation_mm?.max, 4)} mm, mean ${n(r.deviation_mm?.mean, 4)} mm.`;
    }
    default:
      return '';
  }
}

// Rows of the before/after table, in the order of the VTG paper's Tables 1 and 2.
const REPORT_METRICS = [
  ['Print time', (r) => r.time_s, formatDuration],
  ['Energy', (r) => r.energy?.total_j, formatEnergy],
  ['Stepper energy', (r) => r.energy?.thesis_j, formatEnergy],
  ['CO₂', (r) => r.energy?.co2_g, (v) => `${fmt2.format(v)} g`],
  ['Material', (r) => r.material_g, (v) => `${fmt2.format(v)} g`],
  ['Path length', (r) => r.toolpath?.l_total_mm ?? r.distance_mm, formatLength],
  ['Turning points', (r) => r.toolpath?.n_turning, formatCount],
  ['Mean turning angle', (r) => r.toolpath?.mean_turn_deg, (v) => `${fmt1.format(v)}°`],
  ['Mean chord error', (r) => r.toolpath?.mean_chord_error_mm, (v) => `${v.toFixed(4)} mm`],
];

function compareRows(result, job) {
  const { before, after } = result;
  if (!before || !after) return [];
  const isReport = (r) => isNum(r.time_s) || isNum(r.energy?.total_j);
  const rows = [];
  if (isReport(before) && isReport(after)) {
    for (const [name, get, format] of REPORT_METRICS) {
      const b = get(before);
      const a = get(after);
      if (isNum(b) || isNum(a)) rows.push({ name, before: b, after: a, format });
    }
  } else {
    // Metrics objects (smoothing): every numeric field, formatted by its unit.
    const keys = [...new Set([...Object.keys(before), ...Object.keys(after)])];
    for (const k of keys) {
      if (isNum(before[k]) || isNum(after[k])) rows.push({ name: k.replaceAll('_', ' '), before: before[k], after: after[k], format: (v) => formatByKey(k, v) });
    }
  }
  if (isNum(result.planned_time_before_s) && isNum(result.planned_time_after_s)) {
    rows.unshift({ name: 'Print time (planned)', before: result.planned_time_before_s, after: result.planned_time_after_s, format: formatDuration });
  }
  if (isNum(result.max_tip_deviation_mm)) {
    rows.push({ name: 'Tool-tip deviation (max)', before: 0, after: result.max_tip_deviation_mm, format: (v) => `${v.toFixed(4)} mm`, noChange: true });
  }
  if (job === 'vtg' && isNum(result.max_deviation_mm)) {
    rows.push({ name: 'Deviation (max)', before: 0, after: result.max_deviation_mm, format: (v) => `${v.toFixed(4)} mm`, noChange: true });
  }
  return rows;
}

function vibrationCompare() {
  const b = vibrationRuns.input;
  const a = vibrationRuns.output;
  const meanOf = (r, key) => {
    const v = Array.isArray(r?.layers) ? r.layers.map((l) => l[key]).filter(isNum) : [];
    return v.length ? v.reduce((x, y) => x + y, 0) / v.length : null;
  };
  const mean = (r) => meanOf(r, 'amplitude');
  const peak = (r) => {
    const p = r?.psd?.peaks?.[0];
    return p ? p.hz : null;
  };
  const mm = (v) => `${v.toFixed(4)} mm`;
  return [
    { name: 'Deviation (max)', before: b?.deviation_mm?.max, after: a?.deviation_mm?.max, format: mm },
    { name: 'Deviation (mean)', before: b?.deviation_mm?.mean, after: a?.deviation_mm?.mean, format: mm },
    { name: 'Mean layer amplitude', before: mean(b), after: mean(a), format: mm },
    { name: 'Mean layer acceleration RMS', before: meanOf(b, 'acceleration_rms'), after: meanOf(a, 'acceleration_rms'), format: (v) => `${fmt2.format(v)} m/s²` },
    { name: 'Strongest PSD peak', before: peak(b), after: peak(a), format: (v) => `${fmt1.format(v)} Hz`, noChange: true },
  ].filter((r) => isNum(r.before) || isNum(r.after));
}

function renderCompare(rows) {
  const cell = (v, format) => el('td', { class: 'num', text: isNum(v) ? format(v) : '—' });
  els.compareTable.tBodies[0].replaceChildren(
    ...rows.map((r) => {
      const change = !r.noChange && isNum(r.before) && isNum(r.after) && r.before !== 0 ? signedPercent(r.after / r.before - 1) : '—';
      const tr = el('tr', {}, el('th', { scope: 'row', text: r.name }), cell(r.before, r.format), cell(r.after, r.format), el('td', { class: 'num', text: change }));
      if (change.startsWith('−')) tr.classList.add('better');
      return tr;
    }),
  );
}

/** Rows of a paper table in whatever shape the result gives it. */
function tableRows(t) {
  if (Array.isArray(t)) return t.map((r) => (r && typeof r === 'object' ? r : { value: r }));
  if (t && typeof t === 'object') {
    return Object.entries(t).map(([k, v]) => (v && typeof v === 'object' && !Array.isArray(v) ? { metric: k, ...v } : { metric: k, value: v }));
  }
  return [];
}

function renderPaperTables(result) {
  const tables = Object.keys(result).filter((k) => /^table\d+$/.test(k));
  els.paperTables.replaceChildren(
    ...tables.map((k) => {
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

function renderCharts(job, r) {
  if (job === 'infill' && Array.isArray(r.candidates) && r.candidates.length) {
    // Best rotation for each (pattern, angle): one line per pattern.
    const byPattern = new Map();
    for (const c of r.candidates) {
      if (!isNum(c.angle_deg) || !isNum(c.total_j)) continue;
      const m = byPattern.get(c.pattern) ?? new Map();
      if (!m.has(c.angle_deg) || c.total_j < m.get(c.angle_deg)) m.set(c.angle_deg, c.total_j);
      byPattern.set(c.pattern, m);
    }
    const list = [...byPattern].map(([pattern, m]) => {
      const x = [...m.keys()].sort((a, b) => a - b);
      return { label: String(pattern), x, y: x.map((a) => m.get(a)) };
    });
    if (list.length) {
      const u = unionSeries(list);
      lineChart(els.chartInfill, { x: u.x, xLabel: 'infill angle, °', yLabel: 'energy, J', points: true, series: list.map((s, i) => ({ label: s.label, values: u.values[i] })) });
    }
  }
  if (job === 'vibration') {
    const runs = ['input', 'output'].filter((t) => vibrationRuns[t]?.psd?.freqs?.length);
    if (runs.length) {
      const list = runs.map((t) => ({ label: t === 'input' ? 'before' : 'after', x: vibrationRuns[t].psd.freqs, y: vibrationRuns[t].psd.power }));
      const a = alignSeries(list);
      lineChart(els.chartPsd, { x: a.x, xLabel: 'frequency, Hz', yLabel: 'power', logY: true, points: false, series: list.map((s, i) => ({ label: s.label, values: a.values[i] })) });
    }
    const layerRuns = ['input', 'output'].filter((t) => Array.isArray(vibrationRuns[t]?.layers) && vibrationRuns[t].layers.length);
    if (layerRuns.length) {
      const list = layerRuns.map((t) => ({ label: t === 'input' ? 'before' : 'after', x: vibrationRuns[t].layers.map((l, i) => (isNum(l.layer) ? l.layer : i)), y: vibrationRuns[t].layers.map((l) => l.amplitude) }));
      const u = unionSeries(list);
      lineChart(els.chartLayers, { x: u.x, xLabel: 'layer', yLabel: 'amplitude', series: list.map((s, i) => ({ label: s.label, values: u.values[i] })) });
    }
  }
  if (job === 'smooth' && r.series) {
    // Two shapes: { axes, point, first_before, first_after, second_before, second_after }
    // (the crate's Series, thinned to ≤ 2000 points) or { b_before, b_after, c_before, c_after }.
    const s = r.series;
    const [ax1, ax2] = Array.isArray(s.axes) && s.axes.length >= 2 ? s.axes : ['B', 'C'];
    const cols = s.first_before ? [s.first_before, s.first_after, s.second_before, s.second_after] : [s.b_before, s.b_after, s.c_before, s.c_after];
    const n = Math.max(...cols.map((a) => (Array.isArray(a) ? a.length : 0)));
    if (n > 0) {
      const x = Array.isArray(s.point) && s.point.length === n ? s.point : Array.from({ length: n }, (_, i) => i);
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

// ── Layer viewer ───────────────────────────────────────────────────────────

const hoverInfo = $('hover-info');
const viewer = new LayerViewer(els.canvas, els.legend, {
  onHover(hit) {
    hoverInfo.textContent = hit
      ? `${hit.which ? `${hit.which}: ` : ''}${hit.kind} · ${fmt1.format(hit.speed)} mm/s · curvature ${hit.curvature.toFixed(3)} /mm · at ${fmt1.format(hit.x)}, ${fmt1.format(hit.y)} mm`
      : '';
  },
});
const layerCache = new Map(); // `${token}:${which}:${index}` → geometry
const layerCounts = { before: 0, after: 0 };
let layerLoading = false;
let layerWanted = false;

async function getLayer(which, index) {
  const key = `${fileToken}:${which}:${index}`;
  if (layerCache.has(key)) return layerCache.get(key);
  // The first layer of a file makes the worker read the whole toolpath (seconds on 34 MB).
  if (layerCounts[which] === 0) els.layerInfo.textContent = `reading the ${which === 'after' ? 'optimized ' : ''}toolpath…`;
  const g = await client.layer(which, index);
  layerCounts[which] = g.count;
  layerCache.set(key, g);
  if (layerCache.size > LAYER_CACHE) layerCache.delete(layerCache.keys().next().value);
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
      const after = output ? await getLayer('after', Math.min(index, Math.max(0, (layerCounts.after || 1) - 1))) : null;
      if (token !== fileToken) {
        layerWanted = true;
        continue;
      }
      const count = Math.max(layerCounts.before, output ? layerCounts.after : 0);
      els.layerSlider.max = String(Math.max(0, count - 1));
      if (Number(els.layerSlider.value) > count - 1) els.layerSlider.value = String(Math.max(0, count - 1));
      els.layerNumber.textContent = `${before.index + 1} / ${count}`;
      els.layerInfo.textContent = `${isNum(before.z) ? `z = ${before.z.toFixed(2)} mm · ` : ''}${formatCount(before.kind.length)} segments${after ? ` before, ${formatCount(after.kind.length)} after` : ''}`;
      els.canvas.dataset.layer = String(before.index);
      viewer.setLayers(before, after);
    } while (layerWanted && loaded);
  } catch (err) {
    if (!(err instanceof Cancelled)) els.layerInfo.textContent = `Cannot draw this layer: ${err.message}`;
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
  const wanted = Number(hashState().get('layer'));
  // The slider's max is unknown until the first layer arrives: allow the wish.
  els.layerSlider.max = String(Math.max(Number.isInteger(wanted) ? wanted : 0, loaded?.report?.layers ?? 1));
  els.layerSlider.value = String(Number.isInteger(wanted) && wanted >= 0 ? wanted : 0);
  refreshLayers();
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
    for (const input of form.elements) {
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
  if (['feature', 'speed', 'curvature'].includes(color)) els.colorBy.value = color;
  els.showTravel.checked = p.get('travel') === '1';
  const view = p.get('view');
  if (['before', 'after', 'side', 'overlay'].includes(view)) els.viewMode.value = view;
  for (const form of els.actionForms) {
    for (const input of form.elements) {
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

const isNum = (v) => typeof v === 'number' && Number.isFinite(v);
const nf = (digits) => new Intl.NumberFormat('en-US', { maximumFractionDigits: digits, minimumFractionDigits: digits });
const fmt0 = nf(0);
const fmt1 = nf(1);
const fmt2 = nf(2);

function formatMs(ms) {
  return ms < 10 ? `${fmt2.format(ms)} ms` : `${fmt0.format(ms)} ms`;
}

function formatDuration(s) {
  if (!isNum(s)) return '—';
  if (s < 60) return `${fmt1.format(s)} s`;
  const total = Math.round(s);
  const h = Math.floor(total / 3600);
  const m = Math.floor((total % 3600) / 60);
  const sec = total % 60;
  return h > 0 ? `${h} h ${m} min ${sec} s` : `${m} min ${sec} s`;
}

function formatLength(mm) {
  if (!isNum(mm)) return '—';
  if (Math.abs(mm) >= 1000) return `${fmt2.format(mm / 1000)} m`;
  return `${fmt1.format(mm)} mm`;
}

function formatCount(n) {
  return isNum(n) ? fmt0.format(n) : '—';
}

function formatBytes(n) {
  if (!isNum(n)) return '—';
  if (n >= 1024 * 1024) return `${fmt2.format(n / (1024 * 1024))} MiB`;
  if (n >= 1024) return `${fmt1.format(n / 1024)} KiB`;
  return `${fmt0.format(n)} B`;
}

function formatScalar(v) {
  if (v === null || v === undefined) return '—';
  if (isNum(v)) return Number.isInteger(v) ? fmt0.format(v) : String(Math.round(v * 1e4) / 1e4);
  if (typeof v === 'boolean') return v ? 'yes' : 'no';
  return String(v);
}

// JSON.stringify that survives Map, BigInt and typed arrays (the API returns spectra as
// Float64Array): the JSON shown and downloaded is the CLI's.
function toJson(value, space) {
  return JSON.stringify(
    value,
    (_key, v) => {
      if (ArrayBuffer.isView(v)) return Array.from(v);
      if (v instanceof Map) return Object.fromEntries(v);
      if (typeof v === 'bigint') return Number.isSafeInteger(Number(v)) ? Number(v) : v.toString();
      return v;
    },
    space,
  );
}

function plain(value) {
  return JSON.parse(toJson(value) ?? 'null');
}

function formatEnergy(j) {
  if (!isNum(j)) return '—';
  if (Math.abs(j) >= 3.6e6) return `${fmt1.format(j / 3.6e6)} kWh`;
  if (Math.abs(j) >= 1e3) return `${fmt1.format(j / 1e3)} kJ`;
  return `${fmt1.format(j)} J`;
}

function signedPercent(x) {
  return `${x >= 0 ? '+' : '−'}${fmt1.format(Math.abs(x) * 100)} %`;
}

function summaryRows(r, name, ms) {
  const file = r.file ?? {};
  const extrusion = r.extrusion ?? {};
  const warnings = Array.isArray(r.warnings) ? r.warnings : [];
  const rows = [
    ['File', name],
    ['Print time', formatDuration(r.time_s)],
    ['Slicer estimate', isNum(file.slicer_time_s) ? `${formatDuration(file.slicer_time_s)} (${signedPercent(r.time_s / file.slicer_time_s - 1)})` : '—'],
    ['Machine', r.machine ? `${r.machine.profile} · ${String(r.machine.junction_model).replaceAll('_', ' ')}` : '—'],
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

function renderSummary(r, name, ms) {
  const tbody = els.summary.tBodies[0];
  tbody.replaceChildren(
    ...summaryRows(r, name, ms).map(([k, v]) =>
      el('tr', { 'data-key': k.toLowerCase().replace(/\s+/g, '-') }, el('th', { scope: 'row', text: k }), el('td', { text: v })),
    ),
  );
}

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

// A scalar, formatted by the unit its key names (`_mm`, `_s`, `_g`, …).
function formatByKey(key, v) {
  if (!isNum(v)) return formatScalar(v);
  if (/_mm3$/.test(key)) return `${fmt1.format(v)} mm³`;
  if (/_per_mm_deg$/.test(key)) return `${formatScalar(v)} °/mm`;
  if (/_deg$/.test(key)) return `${formatScalar(v)}°`;
  if (/_hz$/.test(key)) return `${formatScalar(v)} Hz`;
  if (/_mm$/.test(key)) return formatLength(v);
  if (/_s$/.test(key)) return formatDuration(v);
  if (/_ms$/.test(key)) return formatMs(v);
  if (/_g$/.test(key)) return `${fmt2.format(v)} g`;
  if (/_(wh|kwh|j|w|c|pct|percent)$/i.test(key)) return `${formatScalar(v)} ${key.split('_').pop()}`;
  return formatScalar(v);
}

// Generic rendering of anything we don't have a dedicated view for yet.
function renderValue(v, depth = 0, key = '') {
  if (v === null || typeof v !== 'object') return document.createTextNode(formatByKey(key, v));
  if (Array.isArray(v)) {
    if (v.every((x) => x === null || typeof x !== 'object')) {
      return document.createTextNode(v.length > 12 ? `[${v.slice(0, 12).map(formatScalar).join(', ')}, … ${v.length} items]` : `[${v.map(formatScalar).join(', ')}]`);
    }
    return document.createTextNode(`${v.length} items (see JSON)`);
  }
  const entries = Object.entries(v);
  if (entries.length === 0) return el('span', { class: 'muted', text: 'empty' });
  if (depth >= 2) return el('code', { text: toJson(v).slice(0, 200) });
  return el(
    'table',
    { class: 'kv nested' },
    el('tbody', {}, ...entries.map(([k, x]) => el('tr', {}, el('th', { scope: 'row', text: k }), el('td', {}, renderValue(x, depth + 1, k))))),
  );
}

function renderExtra(r) {
  const extra = Object.entries(r).filter(([k]) => !KNOWN_FIELDS.has(k));
  els.extra.replaceChildren(
    ...extra.map(([k, v]) => el('div', { class: 'extra-item', 'data-field': k }, el('h3', { text: k }), renderValue(v, 0, k))),
  );
  els.extraPanel.hidden = extra.length === 0;
}

function showReport(rawReport, name, ms) {
  const report = plain(rawReport);
  renderStats(report);
  renderSummary(report, name, ms);
  renderFeatures(report);
  renderWarnings(report);
  renderExtra(report);
  showJson(report, `${baseName(name)}.quietpath.json`);
  els.elapsed.textContent = `analyzed in ${formatMs(ms)}`;
  els.elapsed.dataset.ms = String(ms);
  els.results.hidden = false;
  hideError();
}

/** Shows `value` as the latest report JSON (and what "Download report JSON" saves). */
function showJson(value, filename) {
  lastJson = { value, filename };
  els.reportJson.textContent = toJson(value, 2);
}

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

function baseName(name) {
  return String(name ?? '').replace(/\.[^.]*$/, '') || 'quietpath';
}

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
async function setPrinterSettings(file) {
  const nameEl = document.getElementById('printer-settings-name');
  const clear = document.getElementById('printer-settings-clear');
  if (file) {
    const text = await file.text();
    const key = /^\s*\[printer\]/m.test(text) ? 'klipper_config' : 'machine_gcode';
    printerSettings = { name: file.name, text, key };
    nameEl.textContent = `${file.name} (${key === 'klipper_config' ? 'Klipper printer.cfg' : 'Marlin M503 settings'})`;
  } else {
    printerSettings = null;
    nameEl.textContent = 'none: limits from the file and the preset';
  }
  clear.hidden = !printerSettings;
  if (lastSource && lastSource.name && !current) run(lastSource);
}

document.getElementById('printer-settings').addEventListener('change', (e) => {
  e.stopPropagation();
  setPrinterSettings(e.target.files?.[0] ?? null);
  e.target.value = '';
});
document.getElementById('printer-settings-clear').addEventListener('click', () => setPrinterSettings(null));
els.optionsForm.addEventListener('submit', (e) => e.preventDefault());
els.optionsForm.addEventListener('change', () => {
  if (lastSource && lastSource.name && !current) run(lastSource);
});

for (const form of els.actionForms) {
  form.addEventListener('submit', (e) => {
    e.preventDefault();
    runJob(form.dataset.job, form);
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
  writeHash();
});
els.showTravel.addEventListener('change', () => {
  viewer.set('showTravel', els.showTravel.checked);
  writeHash();
});
els.viewMode.addEventListener('change', () => {
  viewer.set('mode', els.viewMode.value);
  writeHash();
});
els.fit.addEventListener('click', () => viewer.fit());
window.addEventListener('hashchange', readHash);

let dragDepth = 0;
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
  e.dataTransfer.dropEffect = 'copy';
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
resetOptimized();
updateActions();
client.warm();
run(demoSource());

// Offline once loaded (sw.js: network first, cache as the fallback). Not
// essential, so a browser or context without service workers is fine.
if ('serviceWorker' in navigator && /^https?:$/.test(location.protocol)) {
  navigator.serviceWorker.register('./sw.js').catch(() => {});
}
