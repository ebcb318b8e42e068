// End-to-end test of the static playground in www/: serves it with
// scripts/serve.mjs and drives Debian's Chromium through playwright-core.
//
// Needs: www/pkg → the built wasm package (make does this), /usr/bin/chromium
// (or $CHROMIUM), and the corpus in ../shared/corpus next to the repo.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';
import { startServer } from '../../scripts/serve.mjs';

const repoRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const wwwRoot = path.join(repoRoot, 'www');
const corpusDir = path.resolve(repoRoot, '../shared/corpus');
const chromiumPath = process.env.CHROMIUM ?? '/usr/bin/chromium';
const screenshotPath = process.env.PLAYGROUND_SCREENSHOT ?? path.join(os.tmpdir(), 'playground.png');
const BENCHY = 'prusaslicer-2.6.1_benchy_marlin2.gcode';

const STEP_TIMEOUT = 20_000;

let server;
let browser;
let context;
let page;
let baseUrl;
const requests = [];
const consoleErrors = [];
const pageErrors = [];

before(async () => {
  assert.ok(
    fs.existsSync(path.join(wwwRoot, 'pkg', 'quietpath_bg.wasm')),
    'www/pkg/quietpath_bg.wasm is missing: build the wasm package and link it to www/pkg (make does this)',
  );
  assert.ok(fs.existsSync(chromiumPath), `no Chromium at ${chromiumPath} (apt-get install chromium, or set CHROMIUM)`);
  server = await startServer({ root: wwwRoot, port: 0 });
  baseUrl = `http://127.0.0.1:${server.address().port}/`;
  browser = await chromium.launch({
    executablePath: chromiumPath,
    args: [
      '--headless',
      '--no-sandbox',
      '--disable-gpu',
      '--disable-background-networking',
      '--disable-component-update',
      '--disable-sync',
      '--no-first-run',
      '--disable-quic',
    ],
  });
  context = await browser.newContext({ viewport: { width: 1280, height: 900 } });
  page = await context.newPage();
  page.setDefaultTimeout(STEP_TIMEOUT);
  // Every request the page and its worker make (context-level also sees workers).
  context.on('request', (req) => requests.push(req.url()));
  page.on('console', (msg) => {
    if (msg.type() === 'error') consoleErrors.push(msg.text());
  });
  page.on('pageerror', (err) => pageErrors.push(String(err)));
});

after(async () => {
  await browser?.close();
  await new Promise((resolve) => (server ? server.close(resolve) : resolve()));
});

const byTestId = (id) => page.locator(`[data-testid="${id}"]`);

// Wait until the page shows `status` for the file `name`.
async function waitForStatus(status, name) {
  await page.waitForFunction(
    ([s, n]) => {
      const st = document.querySelector('[data-testid="status"]')?.textContent;
      const fn = document.querySelector('[data-testid="filename"]')?.textContent;
      return ['ready', 'error', 'cancelled'].includes(st) && (n === undefined || fn === n);
    },
    [status, name],
    { timeout: STEP_TIMEOUT },
  );
  const got = await byTestId('status').textContent();
  if (got !== status) {
    const err = await byTestId('error').textContent().catch(() => '');
    assert.fail(`expected status "${status}" for ${name ?? 'the page'}, got "${got}" (error: ${err})`);
  }
}

async function reportJson() {
  return JSON.parse(await byTestId('report-json').textContent());
}

async function upload(name, buffer, mimeType = 'text/plain') {
  await byTestId('file').setInputFiles({ name, mimeType, buffer });
}

// Upload a file from disk (Playwright hands the path to the local browser).
async function uploadPath(file) {
  await byTestId('file').setInputFiles(file);
}

test('the demo loads and is analyzed on first visit', async () => {
  const t0 = Date.now();
  await page.goto(baseUrl);
  await waitForStatus('ready', 'demo.gcode');
  const report = await reportJson();
  assert.ok(report.layers > 0, `demo layers = ${report.layers}`);
  assert.ok(report.moves > 0, `demo moves = ${report.moves}`);
  assert.ok(report.time_s > 0, `demo time_s = ${report.time_s}`);
  const summary = await byTestId('summary').textContent();
  assert.match(summary, /Layers/);
  assert.match(summary, /Extrusion mode/);
  assert.equal(await byTestId('error').isVisible(), false);
  assert.equal(await byTestId('progress').evaluate((p) => p.value), 1);
  assert.match(await byTestId('elapsed').textContent(), /\d ms/);
  assert.ok(Date.now() - t0 < STEP_TIMEOUT);
});

