#!/usr/bin/env node
// Dependency-free static file server for the quietpath playground.
//
//   node scripts/serve.mjs [ROOT]        (default ROOT: www/, or env ROOT)
//   PORT=8080 node scripts/serve.mjs     (default port 8080, 127.0.0.1 only)
//
// Every response carries a strict Content-Security-Policy that forbids any
// connection to another origin: the playground works entirely offline and the
// G-code never leaves the browser. Symlinks are followed (www/pkg may be a
// symlink to ../pkg), but a request path can never climb above ROOT.
//
// Tests import { startServer } and start it in-process with port 0.

import http from 'node:http';
import fs from 'node:fs';
import path from 'node:path';
import { fileURLToPath } from 'node:url';

export const CSP = [
  "default-src 'self'",
  "script-src 'self' 'wasm-unsafe-eval'",
  // The threaded build's pool workers too: `make pkg` has them start from their helper script's
  // own URL rather than a blob of it (scripts/pool-helper.mjs).
  "worker-src 'self'",
  "connect-src 'self'",
  'img-src \'self\' data: blob:',
  "style-src 'self'",
  "object-src 'none'",
  "base-uri 'none'",
  "form-action 'none'",
].join('; ');

export const SECURITY_HEADERS = Object.freeze({
  'Content-Security-Policy': CSP,
  'X-Content-Type-Options': 'nosniff',
  'Cache-Control': 'no-cache',
  'Referrer-Policy': 'no-referrer',
  'Cross-Origin-Opener-Policy': 'same-origin',
  // With COOP, makes the page cross-origin isolated: SharedArrayBuffer, which the threaded
  // build's shared wasm memory needs. Every resource the page loads is its own origin's.
  'Cross-Origin-Embedder-Policy': 'require-corp',
});

export const MIME_TYPES = Object.freeze({
  '.html': 'text/html; charset=utf-8',
  '.htm': 'text/html; charset=utf-8',
  '.js': 'text/javascript; charset=utf-8',
  '.mjs': 'text/javascript; charset=utf-8',
  '.css': 'text/css; charset=utf-8',
  '.json': 'application/json; charset=utf-8',
  '.map': 'application/json; charset=utf-8',
  '.wasm': 'application/wasm',
  '.ts': 'text/plain; charset=utf-8',
  '.gcode': 'text/plain; charset=utf-8',
  '.gco': 'text/plain; charset=utf-8',
  '.g': 'text/plain; charset=utf-8',
  '.scad': 'text/plain; charset=utf-8',
  '.txt': 'text/plain; charset=utf-8',
  '.md': 'text/markdown; charset=utf-8',
  '.svg': 'image/svg+xml',
  '.png': 'image/png',
  '.jpg': 'image/jpeg',
  '.jpeg': 'image/jpeg',
  '.gif': 'image/gif',
  '.webp': 'image/webp',
  '.ico': 'image/x-icon',
  '.woff2': 'font/woff2',
});

export function mimeType(file) {
  return MIME_TYPES[path.extname(file).toLowerCase()] ?? 'application/octet-stream';
}

function send(res, status, body, extra = {}) {
  const buf = Buffer.from(body, 'utf8');
  res.writeHead(status, {
    ...SECURITY_HEADERS,
    'Content-Type': 'text/plain; charset=utf-8',
    'Content-Length': buf.length,
    ...extra,
  });
  res.end(res.req.method === 'HEAD' ? undefined : buf);
}

/**
 * Map a URL pathname onto a file below `root`. Returns null when the path is
 * malformed or would escape the root (the check is lexical, so symlinks inside
 * the root are followed on purpose).
 */
export function resolveRequestPath(root, pathname) {
  let decoded;
  try {
    decoded = decodeURIComponent(pathname);
  } catch {
    return null;
  }
  if (decoded.includes('\0') || decoded.includes('\\')) return null;
  const segments = decoded.split('/');
  if (segments.some((s) => s === '..')) return null;
  const full = path.resolve(root, '.' + path.posix.normalize('/' + decoded));
  if (full !== root && !full.startsWith(root + path.sep)) return null;
  return full;
}

function handler(root) {
  return (req, res) => {
    if (req.method !== 'GET' && req.method !== 'HEAD') {
      send(res, 405, 'method not allowed\n', { Allow: 'GET, HEAD' });
      return;
    }
    let url;
    try {
      url = new URL(req.url, 'http://127.0.0.1');
    } catch {
      send(res, 400, 'bad request\n');
      return;
    }
    let file = resolveRequestPath(root, url.pathname);
    if (file === null) {
      send(res, 403, 'forbidden\n');
      return;
    }
    fs.stat(file, (err, st) => {
      if (!err && st.isDirectory()) {
        if (!url.pathname.endsWith('/')) {
          send(res, 301, 'moved\n', { Location: url.pathname + '/' + url.search });
          return;
        }
        file = path.join(file, 'index.html');
        fs.stat(file, (err2, st2) => serveFile(req, res, file, err2, st2));
        return;
      }
      serveFile(req, res, file, err, st);
    });
  };
}

function serveFile(req, res, file, err, st) {
  if (err || !st.isFile()) {
    send(res, 404, 'not found\n');
    return;
  }
  res.writeHead(200, {
    ...SECURITY_HEADERS,
    'Content-Type': mimeType(file),
    'Content-Length': st.size,
    'Last-Modified': st.mtime.toUTCString(),
  });
  if (req.method === 'HEAD') {
    res.end();
    return;
  }
  const stream = fs.createReadStream(file);
  stream.on('error', () => res.destroy());
  stream.pipe(res);
}

/**
 * Start the static server. Resolves once it is listening.
 * @param {{root?: string, port?: number, host?: string, quiet?: boolean}} [opts]
 * @returns {Promise<http.Server>} the listening server (server.address().port
 *   is the real port when port 0 was asked for); server.url is its base URL.
 */
export function startServer({ root, port, host = '127.0.0.1', quiet = true } = {}) {
  const defaultRoot = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '..', 'www');
  const absRoot = path.resolve(root ?? process.env.ROOT ?? defaultRoot);
  const listenPort = Number(port ?? process.env.PORT ?? 8080);
  const server = http.createServer(handler(absRoot));
  return new Promise((resolve, reject) => {
    server.once('error', reject);
    server.listen(listenPort, host, () => {
      server.off('error', reject);
      const addr = server.address();
      server.url = `http://${host}:${addr.port}/`;
      server.root = absRoot;
      if (!quiet) console.log(`quietpath playground: serving ${absRoot} at ${server.url}`);
      resolve(server);
    });
  });
}

const isMain = process.argv[1] && path.resolve(process.argv[1]) === fileURLToPath(import.meta.url);
if (isMain) {
  const root = process.argv[2] ?? process.env.ROOT ?? undefined;
  startServer({ root, quiet: false }).then(
    (server) => {
      if (!fs.existsSync(path.join(server.root, 'pkg', 'quietpath.js'))) {
        console.warn(`warning: ${path.join(server.root, 'pkg', 'quietpath.js')} not found; build the wasm package first`);
      }
      const stop = () => server.close(() => process.exit(0));
      process.on('SIGINT', stop);
      process.on('SIGTERM', stop);
    },
    (err) => {
      console.error(`serve: ${err.message}`);
      process.exit(1);
    },
  );
}
