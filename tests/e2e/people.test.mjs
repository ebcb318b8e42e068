// Browser tests of the playground as a person meets it (issue 32): the printer picker, input
// states, the before/after layer after a job, a running job's progress and the list of jobs,
// readable results, per-layer charts, the phone layout, the 3-D view and accessibility (text
// alternatives of the viewer, the 3-D view and the charts; Tab order). Same set-up as
// playground.test.mjs: scripts/serve.mjs, Debian's Chromium through playwright-core, www/pkg built, the corpus in
// ../shared/corpus and the native CLI (target/release/quietpath or $QUIETPATH_CLI).

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { spawnSync } from 'node:child_process';
import { chromium } from 'playwright-core';
import { startServer } from '../../scripts/serve.mjs';

const repoRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const wwwRoot = path.join(repoRoot, 'www');
const corpusDir = path.resolve(repoRoot, '../shared/corpus');
const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
const cli = process.env.QUIETPATH_CLI ?? path.join(repoRoot, 'target', 'release', 'quietpath');
const BENCHY = 'prusaslicer-2.6.1_benchy_marlin2.gcode';
const STEP_TIMEOUT = 30_000;
const JOB_TIMEOUT = 180_000;

let server;
let browser;
let context;
let page;
let baseUrl;
const pageErrors = [];
const requests = [];

before(async () => {
  assert.ok(fs.existsSync(path.join(wwwRoot, 'pkg', 'quietpath_bg.wasm')), 'www/pkg is missing: make pkg');
  server = await startServer({ root: wwwRoot, port: 0 });
  baseUrl = `http://127.0.0.1:${server.address().port}/`;
  browser = await chromium.launch({
    executablePath: chromiumPath,
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run', '--disable-quic'],
  });
  context = await browser.newContext({ viewport: { width: 1280, height: 900 }, serviceWorkers: 'block' });
  context.on('request', (req) => requests.push(req.url()));
  page = await context.newPage();
  page.setDefaultTimeout(STEP_TIMEOUT);
  page.on('pageerror', (err) => pageErrors.push(String(err)));
});

after(async () => {
  await browser?.close();
  await new Promise((resolve) => (server ? server.close(resolve) : resolve()));
});

const byTestId = (id, p = page) => p.locator(`[data-testid="${id}"]`);

async function settled(p = page) {
  await p.waitForFunction(() => {
    const st = document.querySelector('[data-testid="status"]')?.textContent;
    return ['ready', 'error', 'cancelled'].includes(st) && !document.body.classList.contains('busy');
  }, null, { timeout: JOB_TIMEOUT });
  return byTestId('status', p).textContent();
}

async function loadFile(file, p = page) {
  await byTestId('file', p).setInputFiles(file);
  await p.waitForFunction((n) => document.querySelector('[data-testid="filename"]').textContent === n, typeof file === 'string' ? path.basename(file) : file.name);
  return settled(p);
}

async function reportJson(p = page) {
  return JSON.parse(await byTestId('report-json', p).textContent());
}

function cliJson(args) {
  const r = spawnSync(cli, args, { encoding: 'utf8', maxBuffer: 1 << 28 });
  assert.equal(r.status, 0, r.stderr);
  return JSON.parse(r.stdout);
}

