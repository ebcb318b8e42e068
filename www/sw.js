// @ts-check
// quietpath service worker: the playground keeps working offline once loaded.
//
// Network first, cache as the fallback: online, every request goes to the
// server as if this file did not exist (a rebuilt pkg/ or an edited page is
// picked up at once, no stale versions to chase); each same-origin answer is
// kept, and when the network is gone the kept copy answers. Without this, a
// cancel (which starts a new Web Worker, so fetches worker.js and the wasm
// again) would fail offline. Only this origin's own files are ever fetched or
// cached; user files are read from disk by the page and never pass through.

/** This file runs as the page's service worker: `self` is its global scope. */
const sw = /** @type {ServiceWorkerGlobalScope} */ (/** @type {unknown} */ (self));

const CACHE = 'quietpath-v1';
const SHELL = [
  './',
  'index.html',
  'app.js',
  'jobs.js',
  'viewer.js',
  'charts.js',
  'worker.js',
  'timing-worker.js',
  'style.css',
  'favicon.svg',
  'vendor/uPlot.esm.js',
  'vendor/uPlot.min.css',
  'view3d.js',
  'vendor/three.module.js',
  'vendor/three.core.js',
  'pkg/quietpath.js',
  'pkg/quietpath_bg.wasm',
  'demo/demo.gcode',
];

sw.addEventListener('install', (event) => {
  event.waitUntil(
    caches
      .open(CACHE)
      .then((cache) => cache.addAll(SHELL))
      .then(() => sw.skipWaiting()),
  );
});

sw.addEventListener('activate', (event) => {
  event.waitUntil(
    caches
      .keys()
      .then((keys) => Promise.all(keys.filter((k) => k !== CACHE).map((k) => caches.delete(k))))
      .then(() => sw.clients.claim()),
  );
});

sw.addEventListener('fetch', (event) => {
  const req = event.request;
  if (req.method !== 'GET' || new URL(req.url).origin !== sw.location.origin) return;
  event.respondWith(
    fetch(req)
      .then((res) => {
        if (res.ok && res.type === 'basic') {
          const copy = res.clone();
          event.waitUntil(caches.open(CACHE).then((cache) => cache.put(req, copy)));
        }
        return res;
      })
      .catch(async () => (await caches.match(req)) ?? Response.error()),
  );
});
