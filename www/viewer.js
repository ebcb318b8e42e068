// @ts-check
// Layer viewer: draws one layer's toolpath (Session.layer geometry) on a 2D
// canvas, before and after an optimization, coloured by feature, speed or
// curvature.
//
// Why canvas 2D and colour buckets: a layer of a big print has 10⁴–10⁵
// segments. Stroking each one with its own colour is slow (one state change per
// segment); grouping the segments into a few colour buckets and stroking each
// bucket as one path keeps a redraw in a few milliseconds, which is what makes
// wheel zoom and drag pan smooth. WebGL would be faster still but adds a lot
// of code for no visible gain at these sizes.

/** Feature kinds of LayerGeometry.kind (see crate/src/wasm/types.d.ts). */
export const KINDS = ['travel', 'outer wall', 'inner wall', 'sparse infill', 'solid infill', 'bridge', 'gap fill', 'support', 'adhesion', 'other'];
export const KIND_COLORS = ['#9aa4a0', '#e4572e', '#f3a712', '#2e86ab', '#5a4fcf', '#29bf12', '#a23b72', '#8d6a9f', '#6c8ead', '#7f7f7f'];

// A perceptually ordered ramp (viridis-like) for speed and curvature.
export const RAMP = ['#440154', '#482878', '#3e4a89', '#31688e', '#26828e', '#1f9e89', '#35b779', '#6ece58', '#b5de2b', '#fde725'];
const BUCKETS = RAMP.length;

const MIN_SCALE = 1e-3;
const MAX_SCALE = 1e4;

/** @typedef {import('./jobs.js').LayerMessage} LayerMessage one layer's drawing data */
/** @typedef {{ cx: number, cy: number, scale: number }} View the centre (mm) and CSS px per mm */
/** @typedef {{ geom: LayerMessage | null, ghost?: LayerMessage | null, x: number, w: number, label: string }} Pane */
/** @typedef {{ key: 'speed' | 'curvature' | 'layer-time', lo: number, hi: number }} Range */
/**
 * A segment under the pointer (LayerViewer.pick).
 * @typedef {{ which: string, kind: string, speed: number, curvature: number, x: number, y: number }} Hit
 */

export class LayerViewer {
  /**
   * @param {HTMLCanvasElement} canvas
   * @param {HTMLElement} legend  gets the colour legend
   * @param {object} [hooks]
   * @param {() => void} [hooks.onViewChange] the user zoomed or panned
   * @param {(hit: Hit | null) => void} [hooks.onHover] the segment under the pointer, or none
   */
  constructor(canvas, legend, hooks = {}) {
    this.canvas = canvas;
    // A fresh canvas always has a 2-D context to give.
    this.ctx = /** @type {CanvasRenderingContext2D} */ (canvas.getContext('2d'));
    this.legend = legend;
    this.hooks = hooks;
    /** @type {LayerMessage | null} */
    this.before = null; // LayerGeometry (+ index, count)
    /** @type {LayerMessage | null} */
    this.after = null;
    this.colorBy = 'feature';
    this.showTravel = false;
    this.mode = 'before'; // before | after | side | overlay
    /** @type {View | null} */
    this.view = null; // { cx, cy, scale } (scale: CSS px per mm)
    this.userMoved = false; // zoomed or panned since the last fit: keep that view across layers
    /** @type {{ minX: number, minY: number, maxX: number, maxY: number } | null} */
    this.bounds = null; // the whole print's XY extent { minX, minY, maxX, maxY }, outlined
    /** @type {number[][] | null} */
    this.bed = null; // the printer bed's outline [[x, y], …] in mm, when the file or printer.cfg says
    /** @type {{ before: number | null, after: number | null, lo: number, hi: number } | null} */
    this.layerTime = null; // 'layer-time' colouring: { before, after, lo, hi } in s
    this.frame = 0;
    this.installInput();
    this.resizeObserver = new ResizeObserver(() => this.resize());
    this.resizeObserver.observe(canvas);
    this.resize();
  }

  /**
   * Sets the geometry to draw; `after` may be null. Keeps the view.
   * @param {LayerMessage} before
   * @param {LayerMessage | null} after
   */
  setLayers(before, after) {
    const panes = this.panes().length;
    const newLayer = this.before?.index !== before?.index;
    this.before = before;
    this.after = after;
    // Each layer is fitted anew (a small top layer is not a speck), unless the user has
    // zoomed or panned: then the view they chose stays.
    if (!this.view || this.panes().length !== panes || (newLayer && !this.userMoved)) this.fit();
    this.requestDraw();
  }

