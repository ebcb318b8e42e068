// @ts-check
// 3-D view of the whole part (or a layer range): every layer's toolpath (Session.layer
// geometry) stacked at its height, drawn with three.js (vendored by `make pkg` into
// www/vendor/ from npm, so the page still makes no outside request). Loaded on demand by
// app.js (dynamic import) the first time the 3-D view is picked: the 2-D page never pays for it.
//
// Orbit by dragging, pan with the right button (or Shift+drag), zoom with the wheel, two
// fingers pinch to zoom and drag to orbit. Colours are those of the 2-D viewer (feature,
// speed, curvature, layer time); travels on demand; "after" over a grey "before". A multi-axis
// file is drawn on its workpiece instead: LayerGeometry.xyz, the tool tip in the workpiece frame
// (computed by the crate's orient module), a true 3-D path rather than machine X, Y stacked at
// the layer's height, which for a turning table lies tens of mm from where the material goes.
// It also gets its tool vectors (LayerGeometry.tool, same frame, same tips): short segments
// from the tool tip up the tool axis, every n-th of them, each starting on the drawn path.

import * as THREE from './vendor/three.module.js';
import { KINDS, KIND_COLORS, RAMP } from './viewer.js';

/**
 * One layer to draw: its drawing data and its print time (for the layer-time colours).
 * @typedef {import('./jobs.js').LayerMessage & { time?: number | null }} PartLayer
 */
/**
 * How to draw: the colouring, travels, tool vectors (multi-axis files), the value range of
 * speed, curvature or layer time, and the bed's outline ([[x, y], …] in mm) when known.
 * @typedef {{ colorBy: string, showTravel: boolean, showTools?: boolean, range: { lo: number, hi: number } | null, bed?: number[][] | null }} DrawOptions
 */

const GHOST = new THREE.Color('#9aa4a0');
const TRAVEL = new THREE.Color('#8c9692');
/** Colour of the tool vectors: a magenta none of the feature colours or ramps comes near. */
export const TOOL_COLOR = '#ff00cc';
/** Length of a drawn tool vector, mm: long enough to read the tilt, short beside the part. */
const TOOL_LENGTH_MM = 4;
/** Most tool vectors drawn: one per extruding move would hide the part, so every n-th. */
const MAX_TOOL_VECTORS = 2500;

