// Tests of the npm package's JavaScript API: the Node build (pkg/node, what
// `import 'quietpath'` gives in Node) for everything, and the web build
// (pkg/web, loaded with initSync) for agreement. Run with `npm test` or
// `node --test tests/js/`. Needs pkg/ built and the corpus in ../shared/corpus.

import { test, describe } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import path from 'node:path';
import { execFileSync } from 'node:child_process';
import { fileURLToPath, pathToFileURL } from 'node:url';

const repoRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
// QUIETPATH_PKG points at another build of the package (default: pkg/).
const pkgDir = path.resolve(process.env.QUIETPATH_PKG ?? path.join(repoRoot, 'pkg'));
const corpusDir = path.resolve(repoRoot, '../shared/corpus');
const demoFile = path.join(repoRoot, 'www', 'demo', 'demo.gcode');

const BENCHY = 'prusaslicer-2.6.1_benchy_marlin2.gcode';
const CURA_LEGACY = 'cura-legacy-15.x_fabtotum_socket-screwdriver.gcode';
// Files compared with the CLI. The core routes every transcendental function through the
// pure-Rust libm (crate::math), so native and wasm reports are bit-identical, arcs included.
const CLI_FILES = [
  { name: BENCHY, exact: true },
  { name: CURA_LEGACY, exact: true },
  { name: 'prusaslicer-2.7.4_screw_arcfit.gcode', exact: true },
];

for (const f of ['package.json', 'node/quietpath.js', 'web/quietpath.js', 'web/quietpath_bg.wasm']) {
  if (!fs.existsSync(path.join(pkgDir, f))) {
    throw new Error(
      `${path.join(pkgDir, f)} is missing: build it first with ` +
        '`make pkg`',
    );
  }
}
if (!fs.existsSync(corpusDir)) {
  throw new Error(`corpus not found at ${corpusDir} (shared/ must sit next to the repository)`);
}

const qp = await import(pathToFileURL(path.join(pkgDir, 'node', 'quietpath.js')).href);
const web = await import(pathToFileURL(path.join(pkgDir, 'web', 'quietpath.js')).href);
web.initSync({ module: fs.readFileSync(path.join(pkgDir, 'web', 'quietpath_bg.wasm')) });

const corpus = (name) => fs.readFileSync(path.join(corpusDir, name));
const corpusFiles = fs
  .readdirSync(corpusDir)
  .filter((f) => /\.(gcode|gco|g)$/i.test(f))
  .sort();

// The report must be plain JSON data: no Map, no undefined, no BigInt.
const jsonRoundTrip = (v) => JSON.parse(JSON.stringify(v));

// Deterministic PRNG (mulberry32) so failures can be reproduced.
function rng(seed) {
  let a = seed >>> 0;
  return () => {
    a = (a + 0x6d2b79f5) >>> 0;
    let t = a;
    t = Math.imul(t ^ (t >>> 15), t | 1);
    t ^= t + Math.imul(t ^ (t >>> 7), t | 61);
    return ((t ^ (t >>> 14)) >>> 0) / 4294967296;
  };
}

