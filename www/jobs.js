// Page side of the worker protocol (see worker.js): one worker, promises for
// requests, progress callbacks, cancel by terminating the worker.
//
// The client keeps its own copy of the loaded file and of the latest optimized
// output, so that after a cancel (or a crash) the fresh worker can be given the
// sessions again lazily, just before the next request that needs them, instead
// of making the user load the file again.

/** Rejection reason of requests that were cancelled (or superseded). */
export class Cancelled extends Error {
  constructor(reason = 'cancelled') {
    super(reason);
    this.name = 'Cancelled';
    this.reason = reason;
  }
}

/** Rejection reason of a worker-reported failure; carries the worker's fields. */
export class JobError extends Error {
  constructor(msg) {
    super(msg.message ?? 'unknown error');
    this.name = 'JobError';
    Object.assign(this, { line: msg.line ?? null, column: msg.column ?? null, excerpt: msg.excerpt ?? null, kind: msg.kind ?? null, fatal: !!msg.fatal });
  }
}

export class JobClient {
  /**
   * @param {object} hooks
   *   onHello(version, capabilities, machines): a worker has loaded the wasm
   *   (machines: the built-in presets, MachineProfile[]);
   *   onCrash(detail, loaded, hadPending): the worker died (pending requests
   *   were rejected with a JobError; hadPending says whether there were any).
   */
  constructor(url, hooks = {}) {
    this.url = url;
    this.hooks = hooks;
    this.worker = null;
    this.nextId = 1;
    this.pending = new Map(); // id → { resolve, reject, onProgress }
    this.input = null; // { bytes: ArrayBuffer, name, options }
    this.output = null; // ArrayBuffer of the latest optimized G-code
  }

  /** Starts a worker now (the wasm compiles while the page fetches the demo). */
  warm() {
    this.ensureWorker();
  }

  get busy() {
    return this.pending.size > 0;
  }

  ensureWorker() {
    if (this.worker) return this.worker;
    const w = new Worker(this.url, { type: 'module' });
    w.has = { input: false, output: false };
    w.onmessage = (event) => this.onMessage(w, event.data);
    w.onerror = (event) => {
      event.preventDefault();
      this.onCrash(w, event.message || 'the analysis worker failed to start (is pkg/ built?)');
    };
    w.onmessageerror = () => this.onCrash(w, 'could not read a message from the analysis worker');
    this.worker = w;
    return w;
  }

  onCrash(w, detail) {
    if (w !== this.worker) return;
    const loaded = !!w.loaded;
    const hadPending = this.busy;
    this.discard(new JobError({ message: loaded ? `The analyzer crashed: ${detail}` : `The analyzer could not be started: ${detail}` }));
    // A worker that had loaded the wasm before is replaced right away (warm
    // for the next request); one that never loaded is replaced lazily, so a
    // missing pkg/ cannot make us respawn workers in a loop.
    if (loaded) this.ensureWorker();
    this.hooks.onCrash?.(detail, loaded, hadPending);
  }

  /** Terminates the worker and rejects every pending request with `reason`. */
  discard(reason) {
    if (this.worker) {
      this.worker.terminate();
      this.worker = null;
    }
    const pending = [...this.pending.values()];
    this.pending.clear();
    for (const p of pending) p.reject(reason);
  }

  /** Cancels everything in flight; the next request starts a fresh worker. */
  cancel(reason = 'cancelled') {
    if (!this.busy) return false;
    this.discard(new Cancelled(reason));
    this.ensureWorker();
    return true;
  }

  onMessage(w, msg) {
    if (w !== this.worker || !msg) return;
    if (msg.type === 'hello') {
      w.loaded = true;
      this.hooks.onHello?.(msg.version, msg.capabilities ?? ['analyze'], msg.machines ?? []);
      return;
    }
    const p = this.pending.get(msg.id);
    if (!p) return;
    if (msg.type === 'progress') {
      p.onProgress?.(msg.fraction);
      return;
    }
    this.pending.delete(msg.id);
    if (msg.type === 'error') {
      if (msg.fatal) this.discard(new Cancelled('worker restarted'));
      p.reject(new JobError(msg));
      if (msg.fatal) this.ensureWorker();
    } else {
      p.resolve(msg);
    }
  }

  post(msg, { transfer = [], onProgress } = {}) {
    const w = this.ensureWorker();
    const id = this.nextId++;
    return {
      w,
      promise: new Promise((resolve, reject) => {
        this.pending.set(id, { resolve, reject, onProgress });
        w.postMessage({ ...msg, id }, transfer);
      }),
    };
  }

  /**
   * Gives a fresh worker the sessions it lacks (after a cancel or crash).
   * Requests made at the same time (a job and a layer) share one re-load.
   */
  async restore(needOutput) {
    const w = this.ensureWorker();
    if (!this.input) throw new JobError({ message: 'no file loaded' });
    const reload = (which, buffer) => {
      w.reloading ??= {};
      w.reloading[which] ??= (async () => {
        const bytes = buffer.slice(0);
        await this.post({ type: 'load', which, bytes, name: which, options: this.input.options, analyze: false }, { transfer: [bytes] }).promise;
        w.has[which] = true;
      })().finally(() => {
        delete w.reloading[which];
      });
      return w.reloading[which];
    };
    if (!w.has.input) await reload('input', this.input.bytes);
    if (needOutput && this.output && !w.has.output) await reload('output', this.output);
  }

  /**
   * Loads a file (the new input session) and analyzes it.
   * Anything in flight is cancelled first. Resolves to { report, ms, totalMs }.
   */
  async load(bytes, name, options, onProgress) {
    this.cancel('superseded');
    this.input = { bytes: bytes.slice(0), name, options };
    this.output = null;
    const { w, promise } = this.post({ type: 'load', which: 'input', bytes, name, options }, { transfer: [bytes], onProgress });
    w.has.input = false;
    w.has.output = false;
    const msg = await promise;
    w.has.input = true;
    return msg;
  }

  /**
   * Runs a capability. Resolves to { result, ms, output: ArrayBuffer | null };
   * a job with output makes it the new "after" (kept here for re-loads).
   */
  async job(job, options, target = 'input', onProgress) {
    await this.restore(target === 'output');
    const { w, promise } = this.post({ type: 'job', job, options, target }, { onProgress });
    const msg = await promise;
    if (msg.output) {
      this.output = msg.output.slice(0); // the worker already holds it as a session
      w.has.output = true;
    }
    return msg;
  }

  /** Drawing data of layer `index` of 'before' (input) or 'after' (output). */
  /** One layer's drawing data; with a number `z`, the layer nearest that height. */
  async layer(which, index, z = null) {
    await this.restore(which === 'after');
    const { promise } = this.post({ type: 'layer', which, index, z });
    return promise;
  }
}
