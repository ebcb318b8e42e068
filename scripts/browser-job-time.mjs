// Times a job (VTG or the infill search) on a file in the playground's worker, in Debian's
// Chromium, with default options: the figures the VTG and infill issues' browser bars are about.
// Also samples the resident memory of Chromium's processes every 200 ms and prints the peak.
// Needs www/pkg (make pkg) and /usr/bin/chromium.
//
//   node scripts/browser-job-time.mjs part.gcode [vtg|infill]
import { chromium } from 'playwright-core';
import { startServer } from './serve.mjs';
import { execFileSync } from 'node:child_process';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const job = process.argv[3] ?? 'infill';
if (!['vtg', 'infill'].includes(job)) throw new Error(`unknown job ${job}: vtg or infill`);
const repoRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const server = await startServer({ root: path.join(repoRoot, 'www'), port: 0 });
const baseUrl = `http://127.0.0.1:${server.address().port}/`;
const browser = await chromium.launch({ executablePath: '/usr/bin/chromium', args: ['--headless', '--no-sandbox', '--disable-gpu'] });
const page = await (await browser.newContext({ viewport: { width: 1280, height: 900 } })).newPage();
page.setDefaultTimeout(900_000);

/** Resident memory of every Chromium process, in MB (ps over the process list). */
function chromiumRssMb() {
  const out = execFileSync('ps', ['-C', 'chromium', '-o', 'rss='], { encoding: 'utf8' });
  return out.split('\n').filter(Boolean).reduce((sum, kb) => sum + Number(kb), 0) / 1024;
}
let peakMb = 0;
const sampler = setInterval(() => { try { peakMb = Math.max(peakMb, chromiumRssMb()); } catch { /* between processes */ } }, 200);

await page.goto(baseUrl);
const st = () => page.locator('[data-testid="status"]').textContent();
await page.waitForFunction(() => document.querySelector('[data-testid="status"]').textContent === 'ready');
await page.locator('[data-testid="file"]').setInputFiles(process.argv[2]);
const name = path.basename(process.argv[2]);
await page.waitForFunction((n) => document.querySelector('[data-testid="filename"]').textContent === n && document.querySelector('[data-testid="status"]').textContent === 'ready', name);
const t0 = Date.now();
await page.locator(`[data-testid="run-${job}"]`).click();
await page.waitForFunction(() => document.body.classList.contains('busy'));
await page.waitForFunction(() => !document.body.classList.contains('busy'));
const secs = (Date.now() - t0) / 1000;
clearInterval(sampler);
const rep = JSON.parse(await page.locator('[data-testid="report-json"]').textContent());
const summary = job === 'infill'
  ? { best: rep.best?.pattern, angle: rep.best?.angle_deg, total_j: rep.best?.total_j }
  : { message: rep.message ?? null, output_bytes: rep.output_bytes ?? null, corners: rep.table1?.n_turning };
console.log(JSON.stringify({ job, secs, status: await st(), chromium_peak_mb: Math.round(peakMb), ...summary }));
await browser.close();
server.close();