function assertReportShape(r, label) {
  assert.equal(typeof r, 'object', `${label}: report is not an object`);
  assert.ok(r !== null, `${label}: report is null`);
  for (const k of ['time_s', 'moves', 'layers', 'distance_mm', 'filament_mm', 'material_g']) {
    assert.equal(typeof r[k], 'number', `${label}: ${k} should be a number, got ${typeof r[k]}`);
    assert.ok(Number.isFinite(r[k]), `${label}: ${k} = ${r[k]} is not finite`);
  }
  // Net filament can be negative for a fragment that retracts more than it extrudes.
  for (const k of ['time_s', 'moves', 'layers', 'distance_mm']) {
    assert.ok(r[k] >= 0, `${label}: ${k} = ${r[k]} is negative`);
  }
  assert.ok(Number.isInteger(r.moves) && Number.isInteger(r.layers), `${label}: moves/layers should be integers`);
  for (const k of ['energy', 'toolpath']) {
    assert.equal(typeof r[k], 'object', `${label}: ${k} should be an object`);
    assert.ok(r[k] !== null && !Array.isArray(r[k]), `${label}: ${k} should be a plain object`);
  }
  assert.ok(Array.isArray(r.warnings), `${label}: warnings should be an array`);
  for (const w of r.warnings) {
    assert.ok(Number.isInteger(w.line) && w.line >= 0, `${label}: warning line ${w.line} (0 = the whole file)`);
    assert.equal(typeof w.message, 'string', `${label}: warning message`);
  }
  assert.equal(typeof r.file, 'object');
  assert.ok(Number.isInteger(r.file.bytes), `${label}: file.bytes`);
  assert.ok(Number.isInteger(r.file.lines), `${label}: file.lines`);
  assert.ok(r.file.slicer === null || typeof r.file.slicer === 'string', `${label}: file.slicer is ${r.file.slicer}`);
  assert.ok('flavor' in r.file, `${label}: file.flavor missing`);
  assert.ok(['absolute', 'relative'].includes(r.extrusion?.mode), `${label}: extrusion.mode = ${r.extrusion?.mode}`);
  assert.ok('source' in r.extrusion, `${label}: extrusion.source missing`);
  assert.ok(Array.isArray(r.features), `${label}: features should be an array`);
  for (const f of r.features) {
    assert.equal(typeof f.name, 'string');
    for (const k of ['distance_mm', 'filament_mm', 'time_s']) assert.equal(typeof f[k], 'number', `${label}: feature ${f.name}.${k}`);
  }
  assert.ok('bounds' in r, `${label}: bounds missing (use null when there is none)`);
  if (r.bounds !== null) {
    assert.equal(r.bounds.min.length, 3);
    assert.equal(r.bounds.max.length, 3);
    for (let i = 0; i < 3; i++) assert.ok(r.bounds.min[i] <= r.bounds.max[i], `${label}: bounds min > max on axis ${i}`);
  }
  assert.deepEqual(jsonRoundTrip(r), r, `${label}: report is not plain JSON data (Map, undefined or BigInt inside?)`);
}

test('version() is a non-empty version string', () => {
  const v = qp.version();
  assert.equal(typeof v, 'string');
  assert.match(v, /^\d+\.\d+\.\d+/);
});

describe('corpus reports', () => {
  test(`${BENCHY}: about 160 layers`, () => {
    const r = qp.analyze(corpus(BENCHY));
    assertReportShape(r, BENCHY);
    assert.ok(Math.abs(r.layers - 160) <= 1, `layers = ${r.layers}, expected 160 ± 1`);
    assert.ok(r.moves > 0);
    assert.ok(r.time_s > 60, `time_s = ${r.time_s}`);
    assert.match(r.file.slicer ?? '', /prusa/i, `slicer = ${r.file.slicer}`);
    assert.equal(r.file.bytes, corpus(BENCHY).length);
    assert.ok(r.features.length > 0, 'PrusaSlicer files have ;TYPE: features');
  });

  test(`${CURA_LEGACY}: filament in metres, not kilometres`, () => {
    const r = qp.analyze(corpus(CURA_LEGACY));
    assertReportShape(r, CURA_LEGACY);
    assert.ok(r.filament_mm > 1000 && r.filament_mm < 100000, `filament_mm = ${r.filament_mm}`);
    assert.ok(r.moves > 0);
  });

  test('every corpus file gives a well-formed report', () => {
    assert.ok(corpusFiles.length >= 3, `only ${corpusFiles.length} corpus files`);
    for (const name of corpusFiles) {
      const buf = corpus(name);
      const r = qp.analyze(buf);
      assertReportShape(r, name);
      assert.equal(r.file.bytes, buf.length, `${name}: file.bytes`);
      assert.ok(r.moves > 0, `${name}: no moves`);
      assert.ok(r.filament_mm > 0 && r.material_g > 0, `${name}: filament_mm = ${r.filament_mm}, material_g = ${r.material_g}`);
    }
  });
});

