// A chart of a numeric column in SVG: bars over a label column, or points (joined in x order)
// over a numeric one. Plain SVG: the results are the engineer's own, a few hundred marks at most.

import { isTypedNumber, termText } from "./terms.js";

const SVG = "http://www.w3.org/2000/svg";
const MAX_BARS = 150;
const MAX_POINTS = 5000;

export function el(tag, attributes, parent, text) {
  const node = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  if (text !== undefined) node.textContent = text;
  if (parent) parent.appendChild(node);
  return node;
}

/** The indices of the columns that hold numbers: every bound value a typed number (xsd:integer,
 * xsd:decimal ...), decided for the whole column, never cell by cell, so identifiers that look
 * like numbers (wire numbers, harness ids as strings) stay text. */
export function numericColumns(answer) {
  return answer.vars
    .map((_, i) => i)
    .filter((i) => answer.rows.some((r) => r[i]) && answer.rows.every((r) => !r[i] || isTypedNumber(r[i])));
}

// Numbers that name, order or class rather than measure (an id, a list position, a grid row,
// a nominal cross-section that wires are grouped by): not a default y.
const ORDINAL = /(^|[^a-z])(id|index|idx|position|pos|line|page|no|number|seq|sequence|step|stop|order|rank|row|column|cavity|section)$|(Id|Index|Position|Line|Page|Number|Sequence|Step|Order)$/;
const MEASURE = /count|total|sum|length|mm2|area|size|weight|diameter|radius|dim|distance|^n$|wires|cables|pins/i;

/** The numeric columns that measure something, those named like a measure first. */
export function measureColumns(answer) {
  const measures = numericColumns(answer).filter((i) => !ORDINAL.test(answer.vars[i]));
  return [...measures.filter((i) => MEASURE.test(answer.vars[i])), ...measures.filter((i) => !MEASURE.test(answer.vars[i]))];
}

/** Rows counted per value of column `xi`: [{x, y}] in order of first appearance. */
function counted(rows, xi) {
  const groups = new Map();
  for (const row of rows) {
    const term = row[xi];
    if (!term) continue;
    const key = termText(term);
    if (!groups.has(key)) groups.set(key, { row, x: term, count: 0 });
    groups.get(key).count += 1;
  }
  return [...groups.values()].map((g) => ({ row: g.row, x: g.x, y: { value: String(g.count) } }));
}

export function ticks(min, max, count = 5) {
  if (min === max) return [min];
  const raw = (max - min) / count;
  const step = 10 ** Math.floor(Math.log10(raw));
  const nice = [1, 2, 5, 10].map((m) => m * step).find((s) => s >= raw) || raw;
  const out = [];
  for (let v = Math.ceil(min / nice) * nice; v <= max + nice * 1e-9; v += nice) out.push(Number(v.toPrecision(12)));
  return out;
}

export function short(text, length = 14) {
  return text.length > length ? `${text.slice(0, length - 1)}…` : text;
}

/** The plot's area: its y axis (from 0 or the least value to the greatest), ticked and gridded. */
export function plotArea(svg, width, height, pad, values) {
  const yMin = Math.min(0, ...values);
  const yMax = Math.max(0, ...values);
  const plotW = width - pad.left - pad.right;
  const plotH = height - pad.top - pad.bottom;
  const yScale = (v) => pad.top + plotH - ((v - yMin) / (yMax - yMin || 1)) * plotH;
  const axes = el("g", { class: "axes" }, svg);
  for (const t of ticks(yMin, yMax)) {
    el("line", { x1: pad.left, x2: width - pad.right, y1: yScale(t), y2: yScale(t), class: "grid" }, axes);
    el("text", { x: pad.left - 6, y: yScale(t) + 4, "text-anchor": "end" }, axes, t.toLocaleString());
  }
  return { axes, yScale, plotW, plotH };
}

export const COUNT = -1; // y: how many rows have each x

/** Draw column `yi` (COUNT: the rows per x) against column `xi` (-1: row number); returns a
 * note for the user. */