export class PartView {
  /** @param {HTMLCanvasElement} canvas */
  constructor(canvas) {
    this.canvas = canvas;
    // preserveDrawingBuffer: the picture can be read back (tests, screenshots).
    this.renderer = new THREE.WebGLRenderer({ canvas, antialias: true, preserveDrawingBuffer: true });
    this.renderer.setPixelRatio(window.devicePixelRatio || 1);
    this.scene = new THREE.Scene();
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.1, 100000);
    this.camera.up.set(0, 0, 1);
    this.orbit = { theta: -Math.PI / 3, phi: Math.PI / 3.2, radius: 200, target: new THREE.Vector3() };
    /** @type {THREE.Line<THREE.BufferGeometry, THREE.LineBasicMaterial>[]} */
    this.objects = [];
    this.frame = 0;
    this.fitted = false;
    this.installInput();
    this.resizeObserver = new ResizeObserver(() => this.resize());
    this.resizeObserver.observe(canvas);
    this.resize();
  }

  /**
   * Draws layers: `layers` [{ z, xy, kind, speed, curvature, xyz, tool, time }] of the shown
   * file (through xyz, the workpiece frame, when a multi-axis layer has it),
   * `ghost` the same of the other one (drawn grey) or null; `opts` { colorBy, showTravel,
   * range: { lo, hi } for speed/curvature/layer time }. Keeps the camera unless `refit`.
   * @param {PartLayer[]} layers
   * @param {PartLayer[] | null} ghost
   * @param {DrawOptions} opts
   * @param {boolean} refit
   */
  setLayers(layers, ghost, opts, refit) {
    for (const o of this.objects) {
      this.scene.remove(o);
      o.geometry.dispose();
      o.material.dispose();
    }
    this.objects = [];
    let segments = 0;
    const box = new THREE.Box3();
    /**
     * @param {PartLayer[]} list
     * @param {boolean} isGhost
     */
    const add = (list, isGhost) => {
      const lines = build(list, isGhost, opts);
      if (!lines) return null;
      segments += lines.geometry.getAttribute('position').count / 2;
      lines.geometry.computeBoundingBox();
      box.union(/** @type {THREE.Box3} */ (lines.geometry.boundingBox));
      this.scene.add(lines);
      this.objects.push(lines);
      return lines;
    };
    if (ghost) add(ghost, true);
    const shownLines = add(layers, false);
    const tools = opts.showTools ? buildTools(layers) : null;
    this.canvas.dataset.toolOffsetMm = tools && shownLines ? String(toolOffset(positions(shownLines), positions(tools))) : '';
    if (tools) {
      tools.geometry.computeBoundingBox();
      box.union(/** @type {THREE.Box3} */ (tools.geometry.boundingBox));
      this.scene.add(tools);
      this.objects.push(tools);
    }
    this.canvas.dataset.toolVectors = String(tools ? tools.geometry.getAttribute('position').count / 2 : 0);
    if (opts.bed && opts.bed.length >= 3) {
      // The bed at z = 0, as an outline.
      const pts = opts.bed.map(([x, y]) => new THREE.Vector3(x, y, 0));
      const bed = new THREE.LineLoop(new THREE.BufferGeometry().setFromPoints(pts), new THREE.LineBasicMaterial({ color: '#8c9692' }));
      this.scene.add(bed);
      this.objects.push(bed);
    }
    this.canvas.dataset.segments = String(segments);
    if ((refit || !this.fitted) && !box.isEmpty()) this.fit(box);
    this.requestDraw();
  }

  /** @param {THREE.Box3} box */
  fit(box) {
    const size = box.getSize(new THREE.Vector3());
    box.getCenter(this.orbit.target);
    this.orbit.radius = Math.max(size.x, size.y, size.z, 1) * 1.6;
    this.fitted = true;
    this.requestDraw();
  }

  resize() {
    const w = Math.max(1, this.canvas.clientWidth);
    const h = Math.max(1, this.canvas.clientHeight);
    this.renderer.setSize(w, h, false);
    this.camera.aspect = w / h;
    this.camera.updateProjectionMatrix();
    this.draw();
  }

  requestDraw() {
    if (this.frame) return;
    this.frame = requestAnimationFrame(() => {
      this.frame = 0;
      this.draw();
    });
  }

  draw() {
    const { theta, phi, radius, target } = this.orbit;
    this.camera.position.set(
      target.x + radius * Math.sin(phi) * Math.cos(theta),
      target.y + radius * Math.sin(phi) * Math.sin(theta),
      target.z + radius * Math.cos(phi),
    );
    this.camera.near = Math.max(0.01, radius / 1000);
    this.camera.far = radius * 20;
    this.camera.updateProjectionMatrix();
    this.camera.lookAt(target);
    this.renderer.setClearColor(getComputedStyle(this.canvas).backgroundColor || '#f4f6f5', 1);
    this.renderer.render(this.scene, this.camera);
  }

  installInput() {
    const c = this.canvas;
    const pointers = new Map();
    /** @type {{ x: number, y: number, pan: boolean, d: number | null } | null} */
    let last = null;
    /** @type {(dx: number, dy: number) => void} */
    const orbitBy = (dx, dy) => {
      this.orbit.theta -= dx * 0.008;
      this.orbit.phi = Math.min(Math.PI - 0.05, Math.max(0.05, this.orbit.phi - dy * 0.008));
    };
    /** @type {(dx: number, dy: number) => void} */
    const panBy = (dx, dy) => {
      const scale = this.orbit.radius / c.clientHeight;
      const right = new THREE.Vector3().setFromMatrixColumn(this.camera.matrixWorld, 0);
      const up = new THREE.Vector3().setFromMatrixColumn(this.camera.matrixWorld, 1);
      this.orbit.target.addScaledVector(right, -dx * scale).addScaledVector(up, dy * scale);
    };
    /** @param {number} factor */
    const zoom = (factor) => {
      this.orbit.radius = Math.min(1e5, Math.max(0.5, this.orbit.radius * factor));
    };
    c.addEventListener('pointerdown', (e) => {
      pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
      last = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey, d: null };
      try {
        c.setPointerCapture(e.pointerId);
      } catch {
        // not a tracked pointer: no capture
      }
    });
    c.addEventListener('pointermove', (e) => {
      if (!pointers.has(e.pointerId) || !last) return;
      pointers.set(e.pointerId, { x: e.clientX, y: e.clientY });
      if (pointers.size === 2) {
        const [a, b] = [...pointers.values()];
        const d = Math.hypot(a.x - b.x, a.y - b.y);
        if (last.d) zoom(last.d / d);
        last.d = d;
      } else {
        const dx = e.clientX - last.x;
        const dy = e.clientY - last.y;
        if (last.pan) panBy(dx, dy);
        else orbitBy(dx, dy);
        last.x = e.clientX;
        last.y = e.clientY;
      }
      this.requestDraw();
    });
    /** @param {PointerEvent} e */
    const end = (e) => {
      pointers.delete(e.pointerId);
      if (pointers.size === 0) last = null;
      else if (last) last.d = null;
    };
    c.addEventListener('pointerup', end);
    c.addEventListener('pointercancel', end);
    c.addEventListener('contextmenu', (e) => e.preventDefault());
    c.addEventListener(
      'wheel',
      (e) => {
        e.preventDefault();
        zoom(Math.exp(e.deltaY * (e.deltaMode === 1 ? 0.05 : 0.0015)));
        this.requestDraw();
      },
      { passive: false },
    );
    c.addEventListener('keydown', (e) => {
      /** @type {Record<string, [number, number]>} */
      const keys = { ArrowLeft: [-20, 0], ArrowRight: [20, 0], ArrowUp: [0, -20], ArrowDown: [0, 20] };
      if (keys[e.key]) orbitBy(...keys[e.key]);
      else if (e.key === '+' || e.key === '=') zoom(0.8);
      else if (e.key === '-') zoom(1.25);
      else return;
      e.preventDefault();
      this.requestDraw();
    });
  }

  dispose() {
    this.resizeObserver.disconnect();
    this.renderer.dispose();
  }
}

