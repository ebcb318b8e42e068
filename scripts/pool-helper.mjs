// Lets the threaded build's pool start under the playground's CSP (`worker-src 'self'`).
//
// wasm-bindgen-rayon's helper for builds without a bundler starts each pool worker from a blob
// of its own script (fetched, then URL.createObjectURL), so that a copy hosted on a CDN still
// starts. A blob worker needs `worker-src blob:`, which would also let a page script run any code
// it builds as a worker. The playground serves the helper itself, so the worker is started from
// the script's own same-origin URL instead. The helper is found in the build's snippets; if its
// text is not the one expected (another wasm-bindgen-rayon), this fails loudly rather than
// leave a pool that cannot start.
//
//   node scripts/pool-helper.mjs pkg/web-threads
import fs from 'node:fs';
import path from 'node:path';

const dir = process.argv[2] ?? 'pkg/web-threads';
const snippets = path.join(dir, 'snippets');
const helpers = fs
  .readdirSync(snippets)
  .filter((d) => d.startsWith('wasm-bindgen-rayon-'))
  .map((d) => path.join(snippets, d, 'src', 'workerHelpers.no-bundler.js'))
  .filter((f) => fs.existsSync(f));
if (helpers.length !== 1) throw new Error(`expected one wasm-bindgen-rayon helper in ${snippets}, found ${helpers.length}`);
const file = helpers[0];
const text = fs.readFileSync(file, 'utf8');
// Line by line (the helper ships with CRLF line ends).
const edits = [
  [/^ *let scriptBlob = await fetch\(import\.meta\.url\)\.then\(r => r\.blob\(\)\);\r?\n/m, ''],
  [/^( *)let url = URL\.createObjectURL\(scriptBlob\);(\r?\n)/m, '$1const url = import.meta.url;$2'],
  [/^ *URL\.revokeObjectURL\(url\);\r?\n/m, ''],
];
if (text.includes('const url = import.meta.url;') && !text.includes('createObjectURL')) process.exit(0);
let out = text;
for (const [from, to] of edits) {
  if (!from.test(out)) throw new Error(`${file}: not the wasm-bindgen-rayon helper this script knows (no match for ${from})`);
  out = out.replace(from, to);
}
fs.writeFileSync(file, out);
console.log(`${file}: pool workers start from the script's own URL`);
