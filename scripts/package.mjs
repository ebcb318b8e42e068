// Assembles the npm package in pkg/ from the three wasm-pack builds:
//   pkg/web      --target web      (ES module + init(); the playground uses it)
//   pkg/node     --target nodejs   (CommonJS, loads the wasm synchronously)
//   pkg/bundler  --target bundler  (ES module importing the .wasm; webpack, Vite, …)
// and writes one package.json whose conditional exports pick the right one:
//   import 'quietpath'      → node build in Node, bundler build in bundlers
//   import 'quietpath/web'  → the web build (call the default export init() first)
// Usage: node scripts/package.mjs
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

const root = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..');
const pkg = path.join(root, 'pkg');
const targets = ['web', 'node', 'bundler'];

const cargo = fs.readFileSync(path.join(root, 'Cargo.toml'), 'utf8');
const field = (name) => cargo.match(new RegExp(`^${name}\\s*=\\s*"([^"]*)"`, 'm'))?.[1];
const version = field('version');
if (!version) throw new Error('cannot read the version from Cargo.toml');

const files = ['README.md', 'package.json'];
for (const t of targets) {
  const dir = path.join(pkg, t);
  if (!fs.existsSync(path.join(dir, 'quietpath.js'))) {
    throw new Error(`${dir}/quietpath.js is missing: run wasm-pack for --target ${t} first (make pkg)`);
  }
  // Each sub-build gets its own minimal package.json (module type matters to Node) and loses
  // the wasm-pack files that would shadow the root package.
  for (const f of ['.gitignore', 'README.md', 'LICENSE', 'LICENSE-MIT', 'LICENSE-APACHE']) {
    fs.rmSync(path.join(dir, f), { force: true });
  }
  const sub = { type: t === 'node' ? 'commonjs' : 'module', sideEffects: t === 'bundler' ? ['./quietpath.js', './snippets/*'] : false };
  fs.writeFileSync(path.join(dir, 'package.json'), JSON.stringify(sub, null, 2) + '\n');
  files.push(`${t}/`);
}

const manifest = {
  name: 'quietpath',
  version,
  description:
    'Quieter, cheaper 3D-printer toolpaths: G-code analysis, firmware-faithful motion and energy models, vibration-suppressed toolpath rewriting (WebAssembly).',
  license: 'MIT OR Apache-2.0',
  repository: { type: 'git', url: 'https://github.com/quietpath/quietpath' },
  keywords: ['gcode', '3d-printing', 'toolpath', 'wasm', 'energy', 'vibration', 'slicer'],
  type: 'module',
  main: './node/quietpath.js',
  module: './bundler/quietpath.js',
  types: './web/quietpath.d.ts',
  exports: {
    '.': {
      types: './bundler/quietpath.d.ts',
      node: './node/quietpath.js',
      default: './bundler/quietpath.js',
    },
    './web': { types: './web/quietpath.d.ts', default: './web/quietpath.js' },
    './web/quietpath_bg.wasm': './web/quietpath_bg.wasm',
    './package.json': './package.json',
  },
  files,
  sideEffects: ['./bundler/quietpath.js', './bundler/snippets/*'],
};
fs.writeFileSync(path.join(pkg, 'package.json'), JSON.stringify(manifest, null, 2) + '\n');
fs.writeFileSync(
  path.join(pkg, 'README.md'),
  `# quietpath ${version}\n\nWebAssembly build of [quietpath](${manifest.repository.url}): the API is documented in the repository's docs/js-api.md.\n\n` +
    "```js\nimport { analyze } from 'quietpath';          // Node or a bundler\nimport init, { analyze } from 'quietpath/web'; // plain browser ES modules: await init() first\n```\n",
);
console.log(`pkg/package.json: quietpath ${version} (${targets.join(', ')})`);
