// The npm package as a user meets it: package.json metadata, the three builds agreeing, the
// Session API, and the TypeScript declarations checked by tsc against real CLI output.
// Needs `make pkg` and `make cli` (make test does both).

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
const demo = fs.readFileSync(path.join(repoRoot, 'www', 'demo', 'demo.gcode'));
const cli = path.join(repoRoot, 'target', 'release', 'quietpath');
const tsc = path.join(repoRoot, 'node_modules', '.bin', 'tsc');

const manifest = JSON.parse(fs.readFileSync(path.join(pkgDir, 'package.json'), 'utf8'));
const node = await import(pathToFileURL(path.join(pkgDir, 'node', 'quietpath.js')).href);
const web = await import(pathToFileURL(path.join(pkgDir, 'web', 'quietpath.js')).href);
web.initSync({ module: fs.readFileSync(path.join(pkgDir, 'web', 'quietpath_bg.wasm')) });

test('package.json: name, licence, repository, keywords, types and conditional exports', () => {
  assert.equal(manifest.name, 'quietpath');
  assert.equal(manifest.license, 'MIT OR Apache-2.0');
  assert.match(manifest.repository.url, /github\.com/);
  assert.ok(manifest.keywords.includes('gcode'));
  const cargo = fs.readFileSync(path.join(repoRoot, 'Cargo.toml'), 'utf8');
  assert.equal(manifest.version, cargo.match(/^version = "([^"]+)"/m)[1]);
  for (const target of ['web', 'node', 'bundler']) {
    for (const f of ['quietpath.js', 'quietpath.d.ts', 'quietpath_bg.wasm']) {
      assert.ok(fs.existsSync(path.join(pkgDir, target, f)), `${target}/${f}`);
    }
  }
  assert.ok(fs.existsSync(path.join(pkgDir, manifest.types)));
  assert.equal(manifest.exports['.'].node, './node/quietpath.js');
  assert.equal(manifest.exports['./web'].default, './web/quietpath.js');
});

test('`import "quietpath"` resolves to the Node build through the exports map', () => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'qp-import-'));
  fs.mkdirSync(path.join(dir, 'node_modules'));
  fs.symlinkSync(pkgDir, path.join(dir, 'node_modules', 'quietpath'), 'dir');
  fs.writeFileSync(
    path.join(dir, 'probe.mjs'),
    "import { analyze, version } from 'quietpath';\nconsole.log(JSON.stringify({ v: version(), moves: analyze('M83\\nG1 X1 E1 F60\\n').moves }));\n",
  );
  fs.writeFileSync(path.join(dir, 'probe.cjs'), "const q = require('quietpath');\nconsole.log(q.analyze('G1 X2 F60\\n').moves);\n");
  const esm = JSON.parse(execFileSync(process.execPath, ['probe.mjs'], { cwd: dir, encoding: 'utf8' }));
  assert.deepEqual(esm, { v: manifest.version, moves: 1 });
  assert.equal(execFileSync(process.execPath, ['probe.cjs'], { cwd: dir, encoding: 'utf8' }).trim(), '1');
  fs.rmSync(dir, { recursive: true, force: true });
});

test('the web and Node builds give the same report', () => {
  assert.deepEqual(web.analyze(demo), node.analyze(demo));
});

test('Session: layers to draw, as typed arrays that agree with the report', () => {
  const s = new node.Session(demo);
  const report = s.analyze();
  assert.deepEqual(report, node.analyze(demo));
  assert.equal(s.bytes, demo.length);
  assert.equal(s.layerCount(), report.layers);
  let extruded = 0;
  for (let i = 0; i < s.layerCount(); i++) {
    const g = s.layer(i);
    assert.ok(g.xy instanceof Float32Array && g.kind instanceof Uint8Array);
    assert.equal(g.xy.length, 4 * g.kind.length);
    assert.equal(g.speed.length, g.kind.length);
    assert.equal(g.curvature.length, g.kind.length);
    assert.ok(g.tool instanceof Float32Array && g.tool.length === 0, 'a 3-axis file has no tool vectors');
    assert.ok(g.xyz instanceof Float32Array && g.xyz.length === 0, 'nor a workpiece-frame path');
    for (let k = 0; k < g.kind.length; k++) {
      if (g.kind[k] !== 0) extruded += Math.hypot(g.xy[4 * k + 2] - g.xy[4 * k], g.xy[4 * k + 3] - g.xy[4 * k + 1]);
    }
    assert.ok(g.speed.every((v) => v > 0 && v < 1000));
  }
  // f32 drawing coordinates and arc chords: within 0.1 % of the report's extrusion length.
  assert.ok(Math.abs(extruded - report.extrude_distance_mm) / report.extrude_distance_mm < 1e-3, `${extruded} vs ${report.extrude_distance_mm}`);
  assert.equal(s.layer(1e6).kind.length, 0);
  s.free();
});

