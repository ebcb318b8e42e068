// Times a job (VTG or the infill search) on a file in the playground's worker, in Debian's
// Chromium, with default options: the figures the VTG and infill issues' browser bars are about.
// Also samples the memory of Chromium's processes (their PSS) every 200 ms: the peak while the
// file loads, what they hold once it is loaded, and the peak while the job runs.
// Needs www/pkg (make pkg) and /usr/bin/chromium.
//
//   node scripts/browser-job-time.mjs part.gcode [vtg|infill]
import { chromium } from 'playwright-core';
import { startServer } from './serve.mjs';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
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

/**
 * Memory of every Chromium process, in MB: the sum of their proportional set sizes (PSS, from
 * /proc/PID/smaps_rollup), which counts a page shared by n processes as 1/n in each, where a
 * sum of resident sizes would count the browser's shared libraries once per process.
 */
function chromiumRssMb() {
  const pids = execFileSync('ps', ['-C', 'chromium', '-o', 'pid='], { encoding: 'utf8' }).split('\n').filter(Boolean);
  let kb = 0;
  for (const pid of pids) {
    try {
      const m = /^Pss:\s+(\d+) kB/m.exec(readFileSync(`/proc/${pid.trim()}/smaps_rollup`, 'utf8'));
      kb += m ? Number(m[1]) : 0;
    } catch { /* the process ended */ }
  }
  return kb / 1024;
}
let peakMb = 0;
const sampler = setInterval(() => { try { peakMb = Math.max(peakMb, chromiumRssMb()); } catch { /* between processes */ } }, 200);

await page.goto(baseUrl);
const st = () => page.locator('[data-testid="status"]').textContent();
await page.waitForFunction(() => document.querySelector('[data-testid="status"]').textContent === 'ready');
await page.locator('[data-testid="file"]').setInputFiles(process.argv[2]);
const name = path.basename(process.argv[2]);
await page.waitForFunction((n) => document.querySelector('[data-testid="filename"]').textContent === n && document.querySelector('[data-testid="status"]').textContent === 'ready', name);
const loadedMb = Math.round(chromiumRssMb());
const loadPeakMb = Math.round(peakMb);
peakMb = 0;
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
const threads = Number(await page.evaluate(() => document.body.dataset.threads ?? '1'));
console.log(JSON.stringify({ job, secs, threads, status: await st(), chromium_load_peak_mb: loadPeakMb, chromium_loaded_mb: loadedMb, chromium_job_peak_mb: Math.round(peakMb), ...summary }));
await browser.close();
server.close();