/**
 * One LineSegments of every segment of `list`, coloured per vertex.
 * @param {PartLayer[]} list
 * @param {boolean} ghost
 * @param {DrawOptions} opts
 * @returns {THREE.LineSegments<THREE.BufferGeometry, THREE.LineBasicMaterial> | null}
 */
function build(list, ghost, { colorBy, showTravel, range }) {
  let n = 0;
  for (const g of list) for (const k of g.kind) if (k !== 0 || (showTravel && !ghost)) n++;
  if (n === 0) return null;
  const pos = new Float32Array(n * 6);
  const col = new Float32Array(n * 6);
  const kindColors = KIND_COLORS.map((c) => new THREE.Color(c));
  const ramp = RAMP.map((c) => new THREE.Color(c));
  /** @param {number | null | undefined} v */
  const rampAt = (v) => {
    if (!range || typeof v !== 'number' || !Number.isFinite(v)) return ramp[0];
    const t = (v - range.lo) / (range.hi - range.lo || 1);
    return ramp[Math.min(ramp.length - 1, Math.max(0, Math.floor(t * ramp.length)))];
  };
  let j = 0;
  for (const g of list) {
    const z = typeof g.z === 'number' && Number.isFinite(g.z) ? g.z : 0;
    const { xy, kind } = g;
    // A multi-axis layer: its segments on the workpiece, parallel to xy (same kinds, colours).
    const xyz = g.xyz && g.xyz.length === 6 * kind.length ? g.xyz : null;
    for (let i = 0; i < kind.length; i++) {
      const travel = kind[i] === 0;
      if (travel && !(showTravel && !ghost)) continue;
      let c;
      if (ghost) c = GHOST;
      else if (travel) c = TRAVEL;
      else if (colorBy === 'speed') c = rampAt(g.speed[i]);
      else if (colorBy === 'curvature') c = rampAt(g.curvature[i]);
      else if (colorBy === 'layer-time') c = rampAt(g.time);
      else c = kindColors[kind[i]] ?? kindColors[KINDS.length - 1];
      const o = 4 * i;
      if (xyz) pos.set(xyz.subarray(6 * i, 6 * i + 6), j * 6);
      else pos.set([xy[o], xy[o + 1], z, xy[o + 2], xy[o + 3], z], j * 6);
      col.set([c.r, c.g, c.b, c.r, c.g, c.b], j * 6);
      j++;
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  geometry.setAttribute('color', new THREE.BufferAttribute(col, 3));
  const material = new THREE.LineBasicMaterial({ vertexColors: true, transparent: ghost, opacity: ghost ? 0.35 : 1 });
  return new THREE.LineSegments(geometry, material);
}

/**
 * Tool vectors available in `list` (LayerGeometry.tool holds six numbers per vector).
 * @param {PartLayer[]} list
 * @returns {number}
 */
export function toolCount(list) {
  let n = 0;
  for (const g of list) n += Math.floor((g.tool?.length ?? 0) / 6);
  return n;
}

/**
 * The tool vectors of `list` as one LineSegments: from each tool tip TOOL_LENGTH_MM along the
 * unit tool vector, every n-th so that at most MAX_TOOL_VECTORS are drawn; null when there are
 * none (a three-axis file).
 * @param {PartLayer[]} list
 * @returns {THREE.LineSegments<THREE.BufferGeometry, THREE.LineBasicMaterial> | null}
 */
function buildTools(list) {
  const total = toolCount(list);
  if (total === 0) return null;
  const stride = Math.ceil(total / MAX_TOOL_VECTORS);
  const pos = new Float32Array(Math.ceil(total / stride) * 6);
  let seen = 0;
  let j = 0;
  for (const g of list) {
    const t = g.tool;
    if (!t) continue;
    for (let o = 0; o + 6 <= t.length; o += 6, seen++) {
      if (seen % stride !== 0) continue;
      const L = TOOL_LENGTH_MM;
      pos.set([t[o], t[o + 1], t[o + 2], t[o] + L * t[o + 3], t[o + 1] + L * t[o + 4], t[o + 2] + L * t[o + 5]], j * 6);
      j++;
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.BufferAttribute(pos.subarray(0, j * 6), 3));
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: TOOL_COLOR }));
}

