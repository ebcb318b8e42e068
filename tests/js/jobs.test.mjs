// The optimisers and the dynamics report through the npm package (Node build) against the
// native CLI on the same files: the JSON must be identical, and the rewritten file byte for
// byte the file the CLI writes. Needs `make pkg` and `make cli`.

import { test } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath, pathToFileURL } from 'node:url';

const repoRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const pkgDir = path.resolve(process.env.QUIETPATH_PKG ?? path.join(repoRoot, 'pkg'));
const corpusDir = path.resolve(repoRoot, '../shared/corpus');
const cli = path.join(repoRoot, 'target', 'release', 'quietpath');
const qp = await import(pathToFileURL(path.join(pkgDir, 'node', 'quietpath.js')).href);
const tmp = fs.mkdtempSync(path.join(os.tmpdir(), 'qp-jobs-'));

const DEMO = path.join(repoRoot, 'www', 'demo', 'demo.gcode');
const FIVE_AXIS = path.join(corpusDir, 'multiaxis-xyzbc_zhang-ral2021_model1.gcode');

function runCli(args) {
  return JSON.parse(execFileSync(cli, args, { encoding: 'utf8', maxBuffer: 256 << 20, stdio: ['ignore', 'pipe', 'ignore'] }));
}

// The JS result without the output bytes, as plain JSON.
function reportOf(result) {
  const { output, ...report } = result;
  return { report: JSON.parse(JSON.stringify(report)), output };
}

// Paths where `a` and `b` differ: structure exactly, numbers within `rel` relative error (or
// 1e-12 absolute, for values that are zero up to rounding, such as a minimum deviation).
function diffs(a, b, rel, at = '$', out = []) {
  if (typeof a === 'number' && typeof b === 'number') {
    if (Math.abs(a - b) > rel * Math.max(Math.abs(a), Math.abs(b)) + 1e-12) out.push(`${at}: ${a} vs ${b}`);
  } else if (a && b && typeof a === 'object' && typeof b === 'object') {
    const keys = new Set([...Object.keys(a), ...Object.keys(b)]);
    for (const k of keys) diffs(a[k], b[k], rel, `${at}.${k}`, out);
  } else if (a !== b) {
    out.push(`${at}: ${JSON.stringify(a)} vs ${JSON.stringify(b)}`);
  }
  return out;
}

test('vibration: wasm report equals `quietpath vibration --json` (numbers to 1e-9)', () => {
  const fromCli = runCli(['vibration', DEMO, '--json']);
  const result = qp.vibration(fs.readFileSync(DEMO));
  assert.ok(result.psd.freqs instanceof Float64Array && result.psd.power instanceof Float64Array);
  const fromWasm = JSON.parse(JSON.stringify(result, (_k, v) => (ArrayBuffer.isView(v) ? Array.from(v) : v)));
  // Not bit for bit: nalgebra's eigenvalue solver and matrix exponential and rustfft's twiddle
  // factors call the platform's libm (glibc natively, Rust's libm in wasm), which differ in the
  // last bit; the simulation carries that to about 1e-13.
  assert.deepEqual(diffs(fromWasm, fromCli, 1e-9), []);
  assert.ok(fromWasm.psd.freqs.length > 100 && fromWasm.deviation_mm.mean > 0);
});

test('smooth: wasm report and output equal the CLI on the 5-axis corpus file', () => {
  const out = path.join(tmp, 'smooth.gcode');
  const fromCli = runCli(['smooth', FIVE_AXIS, '-o', out, '--kinematics', 'table-bc', '--json']);
  const { report, output } = reportOf(qp.smooth(fs.readFileSync(FIVE_AXIS), { filter: 'zero-phase-moving-average' }));
  assert.deepEqual(report, fromCli);
  assert.ok(output instanceof Uint8Array);
  assert.ok(Buffer.from(output).equals(fs.readFileSync(out)), 'smoothed file differs from the CLI output');
  assert.ok(report.max_angle_to_original_deg <= report.cone_deg / 2);
});

test('vtg: wasm report and output equal the CLI (dynamics rows to 1e-9)', () => {
  const out = path.join(tmp, 'vtg.gcode');
  const fromCli = runCli(['vtg', DEMO, '-o', out, '--json']);
  const { report, output } = reportOf(qp.vtg(fs.readFileSync(DEMO)));
  // Only Table 2's deviation rows come from the dynamics model (see the vibration test).
  const { deviation: devWasm, ...t2Wasm } = report.table2;
  const { deviation: devCli, ...t2Cli } = fromCli.table2;
  assert.deepEqual({ ...report, table2: t2Wasm }, { ...fromCli, table2: t2Cli });
  // (Their change_pct, a difference of near-equal numbers, amplifies the last-bit noise.)
  const values = (d) => Object.fromEntries(Object.entries(d).map(([k, c]) => [k, [c.before, c.after]]));
  assert.deepEqual(diffs(values(devWasm), values(devCli), 1e-9), []);
  assert.ok(Buffer.from(output).equals(fs.readFileSync(out)), 'rewritten file differs from the CLI output');
  assert.ok(report.max_deviation_mm <= report.tolerance_mm);
  assert.ok(report.table1.n_turning.after < report.table1.n_turning.before);
});

