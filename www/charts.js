// @ts-check
// Charts of the job results, drawn with uPlot (vendored by `make pkg` into
// www/vendor/, so the page still makes no outside request). Each chart lives in
// its own container and is redrawn from scratch when its data changes; a
// ResizeObserver keeps it as wide as the container.

import uPlot from './vendor/uPlot.esm.js';

const PALETTE = ['#1f6f5c', '#e4572e', '#2e86ab', '#f3a712', '#5a4fcf', '#a23b72', '#29bf12', '#7f7f7f'];
const MAX_POINTS = 20000;

/** @typedef {{ label?: string, x: number[], y: number[] }} Series one (x, y) line of alignSeries and unionSeries */

/** @type {WeakMap<HTMLElement, { plot: uPlot, observer: ResizeObserver }>} */
const charts = new WeakMap(); // container → { plot, observer }

/**
 * A line chart's description (lineChart).
 * @typedef {object} ChartSpec
 * @property {string} [title]
 * @property {number[]} x
 * @property {string} xLabel
 * @property {string} yLabel
 * @property {boolean} [logY]
 * @property {boolean} [points]
 * @property {number} [height]
 * @property {{ label: string, values: (number | null | undefined)[], color?: string, dash?: number[] }[]} series
 * @property {(index: number, x: number) => void} [onPick] a click on the plot, at the data point under the cursor
 */

/**
 * Removes the chart in `container` and shows `message` instead.
 * @param {HTMLElement} container
 * @param {string} message
 */
export function clearChart(container, message) {
  const prev = charts.get(container);
  if (prev) {
    prev.observer.disconnect();
    prev.plot.destroy();
    charts.delete(container);
  }
  const p = document.createElement('p');
  p.className = 'empty';
  p.textContent = message;
  container.replaceChildren(p);
  container.dataset.series = '0';
  // The message is text: no picture to describe.
  container.removeAttribute('role');
  container.removeAttribute('aria-label');
}

/**
 * A chart's text alternative: its caption (or what it plots against what), the x range, and
 * each series' lowest and highest values with where they are ("time from 11.6 s at layer 11 to
 * 147 s at layer 10"). Labels are "name, unit" or a bare name.
 * @param {HTMLElement} container
 * @param {ChartSpec} spec
 * @returns {string}
 */
export function describeChart(container, spec) {
  /** @param {number} v */
  const fmt = (v) => (Math.abs(v) >= 100 || Number.isInteger(v) ? Math.round(v).toLocaleString('en-US') : String(Number(v.toPrecision(3))));
  /** @param {string} label */
  const split = (label) => {
    const [name, unit] = label.split(/,\s*(?=[^,]*$)/);
    return { name, unit: unit ? (unit === '°' ? unit : ` ${unit}`) : '' };
  };
  const caption = container.closest('figure')?.querySelector('figcaption')?.textContent?.trim();
  const name = spec.title ?? caption ?? `${spec.yLabel} against ${spec.xLabel}`;
  const { x } = spec;
  if (x.length === 0) return `${name}: no data.`;
  const xl = split(spec.xLabel);
  /** @param {number} v */
  const atX = (v) => `${xl.name} ${fmt(v)}${xl.unit}`;
  const series = spec.series.map((s) => {
    const sl = split(s.label);
    const unit = sl.unit || split(spec.yLabel).unit;
    let lo = -1;
    let hi = -1;
    s.values.forEach((v, j) => {
      if (v == null || !Number.isFinite(v)) return;
      if (lo < 0 || v < /** @type {number} */ (s.values[lo])) lo = j;
      if (hi < 0 || v > /** @type {number} */ (s.values[hi])) hi = j;
    });
    if (lo < 0) return `${sl.name}: no values`;
    const at = (/** @type {number} */ j) => `${fmt(/** @type {number} */ (s.values[j]))}${unit} at ${atX(x[j])}`;
    return `${sl.name} from ${at(lo)} to ${at(hi)}`;
  });
  return `${name}: ${x.length} points, ${xl.name} ${fmt(x[0])} to ${fmt(x[x.length - 1])}${xl.unit}; ${series.join('; ')}.`;
}

/**
 * Keeps every k-th point so a long series stays quick to draw (uPlot itself
 * copes with 10⁵ points, but the orientation series can be much longer).
 * @param {number[]} x
 * @param {(number | null | undefined)[][]} ys
 * @returns {[number[], (number | null | undefined)[][]]}
 */
function thin(x, ys) {
  if (x.length <= MAX_POINTS) return [x, ys];
  const k = Math.ceil(x.length / MAX_POINTS);
  /** @type {<T>(a: T[]) => T[]} */
  const pick = (a) => a.filter((_, i) => i % k === 0);
  return [pick(x), ys.map(pick)];
}

/**
 * Draws a line chart in `container`.
 * @param {HTMLElement} container
 * @param {ChartSpec} spec
 * @returns {uPlot}
 */