  /** Forgets the geometry and the view (a new file). */
  clear() {
    this.before = null;
    this.after = null;
    this.view = null;
    this.requestDraw();
  }

  /**
   * Changes a drawing setting and redraws.
   * @template {'colorBy' | 'showTravel' | 'mode'} K
   * @param {K} key
   * @param {this[K]} value
   */
  set(key, value) {
    const panes = this.panes().length;
    this[key] = value;
    // One pane to two (or back): the old scale would crop, fit again.
    if (this.view && this.panes().length !== panes) this.fit();
    this.requestDraw();
  }

  /**
   * The panes to draw: [{ geom, ghost, x, w }] in CSS px.
   * @returns {Pane[]}
   */
  panes() {
    const w = this.canvas.clientWidth;
    const hasAfter = !!this.after;
    const mode = hasAfter ? this.mode : 'before';
    if (mode === 'side') {
      const half = Math.floor(w / 2);
      return [
        { geom: this.before, x: 0, w: half, label: 'before' },
        { geom: this.after, x: half, w: w - half, label: 'after' },
      ];
    }
    if (mode === 'overlay') return [{ geom: this.after, ghost: this.before, x: 0, w, label: 'after over before' }];
    if (mode === 'after') return [{ geom: this.after, x: 0, w, label: 'after' }];
    return [{ geom: this.before, x: 0, w, label: hasAfter ? 'before' : '' }];
  }

  /**
   * Fits the view to the current layer's printed (non-travel) extent. The
   * extent drops the outermost 1 % of segment ends on each side, so that a
   * purge line at the bed's edge does not shrink the part to a speck.
   */
  fit() {
    this.userMoved = false;
    const g = this.before ?? this.after;
    if (!g) return;
    /** @type {number[]} */
    const xs = [];
    /** @type {number[]} */
    const ys = [];
    /** @param {boolean} onlyPrinting */
    const collect = (onlyPrinting) => {
      const { xy, kind } = g;
      for (let i = 0, n = kind.length; i < n; i++) {
        if (onlyPrinting && kind[i] === 0) continue;
        const o = 4 * i;
        xs.push(xy[o], xy[o + 2]);
        ys.push(xy[o + 1], xy[o + 3]);
      }
    };
    collect(true);
    if (xs.length === 0) collect(false);
    if (xs.length === 0) {
      this.fitBox(0, 0, 100, 100);
      return;
    }
    /** @param {number[]} a */
    const f = (a) => Float64Array.from(a).sort();
    const sx = f(xs);
    const sy = f(ys);
    const lo = Math.floor(0.01 * (sx.length - 1));
    const hi = Math.ceil(0.99 * (sx.length - 1));
    this.fitBox(sx[lo], sy[lo], sx[hi], sy[hi]);
  }

  /** The whole bed in view (B key), else the layer. */
  fitBed() {
    if (!this.bed || !(this.bed.length >= 3)) return this.fit();
    const xs = this.bed.map((p) => p[0]);
    const ys = this.bed.map((p) => p[1]);
    this.fitBox(Math.min(...xs), Math.min(...ys), Math.max(...xs), Math.max(...ys));
    this.userMoved = true;
  }

  /**
   * @param {number} minX
   * @param {number} minY
   * @param {number} maxX
   * @param {number} maxY
   */
  fitBox(minX, minY, maxX, maxY) {
    const pane = this.panes()[0];
    const h = this.canvas.clientHeight || 1;
    const spanX = Math.max(maxX - minX, 1);
    const spanY = Math.max(maxY - minY, 1);
    const scale = 0.85 * Math.min((pane.w || 1) / spanX, h / spanY);
    this.view = { cx: (minX + maxX) / 2, cy: (minY + maxY) / 2, scale: Math.min(MAX_SCALE, Math.max(MIN_SCALE, scale)) };
    this.requestDraw();
  }

  resize() {
    const dpr = window.devicePixelRatio || 1;
    const w = Math.max(1, Math.round(this.canvas.clientWidth * dpr));
    const h = Math.max(1, Math.round(this.canvas.clientHeight * dpr));
    if (this.canvas.width !== w || this.canvas.height !== h) {
      this.canvas.width = w;
      this.canvas.height = h;
    }
    this.draw();
  }