test('Session: a 5-axis file carries unit tool vectors (tip and direction, workpiece frame)', () => {
  const s = new node.Session(fs.readFileSync(path.join(corpusDir, 'multiaxis-xyzbc_zhang-ral2021_model1.gcode')));
  let vectors = 0;
  for (let i = 0; i < s.layerCount(); i++) {
    const g = s.layer(i);
    const t = g.tool;
    assert.ok(t instanceof Float32Array && t.length % 6 === 0);
    for (let o = 0; o < t.length; o += 6) assert.ok(Math.abs(Math.hypot(t[o + 3], t[o + 4], t[o + 5]) - 1) < 1e-5);
    // The path in the workpiece frame, parallel to xy; each tip is an extruding segment's end.
    assert.equal(g.xyz.length, 6 * g.kind.length);
    const ends = new Set();
    for (let k = 0; k < g.kind.length; k++) if (g.kind[k] !== 0) ends.add(`${g.xyz[6 * k + 3]},${g.xyz[6 * k + 4]},${g.xyz[6 * k + 5]}`);
    for (let o = 0; o < t.length; o += 6) assert.ok(ends.has(`${t[o]},${t[o + 1]},${t[o + 2]}`), `layer ${i}: tip ${t.slice(o, o + 3)} on the path`);
    vectors += t.length / 6;
  }
  assert.ok(vectors > 1000, `${vectors} tool vectors`);
  s.free();
});

test('Session: analyze with the timing side apart (readApart → TimingApart → reportApart) gives analyze\'s report', () => {
  // What the playground does in two workers, here in one: the batches and the results cross
  // as bytes, so the report must be the same to the bit. An arc-welded file (G2/G3 moves) and
  // a Klipper-driven one (limits set in the file); the second with a user's machine profile.
  for (const [name, options] of [
    ['prusaslicer-2.7.4_screw_arcfit.gcode', {}],
    ['superslicer-2.3.56_klipper_arcwelder.gcode', { machine: 'voron-klipper' }],
  ]) {
    const s = new node.Session(fs.readFileSync(path.join(corpusDir, name)), options);
    const timing = new node.TimingApart();
    let batches = 0;
    const read = s.readApart(undefined, (batch) => {
      assert.ok(batch instanceof Uint8Array && batch.byteOffset === 0 && batch.byteLength === batch.buffer.byteLength, 'a batch is a whole, transferable buffer');
      batches++;
      timing.feed(batch);
    });
    const report = s.reportApart(read, timing.finish());
    assert.ok(batches >= 1, name);
    assert.deepEqual(report, s.analyze(), name);
    assert.throws(() => s.reportApart(read, new Uint8Array()), /reported already/);
    assert.throws(() => new node.TimingApart().feed(new Uint8Array([0, 1, 2])), (e) => e instanceof Error && e.kind.kind === 'transfer');
    read.free();
    timing.free();
    s.free();
  }
});

test('Session: a malformed file fails with a line number (strict)', () => {
  const s = new node.Session('G1 X1\nG1 Y1.2.3\n', { strict: true });
  assert.throws(() => s.analyze(), (e) => e instanceof Error && e.line === 2 && e.kind.kind === 'invalid_number');
  assert.throws(() => s.layerCount(), (e) => e instanceof Error && e.line === 2);
});

