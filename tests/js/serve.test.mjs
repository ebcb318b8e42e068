// Tests of scripts/serve.mjs, the playground's static file server.

import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import net from 'node:net';
import os from 'node:os';
import path from 'node:path';
import { startServer, CSP } from '../../scripts/serve.mjs';

let dir;
let root;
let server;
let base;

before(async () => {
  dir = fs.mkdtempSync(path.join(os.tmpdir(), 'qp-serve-'));
  root = path.join(dir, 'www');
  fs.mkdirSync(path.join(root, 'sub'), { recursive: true });
  fs.writeFileSync(path.join(root, 'index.html'), '<!doctype html><title>t</title>');
  fs.writeFileSync(path.join(root, 'app.js'), 'export {};');
  fs.writeFileSync(path.join(root, 'style.css'), 'body{}');
  fs.writeFileSync(path.join(root, 'm.wasm'), Buffer.from([0, 0x61, 0x73, 0x6d, 1, 0, 0, 0]));
  fs.writeFileSync(path.join(root, 'a.gcode'), 'G28\n');
  fs.writeFileSync(path.join(root, 'sub', 'index.html'), 'sub');
  fs.writeFileSync(path.join(root, 'sub', 'with space.txt'), 'spaced');
  fs.writeFileSync(path.join(dir, 'secret.txt'), 'secret');
  // www/pkg as a symlink to a directory outside the root, as the Makefile may do.
  fs.mkdirSync(path.join(dir, 'pkg'));
  fs.writeFileSync(path.join(dir, 'pkg', 'quietpath.js'), 'export default 1;');
  fs.symlinkSync(path.join(dir, 'pkg'), path.join(root, 'pkg'), 'dir');
  server = await startServer({ root, port: 0 });
  base = `http://127.0.0.1:${server.address().port}`;
});

after(async () => {
  await new Promise((resolve) => server.close(resolve));
  fs.rmSync(dir, { recursive: true, force: true });
});

// Raw HTTP GET, so that paths are sent exactly as written (fetch normalizes "..").
function rawGet(rawPath) {
  return new Promise((resolve, reject) => {
    const sock = net.connect(server.address().port, '127.0.0.1', () => {
      sock.write(`GET ${rawPath} HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n`);
    });
    let data = '';
    sock.setEncoding('latin1');
    sock.on('data', (d) => (data += d));
    sock.on('end', () => resolve(data));
    sock.on('error', reject);
  });
}

test('listens on 127.0.0.1 with the port asked for (0 = any)', () => {
  assert.equal(server.address().address, '127.0.0.1');
  assert.ok(server.address().port > 0);
});

test('serves files with the right MIME types and security headers', async () => {
  const cases = {
    '/': 'text/html',
    '/index.html': 'text/html',
    '/app.js': 'text/javascript',
    '/style.css': 'text/css',
    '/m.wasm': 'application/wasm',
    '/a.gcode': 'text/plain',
    '/pkg/quietpath.js': 'text/javascript',
    '/sub/': 'text/html',
    '/sub/with%20space.txt': 'text/plain',
  };
  for (const [p, type] of Object.entries(cases)) {
    const res = await fetch(base + p);
    assert.equal(res.status, 200, p);
    assert.ok(res.headers.get('content-type').startsWith(type), `${p}: ${res.headers.get('content-type')}`);
    assert.equal(res.headers.get('content-security-policy'), CSP);
    assert.equal(res.headers.get('x-content-type-options'), 'nosniff');
    assert.equal(res.headers.get('cache-control'), 'no-cache');
    // Cross-origin isolated, for the threaded build's shared memory.
    assert.equal(res.headers.get('cross-origin-opener-policy'), 'same-origin');
    assert.equal(res.headers.get('cross-origin-embedder-policy'), 'require-corp');
    await res.arrayBuffer();
  }
  assert.equal(await (await fetch(base + '/pkg/quietpath.js')).text(), 'export default 1;');
});

test('the CSP forbids outside connections', () => {
  for (const d of [
    "default-src 'self'",
    "script-src 'self' 'wasm-unsafe-eval'",
    "worker-src 'self'",
    "connect-src 'self'",
    "img-src 'self' data: blob:",
    "style-src 'self'",
    "object-src 'none'",
    "base-uri 'none'",
    "form-action 'none'",
  ]) {
    assert.ok(CSP.split('; ').includes(d), `missing ${d}`);
  }
});

test('the page carries the same CSP as a meta tag', () => {
  const html = fs.readFileSync(new URL('../../www/index.html', import.meta.url), 'utf8');
  const m = html.match(/http-equiv="Content-Security-Policy"\s+content="([^"]+)"/);
  assert.ok(m, 'no CSP meta tag in www/index.html');
  assert.equal(m[1], CSP);
});

test('missing files are 404, with headers', async () => {
  const res = await fetch(base + '/nope.js');
  assert.equal(res.status, 404);
  assert.equal(res.headers.get('content-security-policy'), CSP);
  await res.arrayBuffer();
});

test('a directory without a trailing slash redirects', async () => {
  const res = await fetch(base + '/sub', { redirect: 'manual' });
  assert.equal(res.status, 301);
  assert.equal(res.headers.get('location'), '/sub/');
});

test('no directory traversal', async () => {
  for (const p of [
    '/../secret.txt',
    '/sub/../../secret.txt',
    '/%2e%2e/secret.txt',
    '/%2e%2e%2fsecret.txt',
    '/sub/%2e%2e/%2e%2e/secret.txt',
    '/..%5csecret.txt',
    '/%00',
    '/%zz',
  ]) {
    const res = await rawGet(p);
    const status = Number(res.split(' ')[1]);
    assert.ok(status >= 400 && status < 500, `${p} → ${status}`);
    assert.ok(!res.includes('secret\n') && !res.endsWith('secret'), `${p} leaked the file`);
  }
});

test('only GET and HEAD', async () => {
  const res = await fetch(base + '/index.html', { method: 'POST', body: 'x' });
  assert.equal(res.status, 405);
  await res.arrayBuffer();
  const head = await fetch(base + '/index.html', { method: 'HEAD' });
  assert.equal(head.status, 200);
  assert.equal(await head.text(), '');
});