test('machine picker: the presets, "from the file", the time of the CLI for that printer, remembered', { timeout: 4 * STEP_TIMEOUT }, async () => {
  await page.goto(baseUrl);
  assert.equal(await settled(), 'ready');
  const values = await byTestId('machine').locator('option').evaluateAll((o) => o.map((x) => x.value));
  for (const preset of ['', 'prusa-mk3s', 'creality-ender3', 'voron-klipper', 'vtg-ldam-servo']) assert.ok(values.includes(preset), `no option "${preset}" in ${values}`);

  const benchy = path.join(corpusDir, BENCHY);
  assert.equal(await loadFile(benchy), 'ready');
  // The benchy sets its own limits (M201, M203…): "from the file" says so.
  const fileOption = await byTestId('machine').locator('option[value=""]').textContent();
  assert.match(fileOption, /from the file \(its \d+ limits/);
  assert.match(await byTestId('machine-limits').textContent(), /a command in the file/);

  const before = await reportJson();
  await byTestId('machine').selectOption('creality-ender3');
  await page.waitForFunction((b) => document.querySelector('[data-testid="report-json"]').textContent !== b, JSON.stringify(before, null, 2));
  assert.equal(await settled(), 'ready');
  const ender = await reportJson();
  assert.equal(ender.machine.profile, 'creality-ender3');
  assert.equal(ender.time_s, cliJson(['analyze', benchy, '--json', '--machine', 'creality-ender3']).time_s, 'the time of the CLI for that printer');
  assert.notEqual(ender.time_s, before.time_s);
  const summary = await byTestId('summary').textContent();
  assert.match(summary, /Timed as.*Ender-3.*junction-deviation/s);
  assert.match(await byTestId('machine-limits').textContent(), /the creality-ender3 preset/);

  // Remembered across visits.
  await page.reload();
  await settled();
  await page.waitForFunction(() => document.querySelector('[data-testid="machine"]').value === 'creality-ender3');
  assert.equal((await reportJson()).machine.profile, 'creality-ender3');
  await byTestId('machine').selectOption('');
  await settled();
  assert.equal(await page.evaluate(() => localStorage.getItem('quietpath.machine')), null);
  assert.deepEqual(pageErrors, []);
});

test('input states: random bytes, a PNG and an empty file are errors with a reason; bad options say why', { timeout: 4 * STEP_TIMEOUT }, async () => {
  await page.goto(baseUrl);
  await settled();
  let seed = 7;
  const random = Buffer.alloc(8192).map(() => {
    seed = (seed * 1103515245 + 12345) & 0x7fffffff;
    return seed >> 16;
  });
  const cases = [
    [{ name: 'random.gcode', mimeType: 'application/octet-stream', buffer: random }, /binary data/],
    [{ name: 'picture.gcode', mimeType: 'image/png', buffer: fs.readFileSync(path.join(repoRoot, 'docs', 'screenshot.png')) }, /PNG image/],
    [{ name: 'empty.gcode', mimeType: 'text/plain', buffer: Buffer.alloc(0) }, /empty/],
    [{ name: 'words.gcode', mimeType: 'text/plain', buffer: Buffer.from('Dear printer,\nplease print a boat.\n') }, /No G-code moves found/],
  ];
  for (const [file, reason] of cases) {
    assert.equal(await loadFile(file), 'error', `${file.name} should be an error`);
    const text = await byTestId('error').textContent();
    assert.match(text, reason, `${file.name}: ${text}`);
    assert.equal(await page.locator('#results').isVisible(), false, `${file.name}: no report cards for a file that is not G-code`);
  }
  // A negative filament diameter: a message at the option, and no analysis with it.
  await page.locator('#options').evaluate((d) => { d.open = true; });
  await byTestId('opt-diameter').fill('-1.75');
  await byTestId('opt-diameter').dispatchEvent('change');
  await byTestId('demo').click();
  assert.equal(await settled(), 'error');
  assert.match(await byTestId('options-error').textContent(), /Filament diameter: -1\.75 mm is too small: at least 0\.1 mm/);
  assert.match(await byTestId('error').textContent(), /Check the options/);
  await byTestId('opt-diameter').fill('');
  await byTestId('opt-diameter').dispatchEvent('change');
  await byTestId('demo').click();
  assert.equal(await settled(), 'ready');
  assert.equal(await byTestId('options-error').isVisible(), false);
  await page.locator('#options').evaluate((d) => { d.open = false; });
  // A job option out of range: the job says why and does not run.
  await byTestId('opt-vtg-tolerance').fill('-0.1');
  await byTestId('run-vtg').click();
  assert.match(await page.locator('form#form-vtg .availability').textContent(), /Tolerance: -0\.1 mm is too small/);
  assert.equal(await byTestId('job-list').locator('li').count(), 0);
  await byTestId('opt-vtg-tolerance').fill('');
  assert.deepEqual(pageErrors, []);
});

test('after a VTG run the after pane shows the layer at the before pane\'s height', { timeout: JOB_TIMEOUT }, async () => {
  await page.goto(baseUrl);
  await settled();
  const count = Number(await byTestId('layer-slider').getAttribute('max'));
  const wanted = Math.floor(count * 0.6);
  await byTestId('layer-slider').evaluate((s, i) => {
    s.value = String(i);
    s.dispatchEvent(new Event('input', { bubbles: true }));
  }, wanted);
  await page.waitForFunction((i) => document.querySelector('[data-testid="viewer"]').dataset.layer === String(i), wanted);
  await byTestId('run-vtg').click();
  assert.equal(await settled(), 'ready');
  await page.waitForFunction(() => document.querySelector('[data-testid="viewer"]').dataset.afterZ !== undefined);
  const { z, afterZ, layer } = await page.evaluate(() => ({ ...document.querySelector('[data-testid="viewer"]').dataset }));
  assert.equal(layer, String(wanted));
  assert.ok(Number(z) > 1, `before z = ${z}`);
  assert.ok(Math.abs(Number(z) - Number(afterZ)) < 1e-3, `before z = ${z}, after z = ${afterZ}`);
});

test('a running job shows its progress and Cancel beside it, in view; every result is kept in a list', { timeout: 2 * JOB_TIMEOUT }, async () => {
  await page.goto(baseUrl);
  await settled();
  assert.equal(await loadFile(path.join(corpusDir, BENCHY)), 'ready');
  await page.locator('#form-vtg').scrollIntoViewIfNeeded();
  await byTestId('run-vtg').click();
  await page.waitForFunction(() => document.body.classList.contains('busy'));
  const where = await page.evaluate(() => {
    const box = (id) => document.querySelector(`[data-testid="${id}"]`).getBoundingClientRect();
    const inView = (r) => r.top >= 0 && r.bottom <= innerHeight && r.left >= 0 && r.right <= innerWidth && r.width > 0;
    return {
      cancelInView: inView(box('cancel')),
      progressInView: inView(box('progress')),
      inForm: !!document.querySelector('#form-vtg [data-testid="cancel"]'),
      cancelEnabled: !document.querySelector('[data-testid="cancel"]').disabled,
    };
  });
  assert.deepEqual(where, { cancelInView: true, progressInView: true, inForm: true, cancelEnabled: true });
  // Scrolled away, the progress stays in view while the job runs (sticky).
  await page.evaluate(() => window.scrollBy(0, 250));
  const stillInView = await page.evaluate(() => {
    const r = document.querySelector('[data-testid="cancel"]').getBoundingClientRect();
    return document.body.classList.contains('busy') ? r.top >= 0 && r.bottom <= innerHeight : true;
  });
  assert.ok(stillInView, 'Cancel scrolled out of view while the job runs');
  // Far away (the top of the page), it floats at the bottom of the window.
  await page.evaluate(() => window.scrollTo(0, 0));
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const floating = await page.evaluate(() => {
    const r = document.querySelector('[data-testid="cancel"]').getBoundingClientRect();
    return document.body.classList.contains('busy') ? r.top >= 0 && r.bottom <= innerHeight : true;
  });
  assert.ok(floating, 'Cancel out of view at the top of the page while the job runs');
  assert.equal(await settled(), 'ready');
  assert.equal(await page.locator('#form-vtg [data-testid="cancel"]').count(), 0, 'the progress goes back under the file picker');
  // A second job: both results are listed, the first still there.
  await byTestId('opt-vtg-tolerance').fill('0.05');
  await byTestId('run-vtg').click();
  assert.equal(await settled(), 'ready');
  const entries = byTestId('job-entry');
  assert.equal(await entries.count(), 2);
  const first = await reportJson();
  assert.equal(first.tolerance_mm, 0.05);
  await entries.nth(1).locator('button', { hasText: 'Show' }).click();
  assert.notEqual((await reportJson()).tolerance_mm, 0.05, 'the earlier result is shown again');
  await byTestId('opt-vtg-tolerance').fill('');
  assert.deepEqual(pageErrors, []);
});

test('results read as words: named metrics with units and explanations, tidy units, JSON and "More" collapsed', { timeout: JOB_TIMEOUT }, async () => {
  await page.goto(baseUrl);
  assert.equal(await settled(), 'ready');
  assert.equal(await page.locator('#json-details').evaluate((d) => d.open), false, 'the report JSON starts collapsed');
  assert.equal(await page.locator('#extra-details').evaluate((d) => d.open), false, '"More" starts collapsed');
  await byTestId('run-vtg').click();
  assert.equal(await settled(), 'ready');
  const tables = await byTestId('paper-tables').textContent();
  assert.doesNotMatch(tables, /\[object Object\]/);
  assert.match(tables, /Vibration deviation, largest/);
  assert.match(tables, /Path length L/);
  // Every row of the before/after and paper tables: a name and a one-line explanation.
  const rows = await page.locator('[data-testid="compare-table"] tbody th, [data-testid="paper-tables"] tbody th').evaluateAll((ths) => ths.map((th) => ({ name: th.firstChild?.textContent ?? '', explain: th.querySelector('small.explain')?.textContent ?? '' })));
  assert.ok(rows.length > 10);
  for (const r of rows) {
    assert.doesNotMatch(r.name, /_/, `raw key as a name: ${r.name}`);
    assert.ok(r.explain.length > 10 || /^Deviation/.test(r.name), `no explanation for ${r.name}`);
  }
  await page.locator('#extra-details').evaluate((d) => { d.open = true; });
  const text = await page.locator('main').innerText();
  assert.doesNotMatch(text, /\d kwh\b/, 'kWh spelled kwh');
  assert.doesNotMatch(text, /\d c\b/, '°C spelled c');
  assert.doesNotMatch(text, /−0\.0 %/, 'a signed zero change');
  assert.doesNotMatch(text, /\b(l_total_mm|change pct|change_pct)\b/, 'raw keys');
  assert.match(text, /°C/);
  await page.locator('#extra-details').evaluate((d) => { d.open = false; });
});

test('per-layer charts: time, energy and filament; a click shows the layer; layer-time colours; the view refits per layer with a scale bar', { timeout: JOB_TIMEOUT }, async () => {
  await page.goto(baseUrl);
  assert.equal(await settled(), 'ready');
  const report = await reportJson();
  for (const id of ['chart-layer-time', 'chart-layer-energy', 'chart-layer-filament']) {
    assert.equal(await byTestId(id).getAttribute('data-points'), String(report.layer_list.length), id);
    assert.equal(await byTestId(id).locator('canvas').count(), 1, `${id} drawn`);
  }
  assert.match(await byTestId('layers-summary').textContent(), /the longest \d/);
  await page.waitForFunction(() => document.querySelector('[data-testid="viewer"]').dataset.layer === '0');
  // Click near the right end of the time chart: a late layer in the viewer.
  const over = byTestId('chart-layer-time').locator('.u-over');
  const box = await over.boundingBox();
  await over.hover({ position: { x: box.width * 0.9, y: box.height / 2 } });
  await over.click({ position: { x: box.width * 0.9, y: box.height / 2 } });
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="viewer"]').dataset.layer) > 0);
  const layer = Number(await byTestId('viewer').getAttribute('data-layer'));
  const n = report.layer_list.length;
  assert.ok(layer > n * 0.7, `clicked at 90 % of ${n} layers, viewer shows layer ${layer}`);
  assert.equal(await byTestId('layer-slider').inputValue(), String(layer));
  // Layer-time colouring, with its legend.
  await byTestId('color-by').selectOption('layer-time');
  await page.waitForFunction(() => /s per layer/.test(document.querySelector('[data-testid="legend"]').textContent));
  await byTestId('color-by').selectOption('feature');
  // Refit per layer: the first and a late (smaller) layer get different scales; a scale bar.
  const scaleAt = async (i) => {
    await byTestId('layer-slider').evaluate((s, v) => {
      s.value = String(v);
      s.dispatchEvent(new Event('input', { bubbles: true }));
    }, i);
    await page.waitForFunction((v) => document.querySelector('[data-testid="viewer"]').dataset.layer === String(v), i);
    await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
    return Number(await byTestId('viewer').getAttribute('data-scale'));
  };
  const s0 = await scaleAt(0);
  const sTop = await scaleAt(n - 1);
  assert.notEqual(s0, sTop, 'the view refits to each layer');
  assert.match(await byTestId('viewer').getAttribute('data-scale-bar'), /^\d+(\.\d+)? mm$/);
  // The bed from the slicer's settings in the file (the demo: bed_shape 250 × 210), outlined.
  assert.equal(await byTestId('viewer').getAttribute('data-bed'), '250 × 210 mm');
  assert.match(await byTestId('legend').textContent(), /bed 250 × 210 mm/);
  // B shows the whole bed: a smaller scale than the top layer's fit.
  await byTestId('viewer').focus();
  await page.keyboard.press('b');
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  assert.ok(Number(await byTestId('viewer').getAttribute('data-scale')) < sTop, 'B zooms out to the bed');
});