test('vtg allow_slower_pct: wasm equals the CLI, and an out-of-range value is an Error', () => {
  const out = path.join(tmp, 'vtg-slower.gcode');
  const fromCli = runCli(['vtg', DEMO, '-o', out, '--allow-slower', '1', '--no-dynamics', '--json']);
  const { report, output } = reportOf(qp.vtg(fs.readFileSync(DEMO), { allow_slower_pct: 1, dynamics: false }));
  assert.deepEqual(report, fromCli);
  assert.ok(Buffer.from(output).equals(fs.readFileSync(out)), 'rewritten file differs from the CLI output');
  assert.ok(report.after.time_s <= report.before.time_s * 1.01, 'the allowance holds on the whole file');
  assert.throws(() => qp.vtg(fs.readFileSync(DEMO), { allow_slower_pct: 150 }), (e) => e instanceof Error && /allow_slower_pct/.test(e.message));
});

test('vtg inside_corners: wasm equals the CLI, and the output differs from the racing line', () => {
  // The thesis triangle: its corners have the room a racing line needs (the demo's do not,
  // and it comes out the same either way).
  const triangle = path.join(repoRoot, 'tests', 'fixtures', 'gcode', 'prusaslicer-2.5.0_thesis_triangle.gcode');
  const out = path.join(tmp, 'vtg-inside.gcode');
  // Lines allowed: by default the triangle's corners would add lines, and stay sharp.
  const fromCli = runCli(['vtg', triangle, '-o', out, '--inside-corners', '--no-dynamics', '--allow-more-lines', '1000', '--json']);
  const { report, output } = reportOf(qp.vtg(fs.readFileSync(triangle), { inside_corners: true, dynamics: false, allow_more_lines_pct: 1000 }));
  assert.deepEqual(report, fromCli);
  assert.ok(Buffer.from(output).equals(fs.readFileSync(out)), 'rewritten file differs from the CLI output');
  const racing = reportOf(qp.vtg(fs.readFileSync(triangle), { dynamics: false, allow_more_lines_pct: 1000 }));
  assert.ok(!Buffer.from(racing.output).equals(Buffer.from(output)), 'inside corners changed nothing');
  assert.ok(racing.report.paths.keyholes < report.paths.keyholes, 'the racing line rounds tips the inside line loops');
  assert.ok(report.max_deviation_mm <= report.tolerance_mm);
});

test('infill: wasm report and output equal the CLI (angles 0/45/90, two patterns)', () => {
  const out = path.join(tmp, 'infill.gcode');
  const fromCli = runCli(['infill', DEMO, '-o', out, '--angles', '0,45,90', '--patterns', 'rectilinear,grid', '--json']);
  const { report, output } = reportOf(
    qp.infill(fs.readFileSync(DEMO), { angles_deg: [0, 45, 90], patterns: ['rectilinear', 'grid'] }),
  );
  assert.deepEqual(report, fromCli);
  assert.equal(report.candidates.length, 6);
  assert.ok(Buffer.from(output).equals(fs.readFileSync(out)), 'rewritten file differs from the CLI output');
  // The output is a file analyze reads, with the material of the input (±10 %).
  const after = qp.analyze(output);
  assert.ok(Math.abs(after.filament_mm / report.before.filament_mm - 1) < 0.1);
});

test('optimize: wasm report and output equal the CLI (VTG without dynamics, estimates)', () => {
  const out = path.join(tmp, 'optimize.gcode');
  const fromCli = runCli(['optimize', DEMO, '-o', out, '--no-dynamics', '--json']);
  const { report, output } = reportOf(qp.optimize(fs.readFileSync(DEMO), { vtg_options: { dynamics: false } }));
  assert.deepEqual(report, fromCli);
  assert.ok(Buffer.from(output).equals(fs.readFileSync(out)), 'optimised file differs from the CLI output');
  assert.deepEqual(report.stages.map((s) => s.stage), ['vtg', 'estimates']);
  // Never dearer than the input, and the file's own estimate is the planner's.
  assert.ok(report.after.time_s <= report.before.time_s && report.after.energy.total_j <= report.before.energy.total_j);
  assert.equal(qp.analyze(output).time_s, report.after.time_s);
});

test('Session jobs use the session analyze options unless the job names its own', () => {
  const bytes = fs.readFileSync(DEMO);
  const s = new qp.Session(bytes, { machine: 'vtg-ldam-servo' });
  assert.equal(s.vibration().machine, 'vtg-ldam-servo');
  assert.equal(s.vibration({ analyze: { machine: 'creality-ender3' } }).machine, 'creality-ender3');
  s.free();
});

test('job errors are Errors with a kind; bad options are refused', () => {
  assert.throws(() => qp.vibration('G1 X1\n', { ts_ms: -1 }), (e) => e instanceof Error && /ts_ms|option/i.test(e.message));
  assert.throws(() => qp.smooth('G1 X1\n', { nonsense: 1 }), (e) => e instanceof Error && /nonsense|unknown field/i.test(e.message));
  assert.throws(() => qp.vibration('G1 X1.2.3\n', { analyze: { strict: true } }), (e) => e instanceof Error && e.line === 1);
});

test('cancelling a job through the progress callback throws a cancelled error', () => {
  assert.throws(
    () => qp.vibration(fs.readFileSync(DEMO), {}, () => false),
    (e) => e instanceof Error && e.kind?.kind === 'cancelled',
  );
});
