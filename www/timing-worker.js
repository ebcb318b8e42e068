// @ts-check
// quietpath timing worker (module worker), started by worker.js.
//
// A browser worker has one thread, so while worker.js reads a large file for analyze, this
// worker plans its moves (the timing side: planner and energy model), as the CLI does on a
// second thread. worker.js sends the batches Session.readApart produces; this worker feeds
// them to a TimingApart and sends back its results for Session.reportApart.
//
// worker.js → this worker
//   { type: 'begin', run }                   a new analysis (drops any earlier one)
//   { type: 'batch', run, bytes: ArrayBuffer } the next batch, transferred
//   { type: 'finish', run }                  end of file
// this worker → worker.js
//   { type: 'ready' } once the wasm is loaded, or { type: 'failed', message }
//   { type: 'timing', run, bytes: ArrayBuffer } the results (transferred)
//   { type: 'error', run, message }

import init, * as qp from './pkg/quietpath.js';

/** @type {qp.TimingApart | null} */
let timing = null;
let run = -1;
/** @type {string | null} */
let failure = null;

/** @param {unknown} err */
const describe = (err) => (err instanceof Error ? err.message : String(err));

/** @param {{ type: string, run: number, bytes?: ArrayBuffer }} msg */
function handle(msg) {
  if (msg.type === 'begin') {
    timing?.free();
    timing = new qp.TimingApart();
    run = msg.run;
    failure = null;
    return;
  }
  if (msg.run !== run || !timing) return;
  if (msg.type === 'batch' && msg.bytes && failure === null) {
    try {
      timing.feed(new Uint8Array(msg.bytes));
    } catch (err) {
      failure = describe(err);
    }
  } else if (msg.type === 'finish') {
    try {
      if (failure !== null) throw new Error(failure);
      const bytes = timing.finish();
      const buffer = bytes.byteOffset === 0 && bytes.buffer.byteLength === bytes.byteLength ? bytes.buffer : bytes.slice().buffer;
      self.postMessage({ type: 'timing', run, bytes: buffer }, [buffer]);
    } catch (err) {
      self.postMessage({ type: 'error', run, message: describe(err) });
    }
    timing.free();
    timing = null;
  }
}

init().then(
  () => {
    self.onmessage = (event) => handle(event.data);
    self.postMessage({ type: 'ready' });
  },
  (err) => self.postMessage({ type: 'failed', message: describe(err) }),
);