test('phone width (390 px): no sideways scroll, the picker and results fit', { timeout: JOB_TIMEOUT }, async () => {
  const phone = await browser.newContext({ viewport: { width: 390, height: 844 }, deviceScaleFactor: 2, isMobile: true, hasTouch: true, serviceWorkers: 'block' });
  const p = await phone.newPage();
  p.setDefaultTimeout(STEP_TIMEOUT);
  await p.goto(baseUrl);
  assert.equal(await settled(p), 'ready');
  await byTestId('run-vtg', p).click();
  assert.equal(await settled(p), 'ready');
  const wide = await p.evaluate(() => {
    const out = [];
    for (const e of document.querySelectorAll('body *')) {
      const r = e.getBoundingClientRect();
      if (r.width > 0 && r.right > innerWidth + 1 && !e.closest('.table-scroll, .json, details:not([open])')) out.push(`${e.tagName}.${e.className} ${Math.round(r.right)}`);
    }
    return { scroll: document.documentElement.scrollWidth, inner: innerWidth, out: out.slice(0, 8) };
  });
  assert.ok(wide.scroll <= wide.inner, `page scrolls sideways: ${wide.scroll} > ${wide.inner}: ${wide.out.join(', ')}`);
  const shot = process.env.UPDATE_SCREENSHOT ? path.join(repoRoot, 'docs', 'screenshot-phone.png') : path.join(os.tmpdir(), 'playground-phone.png');
  await p.evaluate(() => window.scrollTo(0, 0));
  await p.screenshot({ path: shot, fullPage: true, clip: { x: 0, y: 0, width: 390, height: 1690 } });
  assert.ok(fs.statSync(shot).size > 30_000, 'phone screenshot is suspiciously small');
  await phone.close();
});