test('the page looks right (screenshot)', async () => {
  await page.screenshot({ path: screenshotPath, fullPage: true });
  assert.ok(fs.statSync(screenshotPath).size > 10_000, 'screenshot is suspiciously small');
});

test('uploading a corpus file shows its report', async () => {
  const file = path.join(corpusDir, BENCHY);
  assert.ok(fs.existsSync(file), `corpus file missing: ${file}`);
  await uploadPath(file);
  await waitForStatus('ready', BENCHY);
  const report = await reportJson();
  assert.ok(Math.abs(report.layers - 160) <= 1, `benchy layers = ${report.layers}, expected ≈160`);
  const summary = await byTestId('summary').textContent();
  assert.match(summary, new RegExp(BENCHY.replace(/[.]/g, '\\.')));
  const features = await byTestId('features').locator('tbody tr').count();
  assert.ok(features > 0, 'benchy should have feature rows');
  // The happy path so far (demo + a real file) must not log any error.
  assert.deepEqual(consoleErrors, [], 'console errors on the happy path');
  assert.deepEqual(pageErrors, [], 'uncaught page errors on the happy path');
});

test('a bad file is reported and the page keeps working', async () => {
  // Random bytes (fixed seed) in lenient mode: a report with warnings or a readable error.
  let seed = 0x5eed;
  const random = Buffer.alloc(64 * 1024, 0).map(() => {
    seed = (seed * 1103515245 + 12345) & 0x7fffffff;
    return seed >> 16;
  });
  await upload('random.gcode', random, 'application/octet-stream');
  await waitForStatus(await settledStatus('random.gcode'), 'random.gcode');
  await assertReadableOutcome();

  // UTF-16 text with a BOM.
  const utf16 = Buffer.from('\ufeffG28\r\nG1 X10 Y10 F3000\r\nG1 X20 E1\r\n', 'utf16le');
  await upload('utf16.gcode', utf16);
  await waitForStatus(await settledStatus('utf16.gcode'), 'utf16.gcode');
  await assertReadableOutcome();

  // Strict mode with a malformed line: an error naming the line.
  await page.locator('#options > summary').click();
  await byTestId('opt-strict').check();
  const bad = 'G21\nG90\nG1 X10 Y10 F3000\nG1 X1.2.3 Y10\nG1 X20 Y20\n';
  await upload('malformed.gcode', Buffer.from(bad));
  await waitForStatus('error', 'malformed.gcode');
  const errText = await byTestId('error').textContent();
  assert.match(errText, /line 4/i, `error should name line 4: ${errText}`);
  await byTestId('opt-strict').uncheck();
  await waitForStatus('ready', 'malformed.gcode'); // the option change re-runs it, leniently
  assert.ok((await reportJson()).warnings.length > 0, 'lenient mode should warn about the malformed line');

  // A good file still works afterwards.
  await upload('demo-again.gcode', fs.readFileSync(path.join(wwwRoot, 'demo', 'demo.gcode')));
  await waitForStatus('ready', 'demo-again.gcode');
  assert.ok((await reportJson()).layers > 0);
  assert.equal(await byTestId('error').isVisible(), false);
});

test('cancel stops a run and the next file still works', async (t) => {
  await uploadPath(path.join(corpusDir, 'curaengine-4.13.0_extruder-idler-x2.5_large.gcode'));
  // The run may finish before we get to click; either way the page must recover.
  if (await byTestId('cancel').isEnabled()) await byTestId('cancel').click({ timeout: 1_000 }).catch(() => {});
  await page.waitForFunction(() => ['cancelled', 'ready'].includes(document.querySelector('[data-testid="status"]').textContent));
  const outcome = await byTestId('status').textContent();
  t.diagnostic(`the 34 MB run ended as: ${outcome}`);
  if (outcome === 'cancelled') assert.equal(await byTestId('cancel').isDisabled(), true);
  await uploadPath(path.join(corpusDir, BENCHY));
  await waitForStatus('ready', BENCHY);
  assert.ok(Math.abs((await reportJson()).layers - 160) <= 1);
});