export function drawChart(svg, rows, vars, xi, yi) {
  svg.replaceChildren();
  const width = Math.max(svg.clientWidth || 640, 320);
  const height = 320;
  svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
  const pad = { left: 64, right: 16, top: 14, bottom: 72 };
  const count = yi === COUNT;
  const numericX = !count && xi >= 0 && rows.some((r) => r[xi]) && rows.every((r) => !r[xi] || isTypedNumber(r[xi]));
  const yName = count ? "rows" : vars[yi];
  if (count && xi < 0) return "a count needs an x column: pick one";
  const points = count ? counted(rows, xi) : rows
    .map((row, index) => ({ row, x: xi < 0 ? index + 1 : row[xi], y: row[yi] }))
    .filter((p) => p.y && (xi < 0 || p.x));
  if (!points.length) return "nothing to draw: no row has both values";
  const bars = !numericX && xi >= 0;
  const shown = points.slice(0, bars ? MAX_BARS : MAX_POINTS);
  const ys = shown.map((p) => Number(p.y.value));
  const { axes, yScale, plotW, plotH } = plotArea(svg, width, height, pad, ys);
  el("text", { x: 12, y: pad.top + plotH / 2, transform: `rotate(-90 12 ${pad.top + plotH / 2})`,
    "text-anchor": "middle", class: "axis-title" }, axes, yName);
  const marks = el("g", { class: "marks" }, svg);
  if (bars) {
    const step = plotW / shown.length;
    shown.forEach((p, i) => {
      const v = Number(p.y.value);
      const x = pad.left + i * step;
      const bar = el("rect", { x: x + step * 0.1, width: Math.max(step * 0.8, 1), y: Math.min(yScale(v), yScale(0)),
        height: Math.abs(yScale(v) - yScale(0)), class: "bar" }, marks);
      el("title", {}, bar, `${termText(p.x)}: ${p.y.value}`);
      if (shown.length <= 60 || i % Math.ceil(shown.length / 60) === 0) {
        const lx = x + step / 2;
        el("text", { x: lx, y: height - pad.bottom + 12, transform: `rotate(45 ${lx} ${height - pad.bottom + 12})`,
          class: "tick" }, axes, short(termText(p.x)));
      }
    });
  } else {
    const xs = shown.map((p) => (xi < 0 ? p.x : Number(p.x.value)));
    const xMin = Math.min(...xs);
    const xMax = Math.max(...xs);
    const xScale = (v) => pad.left + ((v - xMin) / (xMax - xMin || 1)) * plotW;
    for (const t of ticks(xMin, xMax)) {
      el("text", { x: xScale(t), y: height - pad.bottom + 16, "text-anchor": "middle" }, axes, t.toLocaleString());
    }
    const order = xs.map((x, i) => [x, ys[i]]).sort((a, b) => a[0] - b[0]);
    el("polyline", { points: order.map(([x, y]) => `${xScale(x)},${yScale(y)}`).join(" "), class: "line" }, marks);
    if (order.length <= 400) {
      for (const [x, y] of order) el("circle", { cx: xScale(x), cy: yScale(y), r: 3, class: "point" }, marks);
    }
  }
  el("text", { x: pad.left + plotW / 2, y: height - 6, "text-anchor": "middle", class: "axis-title" }, axes,
    xi < 0 ? "row" : vars[xi]);
  const cut = points.length > shown.length ? `, the first ${shown.length.toLocaleString()} of ${points.length.toLocaleString()}` : "";
  const xName = xi < 0 ? "row" : vars[xi];
  // The legend: what a mark is.
  const legend = el("g", { class: "legend" }, svg);
  el("rect", { x: width - pad.right - 150, y: 2, width: 10, height: 10, class: bars ? "swatch" : "swatch point-swatch" }, legend);
  el("text", { x: width - pad.right - 135, y: 11, class: "legend-text" }, legend,
    short(count ? `rows per ${xName}` : `${yName} by ${xName}`, 24));
  if (count) return `rows per ${xName}: ${shown.length.toLocaleString()} value(s)${cut}`;
  return `${yName} of ${shown.length.toLocaleString()} row(s)${cut}`;
}