describe('inputs and options', () => {
  const utf8Files = [demoFile, path.join(corpusDir, BENCHY)].filter((f) => {
    try {
      new TextDecoder('utf-8', { fatal: true }).decode(fs.readFileSync(f));
      return true;
    } catch {
      return false;
    }
  });

  test('string and Uint8Array inputs give the same report', () => {
    assert.ok(utf8Files.length > 0, 'no valid UTF-8 test file');
    for (const f of utf8Files) {
      const buf = fs.readFileSync(f);
      const fromBytes = qp.analyze(new Uint8Array(buf.buffer, buf.byteOffset, buf.length));
      const fromString = qp.analyze(buf.toString('utf8'));
      assert.deepEqual(fromString, fromBytes, path.basename(f));
      // A Node Buffer is a Uint8Array too.
      assert.deepEqual(qp.analyze(buf), fromBytes, `${path.basename(f)} (Buffer)`);
    }
  });

  test('options are optional and accept an empty object', () => {
    const buf = fs.readFileSync(demoFile);
    assert.deepEqual(qp.analyze(buf, {}), qp.analyze(buf));
    assert.deepEqual(qp.analyze(buf, undefined, undefined), qp.analyze(buf));
  });

  test('density scales material_g', () => {
    const buf = fs.readFileSync(demoFile);
    const a = qp.analyze(buf, { density_g_cm3: 1.24 });
    const b = qp.analyze(buf, { density_g_cm3: 2.48 });
    assert.ok(a.material_g > 0);
    assert.ok(Math.abs(b.material_g / a.material_g - 2) < 0.01, `${a.material_g} g → ${b.material_g} g`);
    assert.equal(b.filament_mm, a.filament_mm);
  });

  test('progress callback: fractions in [0, 1], increasing, ending at 1', () => {
    const fractions = [];
    const r = qp.analyze(corpus(BENCHY), {}, (f) => fractions.push(f));
    assert.ok(r.layers > 0);
    assert.ok(fractions.length >= 2, `only ${fractions.length} progress calls`);
    for (const f of fractions) {
      assert.equal(typeof f, 'number');
      assert.ok(f >= 0 && f <= 1, `fraction ${f} out of range`);
    }
    for (let i = 1; i < fractions.length; i++) {
      assert.ok(fractions[i] >= fractions[i - 1], `fractions go backwards at call ${i}: ${fractions[i - 1]} → ${fractions[i]}`);
    }
    assert.equal(fractions.at(-1), 1);
    assert.ok(new Set(fractions).size >= 2, 'progress never moved');
  });

  test('an exception thrown by the progress callback does not break the module', () => {
    const buf = fs.readFileSync(demoFile);
    let threw;
    try {
      qp.analyze(buf, {}, () => {
        throw new Error('stop');
      });
    } catch (e) {
      threw = e;
    }
    if (threw !== undefined) {
      assert.ok(threw instanceof Error, `threw ${threw}`);
      assert.ok(!(threw instanceof WebAssembly.RuntimeError), `wasm trapped: ${threw.message}`);
    }
    // The instance must still work afterwards.
    assert.ok(qp.analyze(buf).layers > 0);
  });
});