test('the report JSON can be downloaded', async () => {
  const [download] = await Promise.all([page.waitForEvent('download'), byTestId('download').click()]);
  const file = await download.path();
  const json = JSON.parse(fs.readFileSync(file, 'utf8'));
  assert.ok(Math.abs(json.layers - 160) <= 1);
  assert.match(download.suggestedFilename(), /\.json$/);
});

test('dropping a file on the page analyzes it', async () => {
  await page.evaluate(() => {
    const dt = new DataTransfer();
    dt.items.add(new File(['G21\nG90\nM82\nG1 Z0.2 F600\nG1 X10 Y10 E1 F1200\nG1 X20 E2\n'], 'dropped.gcode', { type: 'text/plain' }));
    document.body.dispatchEvent(new DragEvent('dragenter', { dataTransfer: dt, bubbles: true, cancelable: true }));
    if (!document.body.classList.contains('dragging')) throw new Error('no drop overlay on dragenter');
    document.body.dispatchEvent(new DragEvent('drop', { dataTransfer: dt, bubbles: true, cancelable: true }));
  });
  await waitForStatus('ready', 'dropped.gcode');
  const report = await reportJson();
  assert.ok(report.moves >= 2, `moves = ${report.moves}`);
  assert.equal(await page.evaluate(() => document.body.classList.contains('dragging')), false);
});

test('a crashing worker is reported and replaced', async () => {
  // A second tab whose first worker throws on its first message (standing in
  // for a wasm panic); every later worker request gets the real worker.js.
  const tab = await context.newPage();
  tab.setDefaultTimeout(STEP_TIMEOUT);
  let served = 0;
  await tab.route('**/worker.js', async (route) => {
    if (served++ > 0) return route.fallback();
    await route.fulfill({
      status: 200,
      contentType: 'text/javascript',
      body: "self.postMessage({ type: 'hello', version: 'crashy' });\n" +
        "self.onmessage = () => { throw new Error('simulated worker crash'); };\n",
    });
  });
  await tab.goto(baseUrl);
  await tab.waitForFunction(() => document.querySelector('[data-testid="status"]').textContent === 'error');
  const text = await tab.locator('[data-testid="error"]').textContent();
  assert.match(text, /crash/i, `error text: ${text}`);
  await tab.locator('[data-testid="file"]').setInputFiles(path.join(wwwRoot, 'demo', 'demo.gcode'));
  await tab.waitForFunction(() => document.querySelector('[data-testid="status"]').textContent === 'ready');
  assert.ok(JSON.parse(await tab.locator('[data-testid="report-json"]').textContent()).layers > 0);
  assert.ok(served >= 2, 'the worker was not recreated');
  await tab.close();
});

test('no request leaves 127.0.0.1', async () => {
  assert.ok(requests.length > 0, 'no requests were recorded');
  const outside = requests.filter((u) => {
    if (u.startsWith('blob:') || u.startsWith('data:')) return false;
    const { hostname } = new URL(u);
    return hostname !== '127.0.0.1';
  });
  assert.deepEqual(outside, [], 'requests left the machine');
  assert.ok(requests.some((u) => u.endsWith('.wasm')), 'the wasm module was never requested');
  assert.deepEqual(pageErrors, [], 'uncaught page errors');
});

// Status a file's run ends in: whichever of ready/error the page settles on.
async function settledStatus(name) {
  const handle = await page.waitForFunction(
    (n) => {
      const st = document.querySelector('[data-testid="status"]')?.textContent;
      const fn = document.querySelector('[data-testid="filename"]')?.textContent;
      return fn === n && (st === 'ready' || st === 'error') ? st : false;
    },
    name,
    { timeout: STEP_TIMEOUT },
  );
  return handle.jsonValue();
}

async function assertReadableOutcome() {
  const status = await byTestId('status').textContent();
  if (status === 'error') {
    const text = (await byTestId('error').textContent()).trim();
    assert.ok(text.length > 8, `error message too short: "${text}"`);
    assert.doesNotMatch(text, /unreachable|RuntimeError|\[object /i, `error is not readable: ${text}`);
  } else {
    assert.equal(status, 'ready');
    const report = await reportJson();
    assert.ok(Array.isArray(report.warnings), 'report.warnings should be an array');
  }
}