test('phones: two fingers pinch-zoom the layer view', async () => {
  await page.goto(baseUrl);
  assert.equal(await settled(), 'ready');
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="viewer"]').dataset.segments) > 0);
  const before = Number(await byTestId('viewer').getAttribute('data-scale'));
  await byTestId('viewer').evaluate((c) => {
    const r = c.getBoundingClientRect();
    const cx = r.left + r.width / 2;
    const cy = r.top + r.height / 2;
    const ev = (type, id, x) => c.dispatchEvent(new PointerEvent(type, { pointerId: id, pointerType: 'touch', isPrimary: id === 11, clientX: x, clientY: cy, bubbles: true }));
    ev('pointerdown', 11, cx - 20);
    ev('pointerdown', 12, cx + 20);
    ev('pointermove', 11, cx - 60);
    ev('pointermove', 12, cx + 60);
    ev('pointerup', 11, cx - 60);
    ev('pointerup', 12, cx + 60);
  });
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  const after = Number(await byTestId('viewer').getAttribute('data-scale'));
  assert.ok(Math.abs(after / before - 3) < 0.01, `pinch from 40 px to 120 px: scale ${before} → ${after}`);
});

// Pixels of the 3-D canvas that differ from its background colour (the WebGL picture), or with
// `near` ([r, g, b]) those within a small distance of that colour; `hash` returns a hash of
// where the inked pixels are instead of their count.
async function inked3d(p = page, hash = false, near = null) {
  return p.evaluate(({ hash, near }) => {
    const c = document.querySelector('[data-testid="view-3d"]');
    const t = document.createElement('canvas');
    t.width = c.width;
    t.height = c.height;
    const ctx = t.getContext('2d');
    ctx.drawImage(c, 0, 0);
    const d = ctx.getImageData(0, 0, t.width, t.height).data;
    const ref = near ?? [d[0], d[1], d[2]];
    let n = 0;
    let h = 0;
    for (let i = 0; i < d.length; i += 4) {
      const off = Math.abs(d[i] - ref[0]) + Math.abs(d[i + 1] - ref[1]) + Math.abs(d[i + 2] - ref[2]);
      if (near ? off < 60 : off > 30) {
        n++;
        h = (h * 31 + i) | 0;
      }
    }
    return hash ? h : n;
  }, { hash, near });
}