describe('errors', () => {
  const bad = 'G21\nG90\nG1 X10 Y10 F3000\nG1 X1.2.3 Y10\nG1 X20 Y20\n';

  test('strict mode: a malformed line throws an Error with its line and column', () => {
    let err;
    try {
      qp.analyze(bad, { strict: true });
    } catch (e) {
      err = e;
    }
    assert.ok(err !== undefined, 'strict analyze of a malformed file did not throw');
    assert.ok(err instanceof Error, `threw a ${Object.prototype.toString.call(err)}, not an Error`);
    assert.ok(!(err instanceof WebAssembly.RuntimeError), 'threw a wasm trap');
    assert.equal(err.line, 4);
    assert.equal(typeof err.column, 'number');
    assert.ok(err.column >= 1, `column = ${err.column}`);
    assert.match(err.message, /line 4\b/);
    // The same through bytes.
    assert.throws(() => qp.analyze(new TextEncoder().encode(bad), { strict: true }), (e) => e instanceof Error && e.line === 4);
  });

  test('numbers: an overflowing 1e999 is an Error on its line; compact lower case parses', () => {
    assert.throws(
      () => qp.analyze('G1 X1\nG1 X1e999\n', { strict: true }),
      (e) => e instanceof Error && !(e instanceof WebAssembly.RuntimeError) && e.line === 2,
    );
    const r = qp.analyze('M83\ng1x.5e1f600\n');
    assert.equal(r.moves, 1);
    assert.equal(r.distance_mm, 0.5);
    assert.equal(r.filament_mm, 1);
  });

  test('an invalid option is an Error, not a silently ignored value', () => {
    assert.throws(() => qp.analyze('G1 X1', { filament_diameter_mm: -1 }), (e) => e instanceof Error);
  });

  test('an error about the whole file names no line: infill on a file without sparse infill', () => {
    const vase = fs.readFileSync(path.join(corpusDir, 'prusaslicer-2.7.4_spiral-vase.gcode'));
    assert.throws(
      () => qp.infill(vase, { angles_deg: [0], patterns: ['rectilinear'] }),
      (e) =>
        e instanceof Error &&
        e.kind?.kind === 'nothing_to_regenerate' &&
        e.line === undefined &&
        e.column === undefined &&
        e.message === 'nothing to regenerate: the file marks no sparse infill',
    );
  });

  test('lenient mode: the malformed line becomes a warning', () => {
    const r = qp.analyze(bad);
    assertReportShape(r, 'malformed (lenient)');
    assert.ok(r.warnings.some((w) => w.line === 4), `warnings: ${JSON.stringify(r.warnings)}`);
    assert.ok(r.moves > 0);
  });

  test('UTF-16 input gives an Error or a report, never a trap', () => {
    const utf16 = Buffer.from('\ufeffG28\r\nG1 X10 Y10 F3000\r\nG1 X20 E1\r\n', 'utf16le');
    for (const options of [{}, { strict: true }]) {
      try {
        assertReportShape(qp.analyze(utf16, options), 'utf16');
      } catch (e) {
        if (e instanceof assert.AssertionError) throw e;
        assert.ok(e instanceof Error && !(e instanceof WebAssembly.RuntimeError), `bad throw: ${e}`);
        assert.match(e.message, /utf-?16/i);
      }
    }
  });

  test('200 random inputs never trap (lenient mode)', () => {
    const SEED = 0x9e3779b9;
    const rand = rng(SEED);
    const seeds = [fs.readFileSync(demoFile), corpus(BENCHY).subarray(0, 200_000)];
    const alphabet = Buffer.from('GMTXYZEFSPIJR0123456789.-+ ;()*%\n\r\t\0NnaiF;e', 'latin1');
    for (let i = 0; i < 200; i++) {
      const len = Math.floor(rand() * (i % 10 === 0 ? 65536 : 4096));
      let buf;
      switch (i % 4) {
        case 0: // raw random bytes
          buf = Buffer.alloc(len);
          for (let j = 0; j < len; j++) buf[j] = Math.floor(rand() * 256);
          break;
        case 1: // G-code-ish alphabet
          buf = Buffer.alloc(len);
          for (let j = 0; j < len; j++) buf[j] = alphabet[Math.floor(rand() * alphabet.length)];
          break;
        default: {
          // a slice of a real file with random mutations
          const src = seeds[i % 2];
          const start = Math.floor(rand() * Math.max(1, src.length - len));
          buf = Buffer.from(src.subarray(start, start + len));
          const mutations = 1 + Math.floor(rand() * 20);
          for (let m = 0; m < mutations && buf.length > 0; m++) {
            buf[Math.floor(rand() * buf.length)] = rand() < 0.5 ? Math.floor(rand() * 256) : alphabet[Math.floor(rand() * alphabet.length)];
          }
        }
      }
      const label = `random input #${i} (seed ${SEED}, ${buf.length} bytes)`;
      let report;
      try {
        report = qp.analyze(buf, { strict: false });
      } catch (e) {
        assert.ok(!(e instanceof WebAssembly.RuntimeError), `${label}: wasm trap: ${e.message}`);
        assert.ok(e instanceof Error, `${label}: threw a non-Error: ${e}`);
        assert.ok(typeof e.message === 'string' && e.message.length > 0, `${label}: empty error message`);
        continue;
      }
      assertReportShape(report, label);
    }
    // Still healthy afterwards.
    assert.ok(qp.analyze(fs.readFileSync(demoFile)).layers > 0);
  });

  test('empty input gives an empty report', () => {
    for (const input of ['', new Uint8Array(0)]) {
      const r = qp.analyze(input);
      assertReportShape(r, 'empty');
      assert.equal(r.moves, 0);
      assert.equal(r.layers, 0);
    }
  });
});

