// A chart of several series: grouped bars over a text column (a bar per series at each value),
// or a line per series over a numeric one, with a legend naming each series. The series are
// the answer's measures side by side, or one measure (or the count of rows) split by the values
// of a grouping column (wires per colour, by cross-section).

import { COUNT, el, plotArea, short, ticks } from "./chart.js";
import { isTypedNumber, termText } from "./terms.js";

const PALETTE = ["#2457c5", "#f2a541", "#15803d", "#b42318", "#7c3aed", "#0e7490", "#a16207", "#db2777", "#475467", "#65a30d"];
export const MAX_SERIES = PALETTE.length;
const MAX_GROUPS = 60;

/** The series of a choice: {keys (x values in order of first appearance), series: [{name,
 * values: Map(key -> number)}], numericX}. `choice` is {measures: [column]} or {group: column}. */
export function seriesOf(rows, vars, xi, yi, choice) {
  const numericX = rows.some((r) => r[xi]) && rows.every((r) => !r[xi] || isTypedNumber(r[xi]));
  const keys = [];
  const seen = new Set();
  const byName = new Map();
  const add = (name, key, value) => {
    if (!seen.has(key)) { seen.add(key); keys.push(key); }
    if (!byName.has(name)) byName.set(name, new Map());
    const values = byName.get(name);
    values.set(key, (values.get(key) || 0) + value);
  };
  for (const row of rows) {
    if (!row[xi]) continue;
    const key = termText(row[xi]);
    if (choice.measures) {
      for (const column of choice.measures) if (row[column]) add(vars[column], key, Number(row[column].value));
    } else if (yi === COUNT || row[yi]) {
      add(row[choice.group] ? termText(row[choice.group]) : "(none)", key, yi === COUNT ? 1 : Number(row[yi].value));
    }
  }
  const series = [...byName].slice(0, MAX_SERIES).map(([name, values]) => ({ name, values }));
  return { keys: numericX ? keys : keys.slice(0, MAX_GROUPS), series, numericX, cut: keys.length > MAX_GROUPS && !numericX };
}

/** Draw the series of a choice; returns a note for the user. */
export function drawSeries(svg, rows, vars, xi, yi, choice) {
  svg.replaceChildren();
  const width = Math.max(svg.clientWidth || 640, 320);
  const height = 320;
  svg.setAttribute("viewBox", `0 0 ${width} ${height}`);
  const pad = { left: 64, right: 16, top: 30, bottom: 72 };
  const { keys, series, numericX, cut } = seriesOf(rows, vars, xi, yi, choice);
  if (!keys.length || !series.length) return "nothing to draw: no row has both values";
  const all = series.flatMap((s) => [...s.values.values()]);
  const { axes, yScale, plotW, plotH } = plotArea(svg, width, height, pad, all);
  const yName = choice.measures ? "value" : yi === COUNT ? "rows" : vars[yi];
  el("text", { x: 12, y: pad.top + plotH / 2, transform: `rotate(-90 12 ${pad.top + plotH / 2})`, "text-anchor": "middle", class: "axis-title" }, axes, yName);
  el("text", { x: pad.left + plotW / 2, y: height - 6, "text-anchor": "middle", class: "axis-title" }, axes, vars[xi]);
  const marks = el("g", { class: "marks" }, svg);
  if (numericX) {
    const xs = keys.map(Number);
    const xMin = Math.min(...xs);
    const xMax = Math.max(...xs);
    const xScale = (v) => pad.left + ((v - xMin) / (xMax - xMin || 1)) * plotW;
    for (const t of ticks(xMin, xMax)) el("text", { x: xScale(t), y: height - pad.bottom + 16, "text-anchor": "middle" }, axes, t.toLocaleString());
    series.forEach((s, i) => {
      const points = [...s.values].map(([k, v]) => [Number(k), v]).sort((a, b) => a[0] - b[0]);
      el("polyline", { points: points.map(([x, y]) => `${xScale(x)},${yScale(y)}`).join(" "), class: "series-line", stroke: PALETTE[i] }, marks);
    });
  } else {
    const step = plotW / keys.length;
    const bar = (step * 0.8) / series.length;
    keys.forEach((key, k) => {
      const x = pad.left + k * step + step * 0.1;
      series.forEach((s, i) => {
        if (!s.values.has(key)) return;
        const v = s.values.get(key);
        const rect = el("rect", { x: x + i * bar, width: Math.max(bar, 1), y: Math.min(yScale(v), yScale(0)),
          height: Math.abs(yScale(v) - yScale(0)), class: "series-bar", fill: PALETTE[i] }, marks);
        el("title", {}, rect, `${key}, ${s.name}: ${v.toLocaleString()}`);
      });
      if (keys.length <= 60) {
        const lx = pad.left + k * step + step / 2;
        el("text", { x: lx, y: height - pad.bottom + 12, transform: `rotate(45 ${lx} ${height - pad.bottom + 12})`, class: "tick" }, axes, short(key));
      }
    });
  }
  // The legend: a swatch and a name per series, in a row over the plot.
  const legend = el("g", { class: "legend" }, svg);
  let lx = pad.left;
  series.forEach((s, i) => {
    el("rect", { x: lx, y: 8, width: 10, height: 10, fill: PALETTE[i], class: "series-swatch" }, legend);
    const name = short(s.name, 18);
    el("text", { x: lx + 14, y: 17, class: "legend-text" }, legend, name);
    lx += 24 + name.length * 6.5;
  });
  const what = choice.measures ? `${series.length} measures` : `${yName} by ${vars[choice.group]} (${series.length} series)`;
  return `${what} per ${vars[xi]}${cut ? `, the first ${MAX_GROUPS} values` : ""}`;
}