// The report and option types are generated from the Rust types (crate/src/ts_types.rs); this
// assigns real CLI output to them, so a serde attribute ts-rs reads differently from serde (a
// field left out, renamed, tagged) fails here. An object literal with a field the type lacks
// fails too (excess property check), so the check runs both ways.
test('TypeScript: declarations compile (tsc --strict) and match real CLI output', () => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'qp-types-'));
  // A Klipper file with an untimed homing: the report's optional `homing_count`.
  const klipper = path.join(dir, 'klipper.gcode');
  fs.writeFileSync(klipper, ';FLAVOR:Klipper\nG1 X10 F600\nG28\nG1 X5 F600\n');
  // Rows from known coefficients plus noise, for `calibrate --json`.
  const csv = path.join(dir, 'calibration.csv');
  fs.writeFileSync(
    csv,
    [1, 2, 3, 4, 5, 6, 7, 8].map((x) => [1e4 * x, 3e3 * x * x, x ** 3, 9 - x].concat(1300 * x + 360 * x * x + 70 * x ** 3 + 800 * (9 - x) + (x % 3)).join(',')).join('\n'),
  );
  const reports = [path.join(repoRoot, 'www', 'demo', 'demo.gcode'), path.join(corpusDir, 'prusaslicer-2.7.4_screw_arcfit.gcode'), klipper].map((f) =>
    execFileSync(cli, ['analyze', f, '--json'], { encoding: 'utf8', maxBuffer: 64 << 20 }),
  );
  assert.match(reports[2], /"homing_count": 1/);
  const json = (args) => execFileSync(cli, args, { encoding: 'utf8', maxBuffer: 64 << 20, stdio: ['ignore', 'pipe', 'ignore'] }).trim();
  const typed = [
    ['VibrationReport', json(['vibration', path.join(repoRoot, 'www', 'demo', 'demo.gcode'), '--json'])],
    ['VtgReport', json(['vtg', path.join(repoRoot, 'www', 'demo', 'demo.gcode'), '-o', path.join(dir, 'vtg.gcode'), '--json'])],
    ['InfillReport', json(['infill', path.join(repoRoot, 'www', 'demo', 'demo.gcode'), '-o', path.join(dir, 'infill.gcode'), '--angles', '0:90:90', '--json'])],
    ['SmoothReport', json(['smooth', path.join(corpusDir, 'multiaxis-xyzbc_zhang-ral2021_model1.gcode'), '-o', path.join(dir, 'smooth.gcode'), '--kinematics', 'table-bc', '--json'])],
    ['InfillReport', json(['infill', path.join(repoRoot, 'www', 'demo', 'demo.gcode'), '-o', path.join(dir, 'infill-layers.gcode'), '--angles', '0:90:90', '--per-layer', '--json'])],
    ['OptimizeReport', json(['optimize', path.join(repoRoot, 'www', 'demo', 'demo.gcode'), '-o', path.join(dir, 'optimize.gcode'), '--json'])],
    ['CalibrationFit', json(['calibrate', csv, '--json'])],
    ['MachineProfile[]', JSON.stringify(node.machines())],
  ];
  const api = path.join(pkgDir, 'web', 'quietpath.js').replaceAll('\\', '/');
  const src = [
    `import init, { analyze, calibrate, machines, optimize, Session, version, vibration, smooth, infill, vtg } from '${api}';`,
    `import type { Report, AnalyzeOptions, LayerGeometry, CalibrationFit, QuietpathError, VibrationResult, MachineProfile, VibrationReport, VtgReport, InfillReport, SmoothReport, OptimizeReport, OptimizeOptions } from '${api}';`,
    'export async function use(bytes: Uint8Array): Promise<number> {',
    '  await init();',
    "  const options: AnalyzeOptions = { strict: true, machine: 'prusa-mk3s', junction_model: 'klipper' };",
    '  const r: Report = analyze(bytes, options, (f: number) => f < 2);',
    '  const s = new Session(bytes);',
    '  const g: LayerGeometry = s.layer(0);',
    "  const fit: CalibrationFit = calibrate([[1, 2, 3, 4, 5]]);",
    "  const vr: VibrationResult = vibration(bytes, { ts_ms: 1, window: 256 }, () => true);",
    "  const spectrum: Float64Array = vr.psd.power;",
    "  const sr = smooth(bytes, { cone_deg: 60, window: { millimetres: 5 } });",
    "  const smoothed: Uint8Array = sr.output;",
    "  const vr2 = vtg(bytes, { tolerance_mm: 0.05, limit_feed: false, dynamics: false, allow_slower_pct: 0.5 });",
    "  const turning: number = vr2.table1.n_turning.change_pct + (vr2.table2.deviation?.mean_mm.after ?? 0) + vr2.output.length;",
    "  const ir = infill(bytes, { angles_deg: [0, 90], patterns: ['rectilinear', 'hilbert'], objective: 'time' });",
    "  const best: string = ir.best.pattern + ir.candidates[0].total_j + ir.output.length;",
    "  const sv: VibrationResult = s.vibration({ analyze: { machine: 'vtg-ldam-servo' } });",
    "  const oo: OptimizeOptions = { infill: { per_layer: true }, vtg_options: { tolerance_mm: 0.05 }, arcs: 'off', analyze: { energy: { thesis: { k_c: 70 }, material: 'petg' }, klipper_config: '[printer]\\nmax_accel: 3000\\n' } };",
    "  const or = optimize(bytes, oo);",
    "  const profiles: MachineProfile[] = machines();",
    "  try { analyze('G1 X1.2.3'); } catch (e) { const err = e as QuietpathError; return (err.kind?.kind === 'invalid_number' ? err.kind.letter.length : 0) + (err.line ?? 0); }",
    '  return r.time_s + g.xy.length + g.xyz.length + g.tool.length + fit.k_c + version().length + s.layerCount() + vr.psd.freqs.length + spectrum.length + smoothed.length + sv.steps + sr.corrected + best.length + turning + or.stages.length + or.output.length + profiles[0].limits.acceleration.value;',
    '}',
    ...reports.map((json, i) => `export const report${i}: Report = ${json.trim()};`),
    ...typed.map(([t, json], i) => `export const typed${i}: ${t} = ${json};`),
    '',
  ].join('\n');
  fs.writeFileSync(path.join(dir, 'check.ts'), src);
  try {
    execFileSync(tsc, ['--noEmit', '--strict', '--target', 'es2022', '--lib', 'esnext,dom', '--module', 'nodenext', '--moduleResolution', 'nodenext', '--skipLibCheck', 'false', 'check.ts'], {
      cwd: dir,
      encoding: 'utf8',
    });
  } catch (e) {
    assert.fail(`tsc rejected the declarations or a real report:\n${e.stdout}${e.stderr}`);
  }
  fs.rmSync(dir, { recursive: true, force: true });
});