// Deep equality where numbers may differ by `relTol` (relative); lists every difference.
function jsonDiffs(actual, expected, relTol, at = '$', out = []) {
  if (out.length >= 20) return out;
  if (typeof actual === 'number' && typeof expected === 'number') {
    const scale = Math.max(Math.abs(actual), Math.abs(expected));
    if (actual !== expected && !(Math.abs(actual - expected) <= relTol * scale)) {
      out.push(`${at}: wasm ${actual} ≠ cli ${expected}`);
    }
  } else if (Array.isArray(actual) && Array.isArray(expected)) {
    if (actual.length !== expected.length) out.push(`${at}: wasm has ${actual.length} items, cli ${expected.length}`);
    for (let i = 0; i < Math.min(actual.length, expected.length); i++) jsonDiffs(actual[i], expected[i], relTol, `${at}[${i}]`, out);
  } else if (actual && expected && typeof actual === 'object' && typeof expected === 'object' && !Array.isArray(actual) && !Array.isArray(expected)) {
    for (const k of new Set([...Object.keys(actual), ...Object.keys(expected)])) {
      if (!(k in actual)) out.push(`${at}.${k}: missing in wasm`);
      else if (!(k in expected)) out.push(`${at}.${k}: missing in cli`);
      else jsonDiffs(actual[k], expected[k], relTol, `${at}.${k}`, out);
    }
  } else if (actual !== expected) {
    out.push(`${at}: wasm ${JSON.stringify(actual)} ≠ cli ${JSON.stringify(expected)}`);
  }
  return out;
}

describe('wasm and CLI agree', () => {
  // The most recently built of the release and debug binaries.
  const cli = ['release', 'debug']
    .map((p) => path.join(repoRoot, 'target', p, process.platform === 'win32' ? 'quietpath.exe' : 'quietpath'))
    .filter((p) => fs.existsSync(p))
    .sort((a, b) => fs.statSync(b).mtimeMs - fs.statSync(a).mtimeMs)[0];
  assert.ok(cli, 'no CLI binary at target/release/quietpath or target/debug/quietpath (make cli first)');
  const skip = false;

  for (const { name, exact } of CLI_FILES) {
    test(`${name}: quietpath analyze --json ${exact ? 'equals' : 'matches (≤ 1e-12 relative)'} the wasm report`, { skip }, () => {
      const file = path.join(corpusDir, name);
      const out = execFileSync(cli, ['analyze', file, '--json'], { maxBuffer: 256 * 1024 * 1024, encoding: 'utf8' });
      const fromCli = JSON.parse(out);
      const fromWasm = qp.analyze(fs.readFileSync(file));
      const diffs = jsonDiffs(fromWasm, fromCli, exact ? 0 : 1e-12);
      assert.deepEqual(diffs, [], `${path.relative(repoRoot, cli)} and the wasm package disagree on ${name} (a stale build?)`);
      if (exact) assert.deepEqual(fromWasm, fromCli);
    });
  }

  test('every other corpus file: CLI and wasm reports are identical', { skip }, () => {
    const problems = [];
    for (const name of corpusFiles.filter((n) => !CLI_FILES.some((c) => c.name === n))) {
      const file = path.join(corpusDir, name);
      const fromCli = JSON.parse(execFileSync(cli, ['analyze', file, '--json'], { maxBuffer: 256 * 1024 * 1024, encoding: 'utf8' }));
      const diffs = jsonDiffs(qp.analyze(fs.readFileSync(file)), fromCli, 0);
      if (diffs.length > 0) problems.push(`${name}:\n    ${diffs.slice(0, 5).join('\n    ')}`);
    }
    assert.equal(problems.length, 0, `CLI (${path.relative(repoRoot, cli)}) and wasm disagree:\n  ${problems.join('\n  ')}`);
  });
});
