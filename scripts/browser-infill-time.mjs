// Times the infill search on a file in the playground's worker, in Debian's Chromium: the
// figure the infill issue's 90 s bar is about. Needs www/pkg (make pkg) and /usr/bin/chromium.
//
//   node scripts/browser-infill-time.mjs part.gcode
import { chromium } from 'playwright-core';
import { startServer } from './serve.mjs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
const repoRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const server = await startServer({ root: path.join(repoRoot, 'www'), port: 0 });
const baseUrl = `http://127.0.0.1:${server.address().port}/`;
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: ['--headless', '--no-sandbox', '--disable-gpu'] });
const page = await (await browser.newContext({ viewport: { width: 1280, height: 900 } })).newPage();
page.setDefaultTimeout(600_000);
await page.goto(baseUrl);
const st = () => page.locator('[data-testid="status"]').textContent();
await page.waitForFunction(() => document.querySelector('[data-testid="status"]').textContent === 'ready');
await page.locator('[data-testid="file"]').setInputFiles(process.argv[2]);
const name = path.basename(process.argv[2]);
await page.waitForFunction((n) => document.querySelector('[data-testid="filename"]').textContent === n && document.querySelector('[data-testid="status"]').textContent === 'ready', name);
const t0 = Date.now();
await page.locator('[data-testid="run-infill"]').click();
await page.waitForFunction(() => document.body.classList.contains('busy'));
await page.waitForFunction(() => !document.body.classList.contains('busy'));
const secs = (Date.now() - t0) / 1000;
const rep = JSON.parse(await page.locator('[data-testid="report-json"]').textContent());
console.log(JSON.stringify({ secs, status: await st(), best: rep.best?.pattern, angle: rep.best?.angle_deg, total_j: rep.best?.total_j }));
await browser.close();
server.close();