/**
 * The vertex positions of a drawn LineSegments (x, y, z each).
 * @param {THREE.LineSegments<THREE.BufferGeometry, THREE.LineBasicMaterial> | THREE.Line<THREE.BufferGeometry, THREE.LineBasicMaterial>} lines
 * @returns {ArrayLike<number>}
 */
function positions(lines) {
  return lines.geometry.getAttribute('position').array;
}

/** Grid cell of the nearest-vertex search in toolOffset, mm. */
const OFFSET_CELL_MM = 1;
/** Most tool vectors without a drawn vertex within a cell whose distance toolOffset searches for. */
const OFFSET_SLOW_MAX = 50;

/**
 * How far the drawn tool vectors start from the drawn path, mm: the largest distance from a
 * vector's base (even vertices of `tools`) to its nearest path vertex (`path`, x, y, z each).
 * 0 when each vector starts on the path, as the crate's shared tips make it; the canvas shows
 * it as data-tool-offset-mm, for the tests. One pass over the path: each base is registered in
 * the 27 grid cells around its own, so a vertex finds the bases within a cell by one lookup. A
 * base with none (a broken drawing) is measured against every vertex, at most OFFSET_SLOW_MAX
 * of them, so the result is then a lower bound, already far above a tolerance.
 * @param {ArrayLike<number>} path
 * @param {ArrayLike<number>} tools
 * @returns {number}
 */
export function toolOffset(path, tools) {
  const cell = (/** @type {number} */ v) => Math.floor(v / OFFSET_CELL_MM);
  const key = (/** @type {number} */ x, /** @type {number} */ y, /** @type {number} */ z) => `${x},${y},${z}`;
  /** @type {Map<string, number[]>} */
  const near = new Map();
  const bases = Math.floor(tools.length / 6);
  const best = new Float64Array(bases).fill(Infinity);
  for (let b = 0; b < bases; b++) {
    const [cx, cy, cz] = [0, 1, 2].map((k) => cell(tools[6 * b + k]));
    for (let dx = -1; dx <= 1; dx++)
      for (let dy = -1; dy <= 1; dy++)
        for (let dz = -1; dz <= 1; dz++) {
          const k = key(cx + dx, cy + dy, cz + dz);
          const list = near.get(k);
          if (list) list.push(b);
          else near.set(k, [b]);
        }
  }
  const dist = (/** @type {number} */ b, /** @type {number} */ v) =>
    Math.hypot(path[v] - tools[6 * b], path[v + 1] - tools[6 * b + 1], path[v + 2] - tools[6 * b + 2]);
  for (let v = 0; v + 2 < path.length; v += 3) {
    for (const b of near.get(key(cell(path[v]), cell(path[v + 1]), cell(path[v + 2]))) ?? []) best[b] = Math.min(best[b], dist(b, v));
  }
  let slow = 0;
  for (let b = 0; b < bases && slow < OFFSET_SLOW_MAX; b++) {
    if (best[b] !== Infinity) continue;
    slow++;
    for (let v = 0; v + 2 < path.length; v += 3) best[b] = Math.min(best[b], dist(b, v));
  }
  let max = 0;
  // Bases past OFFSET_SLOW_MAX stay unmeasured (Infinity), left out of the lower bound.
  for (let b = 0; b < bases; b++) if (best[b] !== Infinity) max = Math.max(max, best[b]);
  return max;
}