// Pixels of the 3-D canvas within a small distance of the tool-vector colour (the swatch beside
// the "tool vectors" toggle shows it); -1 when the swatch has no colour.
async function toolInk(p = page) {
  const rgb = await p.evaluate(() =>
    getComputedStyle(document.querySelector('[data-testid="tools-swatch"]')).backgroundColor.match(/\d+/g)?.map(Number));
  if (!rgb || rgb.length < 3) return -1;
  return inked3d(p, false, rgb.slice(0, 3));
}

test('3-D view: the demo drawn with WebGL, a layer range, orbit, the 5-axis file', { timeout: JOB_TIMEOUT }, async () => {
  await page.goto(baseUrl);
  assert.equal(await settled(), 'ready');
  assert.equal(await byTestId('view-3d').isVisible(), false, 'the 2-D view by default');
  await byTestId('view-kind').selectOption('3d');
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="view-3d"]').dataset.segments) > 0, null, { timeout: JOB_TIMEOUT });
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  assert.equal(await byTestId('view-3d').isVisible(), true);
  assert.equal(await byTestId('viewer').isVisible(), false);
  const report = await reportJson();
  assert.equal(await byTestId('view-3d').getAttribute('data-layers'), String(report.layers), 'every layer of the demo');
  const whole = Number(await byTestId('view-3d').getAttribute('data-segments'));
  const ink = await inked3d();
  assert.ok(ink > 2000, `the WebGL canvas is drawn: ${ink} pixels`);
  // A three-axis file has no tool vectors: none drawn, no toggle.
  assert.equal(await byTestId('view-3d').getAttribute('data-tool-vectors'), '0');
  assert.equal(await byTestId('show-tools').isVisible(), false, 'no tool-vector toggle for the 3-axis demo');
  assert.equal(await toolInk(), 0, 'no pixel of the tool-vector colour in the demo');
  assert.equal(await byTestId('view-3d').getAttribute('data-tool-offset-mm'), '', 'no tool offset to measure');
  // A layer range: fewer segments.
  await byTestId('layer-from').fill('10');
  await byTestId('layer-from').dispatchEvent('change');
  await byTestId('layer-to').fill('12');
  await byTestId('layer-to').dispatchEvent('change');
  await page.waitForFunction(() => document.querySelector('[data-testid="view-3d"]').dataset.layers === '3');
  assert.ok(Number(await byTestId('view-3d').getAttribute('data-segments')) < whole / 3);
  // Orbit by dragging: the picture changes.
  await byTestId('view-3d').scrollIntoViewIfNeeded();
  const before = await inked3d(page, true);
  const box = await byTestId('view-3d').boundingBox();
  await page.mouse.move(box.x + box.width / 2, box.y + box.height / 2);
  await page.mouse.down();
  await page.mouse.move(box.x + box.width / 2 + 120, box.y + box.height / 2 + 40, { steps: 5 });
  await page.mouse.up();
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  assert.notEqual(await inked3d(page, true), before, 'orbiting redraws the part');
  // The 5-axis corpus file draws too.
  assert.equal(await loadFile(path.join(corpusDir, 'multiaxis-xyzbc_zhang-ral2021_model1.gcode')), 'ready');
  await page.waitForFunction(() => Number(document.querySelector('[data-testid="view-3d"]').dataset.segments) > 0 && document.querySelector('[data-testid="view-3d"]').dataset.layers !== '3', null, { timeout: JOB_TIMEOUT });
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  assert.ok((await inked3d()) > 500, '5-axis file drawn in 3-D');
  // Its tool vectors (from the crate's kinematic model), on by default, in their own colour.
  assert.equal(await byTestId('show-tools').isVisible(), true, 'the tool-vector toggle for a 5-axis file');
  assert.equal(await byTestId('show-tools').isChecked(), true, 'tool vectors on by default');
  const vectors = Number(await byTestId('view-3d').getAttribute('data-tool-vectors'));
  assert.ok(vectors > 100, `tool vectors drawn: ${vectors}`);
  assert.match((await byTestId('view-3d').getAttribute('aria-label')) ?? '', /tool vectors/);
  // The path is drawn on the workpiece, through the tips the vectors start from: each drawn
  // vector's base is a drawn path vertex (machine X, Y would put it 27 mm away on average).
  assert.match((await byTestId('view-3d').getAttribute('aria-label')) ?? '', /drawn on the workpiece/);
  const offset = Number(await byTestId('view-3d').getAttribute('data-tool-offset-mm'));
  assert.ok(Number.isFinite(offset) && offset < 1e-3, `tool vectors start on the drawn path: ${offset} mm off`);
  const toolPixels = await toolInk();
  assert.ok(toolPixels > 200, `tool-vector pixels: ${toolPixels}`);
  // The toggle hides them.
  await byTestId('show-tools').uncheck();
  await page.waitForFunction(() => document.querySelector('[data-testid="view-3d"]').dataset.toolVectors === '0');
  await page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  assert.ok((await toolInk()) < toolPixels / 20, 'tool vectors hidden by the toggle');
  await byTestId('show-tools').check();
  await page.waitForFunction((n) => document.querySelector('[data-testid="view-3d"]').dataset.toolVectors === String(n), vectors);
  await byTestId('view-kind').selectOption('2d');
  // The 2-D layer view stays in machine axes, and says so for a multi-axis file.
  await page.waitForFunction(() => /machine X, Y/.test(document.querySelector('[data-testid="layer-info"]').textContent ?? ''), null, { timeout: JOB_TIMEOUT });
  assert.deepEqual(pageErrors, []);
});

