// @ts-check
// Page side of the worker protocol (see worker.js): one worker, promises for
// requests, progress callbacks, cancel by terminating the worker.
//
// The client keeps its own copy of the loaded file and of the latest optimized
// output, so that after a cancel (or a crash) the fresh worker can be given the
// sessions again lazily, just before the next request that needs them, instead
// of making the user load the file again.

/**
 * A worker as the client keeps it: which sessions it holds, whether it loaded the wasm, and
 * the session re-loads in flight.
 * @typedef {Worker & { has: { input: boolean, output: boolean }, loaded?: boolean, reloading?: Partial<Record<'input' | 'output', Promise<void>>> }} JobWorker
 */

/**
 * A request in flight.
 * @typedef {{ resolve: (msg: any) => void, reject: (reason: unknown) => void, onProgress?: (fraction: number) => void }} Pending
 */

/** Rejection reason of requests that were cancelled (or superseded). */
export class Cancelled extends Error {
  /** @param {string} [reason] */
  constructor(reason = 'cancelled') {
    super(reason);
    this.name = 'Cancelled';
    this.reason = reason;
  }
}

/** Rejection reason of a worker-reported failure; carries the worker's fields. */
export class JobError extends Error {
  /** @param {{ message?: string, line?: number | null, column?: number | null, excerpt?: string | null, kind?: unknown, fatal?: boolean }} msg */
  constructor(msg) {
    super(msg.message ?? 'unknown error');
    this.name = 'JobError';
    this.line = msg.line ?? null;
    this.column = msg.column ?? null;
    this.excerpt = msg.excerpt ?? null;
    this.kind = msg.kind ?? null;
    this.fatal = !!msg.fatal;
  }
}

/** @typedef {import('./pkg/quietpath.js').AnalyzeOptions} AnalyzeOptions */
/** @typedef {import('./pkg/quietpath.js').MachineProfile} MachineProfile */
/** @typedef {import('./pkg/quietpath.js').Report} Report */
/**
 * The worker's answer to a layer request: the layer's drawing data (LayerGeometry), which
 * layer it is and how many the session has.
 * @typedef {import('./pkg/quietpath.js').LayerGeometry & { which: 'before' | 'after', index: number, count: number }} LayerMessage
 */

export class JobClient {
  /**
   * @param {string | URL} url
   * @param {object} hooks
   * @param {(version: string | null, capabilities: string[], machines: MachineProfile[], threads: number) => void} [hooks.onHello]
   *   a worker has loaded the wasm (machines: the built-in presets)
   * @param {(detail: string, loaded: boolean, hadPending: boolean) => void} [hooks.onCrash]
   *   the worker died (pending requests were rejected with a JobError; hadPending says whether
   *   there were any)
   */
  constructor(url, hooks = {}) {
    this.url = url;
    this.hooks = hooks;
    /** @type {JobWorker | null} */
    this.worker = null;
    this.nextId = 1;
    /** @type {Map<number, Pending>} */
    this.pending = new Map(); // id → { resolve, reject, onProgress }
    /** @type {{ bytes: ArrayBuffer, name: string, options: AnalyzeOptions } | null} */
    this.input = null; // { bytes: ArrayBuffer, name, options }
    /** @type {ArrayBuffer | null} */
    this.output = null; // ArrayBuffer of the latest optimized G-code
  }

  /** Starts a worker now (the wasm compiles while the page fetches the demo). */
  warm() {
    this.ensureWorker();
  }

  get busy() {
    return this.pending.size > 0;
  }

  /** @returns {JobWorker} */
  ensureWorker() {
    if (this.worker) return this.worker;
    const w = /** @type {JobWorker} */ (new Worker(this.url, { type: 'module' }));
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

  /**
   * @param {JobWorker} w
   * @param {string} detail
   */
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

  /**
   * Terminates the worker and rejects every pending request with `reason`.
   * @param {Error} reason
   */
  discard(reason) {
    if (this.worker) {
      this.worker.terminate();
      this.worker = null;
    }
    const pending = [...this.pending.values()];
    this.pending.clear();
    for (const p of pending) p.reject(reason);
  }

  /**
   * Cancels everything in flight; the next request starts a fresh worker.
   * @param {string} [reason]
   */
  cancel(reason = 'cancelled') {
    if (!this.busy) return false;
    this.discard(new Cancelled(reason));
    this.ensureWorker();
    return true;
  }

  /**
   * @param {JobWorker} w
   * @param {any} msg a message of the worker protocol (worker.js)
   */
  onMessage(w, msg) {
    if (w !== this.worker || !msg) return;
    if (msg.type === 'hello') {
      w.loaded = true;
      this.hooks.onHello?.(msg.version, msg.capabilities ?? ['analyze'], msg.machines ?? [], msg.threads ?? 1);
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

  /**
   * Sends a request; `promise` settles with the worker's answer.
   * @param {object} msg
   * @param {{ transfer?: Transferable[], onProgress?: (fraction: number) => void }} [opts]
   * @returns {{ w: JobWorker, promise: Promise<any> }}
   */
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
   * @param {boolean} needOutput
   */
  async restore(needOutput) {
    const w = this.ensureWorker();
    if (!this.input) throw new JobError({ message: 'no file loaded' });
    /** The loaded file, read when each re-load starts (checked above). */
    const input = () => /** @type {NonNullable<JobClient['input']>} */ (this.input);
    /**
     * @param {'input' | 'output'} which
     * @param {ArrayBuffer} buffer
     * @returns {Promise<void>}
     */
    const reload = (which, buffer) => {
      w.reloading ??= {};
      w.reloading[which] ??= (async () => {
        const bytes = buffer.slice(0);
        await this.post({ type: 'load', which, bytes, name: which, options: input().options, analyze: false }, { transfer: [bytes] }).promise;
        w.has[which] = true;
      })().finally(() => {
        delete w.reloading?.[which];
      });
      return w.reloading[which];
    };
    if (!w.has.input) await reload('input', this.input.bytes);
    if (needOutput && this.output && !w.has.output) await reload('output', this.output);
  }

  /**
   * Loads a file (the new input session) and analyzes it.
   * Anything in flight is cancelled first. Resolves to { report, ms, totalMs, workers }.
   * @param {ArrayBuffer} bytes the file (transferred to the worker)
   * @param {string} name
   * @param {AnalyzeOptions} options
   * @param {(fraction: number) => void} [onProgress]
   * @returns {Promise<{ report: Report, ms: number, totalMs: number, workers?: number }>}
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
   * @param {string} job
   * @param {object} options
   * @param {'input' | 'output'} [target]
   * @param {(fraction: number) => void} [onProgress]
   * @returns {Promise<{ result: any, ms: number, output: ArrayBuffer | null }>}
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

  /**
   * Drawing data of layer `index` of 'before' (input) or 'after' (output); with a number `z`,
   * the layer nearest that height.
   * @param {'before' | 'after'} which
   * @param {number} index
   * @param {number | null} [z]
   * @returns {Promise<LayerMessage>}
   */
  async layer(which, index, z = null) {
    await this.restore(which === 'after');
    const { promise } = this.post({ type: 'layer', which, index, z });
    return promise;
  }
}