export function lineChart(container, spec) {
  const prev = charts.get(container);
  if (prev) {
    prev.observer.disconnect();
    prev.plot.destroy();
  }
  container.replaceChildren();
  const [x, ys] = thin(spec.x, spec.series.map((s) => s.values));
  // A log axis cannot show zero or negative values: leave a gap there.
  /** @type {uPlot.AlignedData} */
  const data = [x, ...ys.map((v) => (spec.logY ? v.map((y) => (y != null && y > 0 ? y : null)) : v))];
  const width = Math.max(280, container.clientWidth || 600);
  /** @type {uPlot.Options} */
  const opts = {
    title: spec.title,
    width,
    height: spec.height ?? 260,
    scales: { x: { time: false }, y: spec.logY ? { distr: 3, log: 10 } : {} },
    axes: [
      { label: spec.xLabel, stroke: 'currentColor', grid: { stroke: 'rgba(128,128,128,0.18)' }, ticks: { stroke: 'rgba(128,128,128,0.3)' } },
      { label: spec.yLabel, stroke: 'currentColor', grid: { stroke: 'rgba(128,128,128,0.18)' }, ticks: { stroke: 'rgba(128,128,128,0.3)' }, size: 64 },
    ],
    series: [
      { label: spec.xLabel },
      ...spec.series.map((s, i) => ({
        label: s.label,
        stroke: s.color ?? PALETTE[i % PALETTE.length],
        width: 1.5,
        dash: s.dash,
        spanGaps: true,
        points: { show: spec.points ?? x.length <= 60 },
      })),
    ],
    legend: { live: true },
    cursor: { drag: { x: true, y: false } },
  };
  const plot = new uPlot(opts, data, container);
  const onPick = spec.onPick;
  if (onPick) {
    plot.over.style.cursor = 'pointer';
    /** @type {[number, number] | null} */
    let down = null;
    plot.over.addEventListener('mousedown', (e) => {
      down = [e.clientX, e.clientY];
    });
    plot.over.addEventListener('click', (e) => {
      // A drag is a zoom, not a pick.
      if (down && Math.hypot(e.clientX - down[0], e.clientY - down[1]) > 4) return;
      const i = plot.cursor.idx ?? plot.posToIdx(e.offsetX);
      if (i !== null && i !== undefined && i >= 0) onPick(i, x[i]);
    });
  }
  const observer = new ResizeObserver(() => {
    const w = Math.max(280, container.clientWidth);
    if (Math.abs(w - plot.width) > 2) plot.setSize({ width: w, height: plot.height });
  });
  observer.observe(container);
  charts.set(container, { plot, observer });
  container.dataset.series = String(spec.series.length);
  container.dataset.points = String(x.length);
  // A picture to assistive technology, named by what it shows (uPlot's canvas and live legend
  // are for the pointer).
  container.setAttribute('role', 'img');
  container.setAttribute('aria-label', describeChart(container, spec));
  return plot;
}

/**
 * Linear interpolation of (xs, ys) at x (xs ascending); null outside.
 * @param {number[]} xs
 * @param {number[]} ys
 * @param {number} x
 * @returns {number | null}
 */
function interp(xs, ys, x) {
  if (xs.length === 0 || x < xs[0] || x > xs[xs.length - 1]) return null;
  let lo = 0;
  let hi = xs.length - 1;
  while (hi - lo > 1) {
    const mid = (lo + hi) >> 1;
    if (xs[mid] <= x) lo = mid;
    else hi = mid;
  }
  if (xs[hi] === xs[lo]) return ys[lo];
  const t = (x - xs[lo]) / (xs[hi] - xs[lo]);
  return ys[lo] + t * (ys[hi] - ys[lo]);
}

/**
 * Puts several (x, y) series on one x axis (uPlot's data layout): the x values
 * of the first series, the others interpolated onto them when they differ.
 * @param {Series[]} list
 * @returns {{ x: number[], values: (number | null)[][] }}
 */
export function alignSeries(list) {
  const base = list[0].x;
  return {
    x: base,
    values: list.map((s, i) => {
      if (i === 0) return s.y;
      const same = s.x.length === base.length && s.x.every((v, j) => v === base[j]);
      return same ? s.y : base.map((x) => interp(s.x, s.y, x));
    }),
  };
}

/**
 * Union of the x values of several series; each series null where it has no point.
 * @param {Series[]} list
 * @returns {{ x: number[], values: (number | null | undefined)[][] }}
 */
export function unionSeries(list) {
  const xs = [...new Set(list.flatMap((s) => s.x))].sort((a, b) => a - b);
  return {
    x: xs,
    values: list.map((s) => {
      const m = new Map(s.x.map((x, i) => [x, s.y[i]]));
      return xs.map((x) => (m.has(x) ? m.get(x) : null));
    }),
  };
}