test('accessibility: the viewer, the 3-D view and every chart say what they show, and follow the layer; Tab follows the page', { timeout: JOB_TIMEOUT }, async () => {
  await page.goto(baseUrl);
  assert.equal(await settled(), 'ready');
  const report = await reportJson();
  const n = report.layers;
  const label = async (id) => (await byTestId(id).getAttribute('aria-label')) ?? '';
  const frames = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));

  // The layer viewer: a picture whose name is the layer shown, its height and its colours.
  assert.equal(await byTestId('viewer').getAttribute('role'), 'img');
  const showLayer = async (i) => {
    await byTestId('layer-slider').evaluate((s, v) => {
      s.value = String(v);
      s.dispatchEvent(new Event('input', { bubbles: true }));
    }, i);
    await page.waitForFunction((v) => (document.querySelector('[data-testid="viewer"]').getAttribute('aria-label') ?? '').startsWith(`Layer ${v + 1} of `), i);
    await frames();
    const text = await label('viewer');
    const z = Number(await byTestId('viewer').getAttribute('data-z'));
    assert.ok(text.startsWith(`Layer ${i + 1} of ${n}, z = ${z.toFixed(2)} mm: the file, `), text);
    return { text, z };
  };
  const first = await showLayer(0);
  assert.match(first.text, /[\d,]+ segments drawn, coloured by feature \(.*outer wall.*\)\. Wheel or \+\/- to zoom/);
  const tenth = await showLayer(9);
  assert.notEqual(tenth.text, first.text, 'the name follows the layer');
  await byTestId('color-by').selectOption('speed');
  await page.waitForFunction(() => /coloured by speed \([\d.]+ to [\d.]+ mm\/s/.test(document.querySelector('[data-testid="viewer"]').getAttribute('aria-label')));
  await byTestId('color-by').selectOption('feature');
  await page.waitForFunction(() => /coloured by feature/.test(document.querySelector('[data-testid="viewer"]').getAttribute('aria-label')));

  // Every chart drawn is a picture named by its caption and a summary of its series; a chart
  // not drawn yet shows its message as text (no picture role).
  const charts = await page.evaluate(() =>
    [...document.querySelectorAll('[data-testid^="chart-"]')].map((c) => ({ id: c.dataset.testid, drawn: !!c.querySelector('canvas'), role: c.getAttribute('role'), label: c.getAttribute('aria-label') })),
  );
  assert.ok(charts.filter((c) => c.drawn).length >= 3, JSON.stringify(charts));
  for (const c of charts) {
    if (c.drawn) assert.equal(c.role, 'img', c.id);
    else assert.deepEqual([c.role, c.label], [null, null], c.id);
  }
  const perLayer = [
    ['chart-layer-time', 'Print time per layer, s', 'time', 's'],
    ['chart-layer-energy', 'Energy per layer, J', 'energy', 'J'],
    ['chart-layer-filament', 'Filament per layer, mm', 'filament', 'mm'],
  ];
  for (const [id, caption, series, unit] of perLayer) {
    const text = await label(id);
    const re = new RegExp(`^${caption}: ${n} points, layer 1 to ${n}; ${series} from [\\d.,]+ ${unit} at layer \\d+ to [\\d.,]+ ${unit} at layer \\d+\\.$`);
    assert.match(text, re, id);
  }
  // The longest layer the time chart names is the report's.
  const times = report.layer_list.map((l) => l.time_s);
  const longest = times.indexOf(Math.max(...times)) + 1;
  assert.match(await label('chart-layer-time'), new RegExp(` to [\\d.,]+ s at layer ${longest}\\.$`));
  // Another printer: new per-layer times, a new summary.
  const timeLabel = await label('chart-layer-time');
  await byTestId('machine').selectOption('creality-ender3');
  await page.waitForFunction((t) => document.querySelector('[data-testid="chart-layer-time"]').getAttribute('aria-label') !== t, timeLabel);
  assert.equal(await settled(), 'ready');
  await byTestId('machine').selectOption('');
  assert.equal(await settled(), 'ready');

  // The 3-D view: its name is the layer range, their heights and the colours; it follows the range.
  await byTestId('view-kind').selectOption('3d');
  await page.waitForFunction((n) => (document.querySelector('[data-testid="view-3d"]').getAttribute('aria-label') ?? '').startsWith(`The part in 3-D: layers 1 to ${n} of ${n}`), n, { timeout: JOB_TIMEOUT });
  assert.equal(await byTestId('view-3d').getAttribute('role'), 'img');
  const whole = await label('view-3d');
  assert.match(whole, /, z = [\d.]+ to [\d.]+ mm, of the file, [\d,]+ segments, coloured by feature\. Drag to orbit/);
  await byTestId('layer-from').fill('10');
  await byTestId('layer-from').dispatchEvent('change');
  await byTestId('layer-to').fill('12');
  await byTestId('layer-to').dispatchEvent('change');
  const range = `The part in 3-D: layers 10 to 12 of ${n}, z = ${tenth.z.toFixed(2)} to `;
  await page.waitForFunction((r) => (document.querySelector('[data-testid="view-3d"]').getAttribute('aria-label') ?? '').startsWith(r), range);
  await byTestId('view-kind').selectOption('2d');

  // Tab order follows the page: no positive tabindex, and Tab visits the controls in document order.
  const positive = await page.evaluate(() => [...document.querySelectorAll('[tabindex]')].filter((e) => e.tabIndex > 0).map((e) => e.outerHTML.slice(0, 100)));
  assert.deepEqual(positive, []);
  // A fresh page: Tab starts from the top of the document.
  await page.goto(baseUrl);
  assert.equal(await settled(), 'ready');
  const visited = [];
  for (let i = 0; i < 200; i++) {
    await page.keyboard.press('Tab');
    const at = await page.evaluate(() => {
      const e = document.activeElement;
      if (!e || e === document.body) return null;
      // Where it is on the page: its panel's top (panels side by side share a row).
      const panel = e.closest('.panel, .stats') ?? e;
      return {
        order: [...document.querySelectorAll('*')].indexOf(e),
        top: panel.getBoundingClientRect().top + window.scrollY,
        name: e.dataset?.testid || e.id || `${e.tagName.toLowerCase()}${e.getAttribute('name') ? `[${e.getAttribute('name')}]` : ''}`,
      };
    });
    if (!at || (visited.length && at.order === visited[0].order)) break;
    visited.push(at);
  }
  assert.ok(visited.length > 20, `Tab reached ${visited.length} controls: ${visited.map((v) => v.name).join(' ')}`);
  for (let i = 1; i < visited.length; i++) {
    const [a, b] = [visited[i - 1], visited[i]];
    assert.ok(b.order > a.order, `Tab went from ${a.name} back to ${b.name}: ${visited.map((v) => v.name).join(' → ')}`);
    // The page's grid places panels by area: the document order must be the order they are seen in.
    assert.ok(b.top >= a.top - 1, `Tab went from ${a.name} (panel at y = ${Math.round(a.top)}) up to ${b.name} (y = ${Math.round(b.top)})`);
  }
  const names = visited.map((v) => v.name);
  const main = ['file', 'demo', 'machine', 'layer-slider', 'color-by', 'show-travel', 'fit', 'view-kind', 'viewer', 'run-optimize', 'run-vtg', 'run-infill', 'run-smooth', 'run-vibration', 'download'];
  for (const id of main) assert.ok(names.includes(id), `Tab never reaches ${id}: ${names.join(' ')}`);
  assert.deepEqual(names.filter((x) => main.includes(x)), main, 'the main controls in the order of the page');
  assert.deepEqual(pageErrors, []);
});

test('no request leaves 127.0.0.1', () => {
  const outside = requests.filter((u) => !u.startsWith(baseUrl) && !u.startsWith('blob:') && !u.startsWith('data:'));
  assert.deepEqual(outside, []);
});