  requestDraw() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.draw();
    });
  }

  /**
   * Pane under CSS x, and the world point under (x, y). Needs a view.
   * @param {number} x
   * @param {number} y
   * @returns {{ pane: Pane, wx: number, wy: number }}
   */
  locate(x, y) {
    const panes = this.panes();
    const pane = panes.find((p) => x >= p.x && x < p.x + p.w) ?? panes[0];
    const h = this.canvas.clientHeight;
    const { cx, cy, scale } = /** @type {View} */ (this.view);
    return { pane, wx: cx + (x - pane.x - pane.w / 2) / scale, wy: cy - (y - h / 2) / scale };
  }

  installInput() {
    const c = this.canvas;
    c.addEventListener(
      'wheel',
      (e) => {
        if (!this.view) return;
        e.preventDefault();
        const r = c.getBoundingClientRect();
        const x = e.clientX - r.left;
        const y = e.clientY - r.top;
        const { pane, wx, wy } = this.locate(x, y);
        const factor = Math.exp(-e.deltaY * (e.deltaMode === 1 ? 0.05 : 0.0015));
        const scale = Math.min(MAX_SCALE, Math.max(MIN_SCALE, this.view.scale * factor));
        // Keep the world point under the cursor where it is.
        const h = c.clientHeight;
        this.view = {
          scale,
          cx: wx - (x - pane.x - pane.w / 2) / scale,
          cy: wy + (y - h / 2) / scale,
        };
        this.userMoved = true;
        this.requestDraw();
        this.hooks.onViewChange?.();
      },
      { passive: false },
    );
    /** @type {{ x: number, y: number, cx: number, cy: number } | null} */
    let drag = null;
    // Two fingers: pinch to zoom about their midpoint (phones and tablets).
    const touches = new Map();
    /** @type {{ d: number, x: number, y: number, scale: number, world: { pane: Pane, wx: number, wy: number } } | null} */
    let pinch = null;
    const pinchState = () => {
      const [a, b] = [...touches.values()];
      const r = c.getBoundingClientRect();
      return { d: Math.hypot(a.x - b.x, a.y - b.y) || 1, x: (a.x + b.x) / 2 - r.left, y: (a.y + b.y) / 2 - r.top };
    };
    c.addEventListener('pointerdown', (e) => {
      if (e.pointerType === 'touch') touches.set(e.pointerId, { x: e.clientX, y: e.clientY });
      if (touches.size === 2 && this.view) {
        const p = pinchState();
        pinch = { ...p, scale: this.view.scale, world: this.locate(p.x, p.y) };
        drag = null;
        return;
      }
      if (!this.view || e.button !== 0) return;
      drag = { x: e.clientX, y: e.clientY, cx: this.view.cx, cy: this.view.cy };
      try {
        c.setPointerCapture(e.pointerId);
      } catch {
        // a pointer the browser no longer tracks: drag without capture
      }
      c.classList.add('dragging');
    });
    let hoverFrame = 0;
    /** @type {[number, number]} */
    let hoverAt = [0, 0];
    c.addEventListener('pointermove', (e) => {
      if (touches.has(e.pointerId)) touches.set(e.pointerId, { x: e.clientX, y: e.clientY });
      if (pinch && touches.size === 2) {
        const p = pinchState();
        const scale = Math.min(MAX_SCALE, Math.max(MIN_SCALE, (pinch.scale * p.d) / pinch.d));
        const { pane, wx, wy } = pinch.world;
        const h = c.clientHeight;
        this.view = { scale, cx: wx - (p.x - pane.x - pane.w / 2) / scale, cy: wy + (p.y - h / 2) / scale };
        this.userMoved = true;
        this.requestDraw();
        return;
      }
      if (!drag) {
        // Readout of the segment under the cursor, at most once per frame.
        const r = c.getBoundingClientRect();
        hoverAt = [e.clientX - r.left, e.clientY - r.top];
        if (!hoverFrame) {
          hoverFrame = requestAnimationFrame(() => {
            hoverFrame = 0;
            this.hooks.onHover?.(this.pick(...hoverAt));
          });
        }
        return;
      }
      const view = /** @type {View} */ (this.view); // a drag starts only with a view
      const s = view.scale;
      if (e.clientX !== drag.x || e.clientY !== drag.y) this.userMoved = true;
      this.view = { ...view, cx: drag.cx - (e.clientX - drag.x) / s, cy: drag.cy + (e.clientY - drag.y) / s };
      this.requestDraw();
    });
    /** @param {PointerEvent} e */
    const end = (e) => {
      touches.delete(e?.pointerId);
      if (touches.size < 2) pinch = null;
      if (!drag) return;
      drag = null;
      c.classList.remove('dragging');
      this.hooks.onViewChange?.();
    };
    c.addEventListener('pointerleave', () => this.hooks.onHover?.(null));
    c.addEventListener('pointerup', end);
    c.addEventListener('pointercancel', end);
    c.addEventListener('dblclick', () => this.fit());
    // Keyboard: arrows pan, +/- zoom, 0 fits (the canvas is focusable).
    c.addEventListener('keydown', (e) => {
      if (!this.view) return;
      const step = 40 / this.view.scale;
      const v = { ...this.view };
      if (e.key === 'ArrowLeft') v.cx -= step;
      else if (e.key === 'ArrowRight') v.cx += step;
      else if (e.key === 'ArrowUp') v.cy += step;
      else if (e.key === 'ArrowDown') v.cy -= step;
      else if (e.key === '+' || e.key === '=') v.scale = Math.min(MAX_SCALE, v.scale * 1.25);
      else if (e.key === '-') v.scale = Math.max(MIN_SCALE, v.scale / 1.25);
      else if (e.key === '0') return this.fit();
      else if (e.key === 'b' || e.key === 'B') return this.fitBed();
      else return;
      e.preventDefault();
      this.userMoved = true;
      this.view = v;
      this.requestDraw();
    });
  }

  /**
   * The drawn segment nearest to CSS point (x, y), within a few pixels:
   * { which, kind, speed, curvature } or null.
   */
  /**
   * @param {number} x
   * @param {number} y
   * @returns {Hit | null}
   */
  pick(x, y) {
    if (!this.view) return null;
    const { pane, wx, wy } = this.locate(x, y);
    const g = pane.geom;
    if (!g) return null;
    const { xy, kind } = g;
    const limit = 6 / this.view.scale;
    let best = limit * limit;
    let found = -1;
    for (let i = 0, n = kind.length; i < n; i++) {
      if (kind[i] === 0 && !this.showTravel) continue;
      const o = 4 * i;
      const x0 = xy[o];
      const y0 = xy[o + 1];
      const dx = xy[o + 2] - x0;
      const dy = xy[o + 3] - y0;
      const len2 = dx * dx + dy * dy;
      const t = len2 > 0 ? Math.max(0, Math.min(1, ((wx - x0) * dx + (wy - y0) * dy) / len2)) : 0;
      const ex = x0 + t * dx - wx;
      const ey = y0 + t * dy - wy;
      const d2 = ex * ex + ey * ey;
      if (d2 < best) {
        best = d2;
        found = i;
      }
    }
    if (found < 0) return null;
    return { which: pane.label, kind: KINDS[kind[found]] ?? 'other', speed: g.speed[found], curvature: g.curvature[found], x: wx, y: wy };
  }

  /**
   * Value range for speed / curvature colouring, shared by before and after.
   * @returns {Range | null}
   */
  range() {
    if (this.colorBy === 'feature') return null;
    if (this.colorBy === 'layer-time') {
      const t = this.layerTime;
      return { key: 'layer-time', lo: t?.lo ?? 0, hi: t && t.hi > t.lo ? t.hi : (t?.lo ?? 0) + 1 };
    }
    const key = this.colorBy === 'speed' ? 'speed' : 'curvature';
    /** @type {number[]} */
    const values = [];
    for (const g of [this.before, this.after]) {
      if (!g) continue;
      const a = g[key];
      const step = Math.max(1, Math.floor(a.length / 20000)); // a sample is enough for a range
      for (let i = 0; i < a.length; i += step) if (g.kind[i] !== 0 && Number.isFinite(a[i])) values.push(a[i]);
    }
    if (values.length === 0) return { key, lo: 0, hi: 1 };
    values.sort((p, q) => p - q);
    // Curvature has a long tail (corners): clip at the 95th percentile.
    const lo = key === 'speed' ? values[0] : 0;
    const hi = key === 'speed' ? values[values.length - 1] : values[Math.floor(0.95 * (values.length - 1))];
    return { key, lo, hi: hi > lo ? hi : lo + 1 };
  }

  draw() {
    const { ctx, canvas } = this;
    const dpr = window.devicePixelRatio || 1;
    ctx.setTransform(1, 0, 0, 1, 0, 0);
    ctx.clearRect(0, 0, canvas.width, canvas.height);
    let drawn = 0;
    const range = this.range();
    if (this.view && (this.before || this.after)) {
      const h = canvas.clientHeight;
      const panes = this.panes();
      for (const p of panes) {
        ctx.save();
        ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
        ctx.beginPath();
        ctx.rect(p.x, 0, p.w, h);
        ctx.clip();
        this.drawBounds(p, h);
        if (p.ghost) this.drawGeometry(p.ghost, p, h, null, true);
        if (p.geom) drawn += this.drawGeometry(p.geom, p, h, range, false);
        if (panes.length > 1 || p.label) {
          ctx.font = '12px system-ui, sans-serif';
          ctx.fillStyle = getComputedStyle(canvas).color;
          ctx.fillText(p.label + (p.geom && typeof p.geom.z === 'number' && Number.isFinite(p.geom.z) ? `  z = ${p.geom.z.toFixed(2)} mm` : ''), p.x + 8, 16);
        }
        ctx.restore();
      }
      if (panes.length > 1) {
        ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
        ctx.strokeStyle = 'rgba(128,128,128,0.5)';
        ctx.lineWidth = 1;
        ctx.beginPath();
        ctx.moveTo(panes[1].x + 0.5, 0);
        ctx.lineTo(panes[1].x + 0.5, h);
        ctx.stroke();
      }
    }
    if (this.view && (this.before || this.after)) this.drawScaleBar(canvas.clientHeight);
    canvas.dataset.segments = String(drawn);
    canvas.dataset.scale = this.view ? String(this.view.scale) : '';
    const bed = this.bed;
    if (bed && bed.length >= 3) {
      const xs = bed.map((p) => p[0]);
      const ys = bed.map((p) => p[1]);
      canvas.dataset.bed = `${+(Math.max(...xs) - Math.min(...xs)).toFixed(1)} × ${+(Math.max(...ys) - Math.min(...ys)).toFixed(1)} mm`;
    } else delete canvas.dataset.bed;
    this.renderLegend(range);
    const label = this.describe(drawn);
    if (canvas.getAttribute('aria-label') !== label) canvas.setAttribute('aria-label', label);
  }

  /**
   * The canvas's text alternative, kept in step with every redraw: which layer is shown (its
   * number and height), what is drawn and in which colours (the legend), and the keys.
   * @param {number} segments how many segments the last draw stroked
   * @returns {string}
   */
  describe(segments) {
    const keys = 'Wheel or +/- to zoom, drag or arrow keys to pan, double-click or 0 to fit the layer, B to see the whole bed.';
    const g = this.before ?? this.after;
    if (!g || !this.view) return `Toolpath of the selected layer: nothing loaded yet. ${keys}`;
    /** @param {LayerMessage | null} l */
    const z = (l) => (l && typeof l.z === 'number' && Number.isFinite(l.z) ? `z = ${l.z.toFixed(2)} mm` : 'no height');
    const panes = this.panes();
    const what = panes.length > 1 ? `before and after side by side (after at ${z(this.after)})` : panes[0].label === 'after over before' ? `the optimized file (at ${z(this.after)}) over the original` : panes[0].label === 'after' ? `the optimized file, at ${z(this.after)}` : 'the file';
    const colours = { feature: 'feature', speed: 'speed', curvature: 'curvature', 'layer-time': 'layer time' }[this.colorBy] ?? this.colorBy;
    // The legend's entries: a swatch and its name, or the colour ramp's ends ("12 to 150 mm/s").
    const legend = [...this.legend.children]
      .map((li) => [...li.childNodes].map((n) => (n.textContent ?? '').trim()).filter(Boolean).join(li.classList.contains('ramp') ? ' to ' : ' '))
      .filter(Boolean)
      .join(', ');
    return `Layer ${g.index + 1} of ${g.count}, ${z(g)}: ${what}, ${segments.toLocaleString('en-US')} segments drawn, coloured by ${colours}${legend ? ` (${legend})` : ''}. ${keys}`;
  }

  /**
   * The whole print's XY extent as a dashed outline, so a layer is seen in its place.
   * @param {Pane} pane
   * @param {number} h the canvas height, CSS px
   */
  drawBounds(pane, h) {
    const b = this.bounds;
    if (!this.view) return;
    const { ctx, bed } = this;
    const { cx, cy, scale } = this.view;
    const ox = pane.x + pane.w / 2 - cx * scale;
    const oy = h / 2 + cy * scale;
    if (bed && bed.length >= 3) {
      // The bed: a solid outline and a faint fill.
      ctx.save();
      ctx.beginPath();
      bed.forEach(([x, y], i) => (i ? ctx.lineTo(ox + x * scale, oy - y * scale) : ctx.moveTo(ox + x * scale, oy - y * scale)));
      ctx.closePath();
      ctx.fillStyle = 'rgba(128,128,128,0.06)';
      ctx.fill();
      ctx.strokeStyle = 'rgba(128,128,128,0.8)';
      ctx.lineWidth = 1.5;
      ctx.stroke();
      ctx.restore();
    }
    if (!b) return;
    ctx.save();
    ctx.strokeStyle = 'rgba(128,128,128,0.55)';
    ctx.lineWidth = 1;
    ctx.setLineDash([6, 4]);
    ctx.strokeRect(ox + b.minX * scale, oy - b.maxY * scale, (b.maxX - b.minX) * scale, (b.maxY - b.minY) * scale);
    ctx.restore();
  }

  /**
   * A scale bar of a round length (1, 2 or 5 × 10ⁿ mm), about 100 px long, bottom left.
   * Needs a view.
   * @param {number} h the canvas height, CSS px
   */
  drawScaleBar(h) {
    const { ctx } = this;
    const { scale } = /** @type {View} */ (this.view);
    const dpr = window.devicePixelRatio || 1;
    const target = 100 / scale; // mm in 100 px
    const pow = 10 ** Math.floor(Math.log10(target));
    const mm = [1, 2, 5, 10].map((m) => m * pow).filter((v) => v <= target * 1.5).pop() ?? pow;
    const px = mm * scale;
    ctx.save();
    ctx.setTransform(dpr, 0, 0, dpr, 0, 0);
    const color = getComputedStyle(this.canvas).color;
    ctx.strokeStyle = color;
    ctx.fillStyle = color;
    ctx.lineWidth = 2;
    const x = 12;
    const y = h - 14;
    ctx.beginPath();
    ctx.moveTo(x, y - 5);
    ctx.lineTo(x, y);
    ctx.lineTo(x + px, y);
    ctx.lineTo(x + px, y - 5);
    ctx.stroke();
    ctx.font = '12px system-ui, sans-serif';
    const label = mm >= 1 ? `${+mm.toFixed(0)} mm` : `${+mm.toPrecision(1)} mm`;
    ctx.fillText(label, x + px + 6, y + 1);
    ctx.restore();
    this.canvas.dataset.scaleBar = label;
  }

  /**
   * Strokes one geometry into a pane; returns the number of segments drawn. Needs a view.
   * @param {LayerMessage} g
   * @param {Pane} pane
   * @param {number} h the canvas height, CSS px
   * @param {Range | null} range colour by this value range, or by feature when null
   * @param {boolean} ghost grey, under the other file
   * @returns {number}
   */
  drawGeometry(g, pane, h, range, ghost) {
    const { ctx } = this;
    const { cx, cy, scale } = /** @type {View} */ (this.view);
    const ox = pane.x + pane.w / 2 - cx * scale;
    const oy = h / 2 + cy * scale;
    const { xy, kind } = g;
    const n = kind.length;
    // Bucket of each segment: -1 skipped, 0 travel, 1.. colour buckets.
    const bucket = new Int8Array(n);
    let colors;
    if (ghost) {
      colors = [null, 'rgba(140,140,140,0.35)'];
      for (let i = 0; i < n; i++) bucket[i] = kind[i] === 0 ? -1 : 1;
    } else if (!range) {
      colors = [null, ...KIND_COLORS.slice(1)];
      for (let i = 0; i < n; i++) bucket[i] = kind[i];
    } else {
      colors = [null, ...RAMP];
      const k = BUCKETS / (range.hi - range.lo);
      /** @param {number} v */
      const toBucket = (v) => {
        const b = Math.floor((v - range.lo) * k);
        return 1 + (b < 0 ? 0 : b >= BUCKETS ? BUCKETS - 1 : b);
      };
      if (range.key === 'layer-time') {
        // The whole layer in the colour of its print time (short layers cool badly).
        const t = g === this.after ? this.layerTime?.after : this.layerTime?.before;
        const b = typeof t === 'number' && Number.isFinite(t) ? toBucket(t) : -1;
        for (let i = 0; i < n; i++) bucket[i] = kind[i] === 0 ? 0 : b;
      } else {
        const a = g[range.key];
        for (let i = 0; i < n; i++) if (kind[i] !== 0) bucket[i] = toBucket(a[i]);
      }
    }
    // Extrusion lines about as wide as a real line when zoomed in.
    const width = Math.max(1, Math.min(0.45 * scale, 8));
    ctx.lineCap = 'round';
    ctx.lineJoin = 'round';
    let drawn = 0;
    /**
     * @param {number} b the bucket
     * @param {string} style
     * @param {number} lw line width, CSS px
     * @param {number[]} dash
     */
    const strokeBucket = (b, style, lw, dash) => {
      ctx.beginPath();
      let px = NaN;
      let py = NaN;
      let count = 0;
      for (let i = 0; i < n; i++) {
        if (bucket[i] !== b) continue;
        const o = 4 * i;
        const x0 = ox + xy[o] * scale;
        const y0 = oy - xy[o + 1] * scale;
        // Consecutive segments share an end: continue the polyline.
        if (x0 !== px || y0 !== py) ctx.moveTo(x0, y0);
        px = ox + xy[o + 2] * scale;
        py = oy - xy[o + 3] * scale;
        ctx.lineTo(px, py);
        count++;
      }
      if (count === 0) return 0;
      ctx.strokeStyle = style;
      ctx.lineWidth = lw;
      ctx.setLineDash(dash);
      ctx.stroke();
      return count;
    };
    if (this.showTravel && !ghost) drawn += strokeBucket(0, 'rgba(140,150,146,0.7)', 0.75, [3, 3]);
    for (let b = 1; b < colors.length; b++) drawn += strokeBucket(b, /** @type {string} */ (colors[b]), ghost ? Math.max(1, width * 0.8) : width, []);
    ctx.setLineDash([]);
    return drawn;
  }

  /** @param {Range | null} range */
  renderLegend(range) {
    const items = [];
    /**
     * @param {string} color
     * @param {string} label
     * @param {boolean} [dashed]
     */
    const swatch = (color, label, dashed) => {
      const li = document.createElement('li');
      const s = document.createElement('span');
      s.className = dashed ? 'swatch dashed' : 'swatch';
      s.style.background = dashed ? 'transparent' : color;
      if (dashed) s.style.borderColor = color;
      li.append(s, label);
      return li;
    };
    if (!range) {
      const present = new Set();
      for (const g of [this.before, this.after]) if (g) for (const k of g.kind) present.add(k);
      for (let k = 1; k < KINDS.length; k++) if (present.has(k)) items.push(swatch(KIND_COLORS[k], KINDS[k]));
    } else {
      const unit = range.key === 'speed' ? 'mm/s' : range.key === 'layer-time' ? 's per layer' : '1/mm';
      /** @param {number} v */
      const fmt = (v) => (Math.abs(v) >= 10 ? v.toFixed(0) : v.toFixed(2));
      const li = document.createElement('li');
      li.className = 'ramp';
      const bar = document.createElement('span');
      bar.className = 'ramp-bar';
      bar.style.background = `linear-gradient(to right, ${RAMP.join(', ')})`;
      li.append(`${fmt(range.lo)}`, bar, `${fmt(range.hi)}${range.key === 'curvature' ? '+' : ''} ${unit}`);
      items.push(li);
    }
    if (this.showTravel) items.push(swatch('#9aa4a0', 'travel', true));
    if ((this.bed?.length ?? 0) >= 3) items.push(swatch('rgba(128,128,128,0.8)', `bed ${this.canvas.dataset.bed ?? ''}`, true));
    if (this.bounds) items.push(swatch('rgba(128,128,128,0.55)', 'the whole print', true));
    this.legend.replaceChildren(...items);
  }
}
