// quietpath playground: page logic.
//
// Reads a G-code file (picker, drag-and-drop or the bundled demo) as an
// ArrayBuffer, transfers it to worker.js, and renders the report it sends back.
// Nothing is uploaded: the only requests this page makes are for its own files
// (enforced by the Content-Security-Policy). See worker.js for the protocol.

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
};

const DEMO_URL = 'demo/demo.gcode';
const MAX_WARNINGS_SHOWN = 500;

// Fields rendered by dedicated views; everything else goes to "More".
const KNOWN_FIELDS = new Set([
  'time_s', 'moves', 'layers', 'distance_mm', 'filament_mm', 'material_g',
  'warnings', 'file', 'extrusion', 'features', 'bounds',
]);

// ── Worker management ──────────────────────────────────────────────────────

let worker = null;
let nextId = 1;
let current = null; // the run in flight: { id, name, startedAt }
let lastReport = null;
let lastSource = null; // { name, load: () => Promise<ArrayBuffer> }
let downloadUrl = null;

function createWorker() {
  const w = new Worker('./worker.js', { type: 'module' });
  w.onmessage = (event) => onWorkerMessage(w, event.data);
  w.onerror = (event) => {
    event.preventDefault();
    const detail = event.message || 'the analysis worker failed to start (is pkg/ built?)';
    onWorkerCrash(w, detail);
  };
  w.onmessageerror = () => onWorkerCrash(w, 'could not read a message from the analysis worker');
  return w;
}

function getWorker() {
  if (!worker) worker = createWorker();
  return worker;
}

function discardWorker() {
  if (worker) {
    worker.terminate();
    worker = null;
  }
}

function onWorkerCrash(w, detail) {
  if (w !== worker) return;
  discardWorker();
  showError({ message: w.loaded ? `The analyzer crashed: ${detail}` : `The analyzer could not be started: ${detail}` });
  if (current) finishRun('error');
  else setStatus('error');
  // A worker that had loaded the wasm before is replaced right away (warm for
  // the next file); one that never loaded is replaced lazily by the next run,
  // so a missing pkg/ cannot make us respawn workers in a loop.
  if (w.loaded) worker = createWorker();
}

function onWorkerMessage(w, msg) {
  if (w !== worker || !msg) return;
  if (msg.type === 'hello') {
    w.loaded = true;
    els.version.textContent = msg.version ? `v${msg.version}` : '';
    return;
  }
  if (!current || msg.id !== current.id) return; // stale (cancelled) run
  switch (msg.type) {
    case 'progress':
      els.progress.value = Math.max(els.progress.value, Math.min(1, msg.fraction));
      break;
    case 'result':
      showReport(msg.report, current.name, msg.ms);
      finishRun('ready');
      break;
    case 'error':
      showError(msg);
      finishRun('error');
      if (msg.fatal) {
        discardWorker();
        worker = createWorker();
      }
      break;
    default:
      break;
  }
}

function setStatus(text) {
  els.status.textContent = text;
  els.status.dataset.state = text;
}

function finishRun(status) {
  if (current) {
    const ms = performance.now() - current.startedAt;
    if (status !== 'ready') els.elapsed.textContent = `${formatMs(ms)} total`;
  }
  current = null;
  els.cancel.disabled = true;
  document.body.classList.remove('busy');
  setStatus(status);
}

// ── Running an analysis ────────────────────────────────────────────────────

function readOptions() {
  const form = new FormData(els.optionsForm);
  const options = {};
  if (form.get('strict')) options.strict = true;
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
  if (current) cancel('superseded');
  const id = nextId++;
  current = { id, name: source.name, startedAt: performance.now() };
  hideError();
  setStatus('reading');
  els.filename.textContent = source.name;
  els.elapsed.textContent = '';
  els.progress.value = 0;
  els.cancel.disabled = false;
  document.body.classList.add('busy');

  let bytes;
  try {
    bytes = await source.load();
  } catch (err) {
    if (current?.id !== id) return;
    showError({ message: `Could not read ${source.name}: ${err?.message ?? err}` });
    finishRun('error');
    return;
  }
  if (current?.id !== id) return; // cancelled while reading
  setStatus('analyzing');
  getWorker().postMessage(
    { id, type: 'analyze', bytes, name: source.name, options: readOptions() },
    [bytes],
  );
}

function cancel(reason = 'cancelled') {
  if (!current) return;
  discardWorker();
  current = null;
  worker = createWorker();
  els.cancel.disabled = true;
  els.progress.value = 0;
  document.body.classList.remove('busy');
  if (reason === 'cancelled') {
    setStatus('cancelled');
    els.elapsed.textContent = '';
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

// JSON.stringify that survives Map (serde-wasm-bindgen's default for maps) and BigInt.
function toJson(value, space) {
  return JSON.stringify(
    value,
    (_key, v) => {
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
  lastReport = { report, name };
  renderStats(report);
  renderSummary(report, name, ms);
  renderFeatures(report);
  renderWarnings(report);
  renderExtra(report);
  els.reportJson.textContent = toJson(report, 2);
  els.elapsed.textContent = `analyzed in ${formatMs(ms)}`;
  els.results.hidden = false;
  hideError();
}

function showError({ message, line, column, excerpt }) {
  els.results.hidden = true; // whatever report is shown belongs to another file
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

function downloadReport() {
  if (!lastReport) return;
  if (downloadUrl) URL.revokeObjectURL(downloadUrl);
  const blob = new Blob([toJson(lastReport.report, 2) + '\n'], { type: 'application/json' });
  downloadUrl = URL.createObjectURL(blob);
  const a = el('a', { href: downloadUrl, download: `${lastReport.name.replace(/\.[^.]*$/, '') || 'report'}.quietpath.json` });
  document.body.append(a);
  a.click();
  a.remove();
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
els.optionsForm.addEventListener('submit', (e) => e.preventDefault());
els.optionsForm.addEventListener('change', () => {
  if (lastSource && lastSource.name && !current) run(lastSource);
});

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

// Start the worker right away (the wasm compiles while the demo downloads),
// then analyze the bundled demo.
getWorker();
run(demoSource());
