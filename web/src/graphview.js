// The graph view in SVG: a component with its pins on a ring and the components its wires
// reach, or any node with its neighbours. Click a node to walk on, Back to return; wheel to
// zoom, drag to pan. Labels keep their size on screen and are placed where they overlap
// nothing; one that fits nowhere is left out (its node's tooltip still names it) until a
// closer zoom gives it room.

import { getJson } from "./api.js";
import { shorten } from "./prefixes.js";

const SVG = "http://www.w3.org/2000/svg";
const $ = (id) => document.getElementById(id);
const HOME = { x: -430, y: -400, w: 860, h: 800 };
const NODE_FONT = 15;
const EDGE_FONT = 12;

function svg(tag, attributes, parent) {
  const element = document.createElementNS(SVG, tag);
  for (const [key, value] of Object.entries(attributes)) element.setAttribute(key, value);
  if (parent) parent.appendChild(element);
  return element;
}

function ring(items, radius, startAngle = -Math.PI / 2) {
  const positions = new Map();
  items.forEach((item, index) => {
    const angle = startAngle + (2 * Math.PI * index) / Math.max(items.length, 1);
    positions.set(item.id, { x: radius * Math.cos(angle), y: radius * Math.sin(angle), angle });
  });
  return positions;
}

// Centre in the middle; a component's pins on an inner ring; everything else on an outer
// ring, each near the mean angle of the inner nodes it is joined to.
function layout(data) {
  const positions = new Map([[data.center, { x: 0, y: 0, angle: 0 }]]);
  const inner = data.nodes.filter((n) => n.kind === "pin");
  const outer = data.nodes.filter((n) => n.id !== data.center && n.kind !== "pin");
  inner.sort((a, b) => a.label.localeCompare(b.label, undefined, { numeric: true }));
  const innerRadius = Math.max(170, inner.length * 9);
  for (const [id, p] of ring(inner, innerRadius)) positions.set(id, p);
  const outerRadius = Math.max(innerRadius + 160, outer.length * 11, 300);
  const wanted = outer.map((node) => {
    const angles = data.edges
      .filter((e) => (e.target === node.id && positions.has(e.source)) || (e.source === node.id && positions.has(e.target)))
      .map((e) => positions.get(e.target === node.id ? e.source : e.target))
      .filter((p) => p && (p.x || p.y))
      .map((p) => p.angle);
    const mean = angles.length
      ? Math.atan2(angles.reduce((s, a) => s + Math.sin(a), 0), angles.reduce((s, a) => s + Math.cos(a), 0))
      : null;
    return { node, mean };
  });
  const free = wanted.filter((w) => w.mean === null).map((w) => w.node);
  const placed = wanted.filter((w) => w.mean !== null).sort((a, b) => a.mean - b.mean);
  const step = (2 * Math.PI) / Math.max(outer.length, 1);
  let last = -Infinity;
  for (const w of placed) {
    const angle = Math.max(w.mean, last + step * 0.9);
    last = angle;
    positions.set(w.node.id, { x: outerRadius * Math.cos(angle), y: outerRadius * Math.sin(angle), angle });
  }
  for (const [id, p] of ring(free, inner.length ? outerRadius : 300, -Math.PI / 2 + step / 2)) positions.set(id, p);
  return positions;
}

function overlaps(a, list) {
  return list.some((b) => a.x < b.x + b.w && b.x < a.x + a.w && a.y < b.y + b.h && b.y < a.y + a.h);
}

export class GraphView {
  constructor({ onStatus }) {
    this.canvas = $("graph");
    this.onStatus = onStatus;
    this.history = [];
    this.key = null;
    this.box = { ...HOME };
    this.labels = [];
    this.installZoom();
  }

  // -- zoom and pan ------------------------------------------------------------------------

  installZoom() {
    const canvas = this.canvas;
    canvas.addEventListener("wheel", (event) => {
      event.preventDefault();
      const point = this.toGraph(event.clientX, event.clientY);
      this.zoom(event.deltaY < 0 ? 1 / 1.2 : 1.2, point);
    }, { passive: false });
    let drag = null;
    canvas.addEventListener("pointerdown", (event) => {
      if (event.button !== 0 || event.target.closest("g.node")) return;
      drag = { x: event.clientX, y: event.clientY, box: { ...this.box } };
      canvas.setPointerCapture(event.pointerId);
    });
    canvas.addEventListener("pointermove", (event) => {
      if (!drag) return;
      const scale = this.box.w / canvas.clientWidth;
      this.setBox({ ...drag.box, x: drag.box.x - (event.clientX - drag.x) * scale, y: drag.box.y - (event.clientY - drag.y) * scale });
    });
    canvas.addEventListener("pointerup", () => { drag = null; });
    $("graph-zoom-in").addEventListener("click", () => this.zoom(1 / 1.4));
    $("graph-zoom-out").addEventListener("click", () => this.zoom(1.4));
    $("graph-fit").addEventListener("click", () => this.fit());
  }

  toGraph(clientX, clientY) {
    const rect = this.canvas.getBoundingClientRect();
    // viewBox keeps its aspect inside the element (xMidYMid meet): one scale for both axes.
    const scale = Math.max(this.box.w / rect.width, this.box.h / rect.height);
    const cx = this.box.x + this.box.w / 2;
    const cy = this.box.y + this.box.h / 2;
    return { x: cx + (clientX - rect.left - rect.width / 2) * scale, y: cy + (clientY - rect.top - rect.height / 2) * scale };
  }

  zoom(factor, around = null) {
    const c = around || { x: this.box.x + this.box.w / 2, y: this.box.y + this.box.h / 2 };
    const w = Math.min(Math.max(this.box.w * factor, 60), 20000);
    const f = w / this.box.w;
    this.setBox({ x: c.x - (c.x - this.box.x) * f, y: c.y - (c.y - this.box.y) * f, w, h: this.box.h * f });
    clearTimeout(this.relabel);
    this.relabel = setTimeout(() => this.placeLabels(), 80);
  }

  setBox(box) {
    this.box = box;
    this.canvas.setAttribute("viewBox", `${box.x} ${box.y} ${box.w} ${box.h}`);
  }

  /** Show the whole graph: nodes and edges first, then with the labels placed around them. */
  fit() {
    const content = this.canvas.querySelector("g.content");
    if (!content) return;
    const frame = (b, margin) => {
      const aspect = HOME.w / HOME.h;
      let w = b.width + 2 * margin;
      let h = b.height + 2 * margin;
      if (w / h > aspect) h = w / aspect; else w = h * aspect;
      this.setBox({ x: b.x + b.width / 2 - w / 2, y: b.y + b.height / 2 - h / 2, w, h });
    };
    const shapes = [content.querySelector("g.nodes"), content.querySelector("g.edges")].map((g) => g.getBBox());
    const x = Math.min(...shapes.map((b) => b.x));
    const y = Math.min(...shapes.map((b) => b.y));
    frame({ x, y, width: Math.max(...shapes.map((b) => b.x + b.width)) - x,
      height: Math.max(...shapes.map((b) => b.y + b.height)) - y }, 40);
    this.placeLabels();
    frame(content.getBBox(), 12); // labels left out (display: none) do not count
    this.placeLabels();
  }

  // -- labels ------------------------------------------------------------------------------

  /** Place every label where it overlaps no node and no label placed before it. */
  placeLabels() {
    const rect = this.canvas.getBoundingClientRect();
    const scale = rect.width ? Math.max(this.box.w / rect.width, this.box.h / rect.height) : 1;
    const taken = this.nodeBoxes.map((n) => ({ x: n.x - n.r, y: n.y - n.r, w: 2 * n.r, h: 2 * n.r }));
    for (const label of this.labels) {
      const size = (label.edge ? EDGE_FONT : NODE_FONT) * scale;
      label.element.setAttribute("font-size", size);
      label.element.classList.remove("crowded");
      const w = label.element.getComputedTextLength() + size * 0.3; // the halo drawn around it
      const h = size * 1.15;
      let spot = null;
      for (const [x, y] of label.candidates(w, h, size)) {
        const box = { x: x - w / 2, y: y - h * 0.8, w, h };
        if (!overlaps(box, taken)) {
          spot = { x, y, box };
          break;
        }
      }
      if (spot) {
        taken.push(spot.box);
        label.element.setAttribute("x", spot.x);
        label.element.setAttribute("y", spot.y);
        label.element.classList.remove("crowded");
      } else {
        label.element.classList.add("crowded");
      }
    }
  }

  // -- drawing -----------------------------------------------------------------------------

  draw(data) {
    const canvas = this.canvas;
    canvas.replaceChildren();
    const root = svg("g", { class: "content" }, canvas);
    const positions = layout(data);
    const edges = svg("g", { class: "edges" }, root);
    const labelLayer = svg("g", { class: "labels" }, root);
    this.labels = [];
    this.nodeBoxes = [];
    const nodeLabels = [];
    for (const edge of data.edges) {
      const a = positions.get(edge.source);
      const b = positions.get(edge.target);
      if (!a || !b) continue;
      const line = svg("line", { x1: a.x, y1: a.y, x2: b.x, y2: b.y, class: `edge ${edge.kind}` }, edges);
      svg("title", {}, line).textContent = edge.label;
      if (edge.kind === "pin") continue; // the ring says it
      const text = svg("text", { class: "edge-label", "text-anchor": "middle" }, labelLayer);
      text.textContent = edge.label;
      const dx = b.x - a.x;
      const dy = b.y - a.y;
      const length = Math.hypot(dx, dy) || 1;
      this.labels.push({
        edge: true, element: text, text: edge.label,
        candidates: (w, h, size) => [0.5, 0.4, 0.6, 0.3, 0.7, 0.2, 0.8].flatMap((t) => [0, 1, -1].map((side) => [
          a.x + dx * t - (dy / length) * side * size, a.y + dy * t + (dx / length) * side * size + size * 0.35])),
      });
    }
    const nodes = svg("g", { class: "nodes" }, root);
    for (const node of data.nodes) {
      const p = positions.get(node.id);
      if (!p) continue;
      const group = svg("g", { class: `node kind-${node.kind}`, transform: `translate(${p.x},${p.y})`, "data-id": node.id }, nodes);
      const r = node.id === data.center ? 22 : node.kind === "pin" ? 9 : 14;
      svg("circle", { r }, group);
      svg("title", {}, group).textContent = `${node.label}\n${node.id}`;
      this.nodeBoxes.push({ x: p.x, y: p.y, r });
      const text = svg("text", { "text-anchor": "middle", class: "node-label" }, labelLayer);
      text.textContent = node.label;
      text.dataset.id = node.id;
      // Away from the centre first (outside the rings), then around the node.
      const out = Math.hypot(p.x, p.y) ? [p.x / Math.hypot(p.x, p.y), p.y / Math.hypot(p.x, p.y)] : [0, -1];
      nodeLabels.push({
        edge: false, element: text, text: node.label, rank: node.id === data.center ? 0 : node.kind === "pin" ? 2 : 1,
        candidates: (w, h, size) => {
          const gap = r + size * 0.4;
          const spots = [];
          for (const k of [1, 1.8, 2.6]) {
            spots.push([p.x + out[0] * (gap * k + w / 2), p.y + out[1] * (gap * k + h / 2) + size * 0.35]);
            spots.push([p.x, p.y - gap * k], [p.x, p.y + gap * k + size * 0.8],
              [p.x + gap * k + w / 2, p.y + size * 0.35], [p.x - gap * k - w / 2, p.y + size * 0.35]);
          }
          return spots;
        },
      });
      group.addEventListener("click", () => {
        if (node.id === data.center) return;
        this.show(node.kind === "component" ? { component: node.label } : { node: node.id });
      });
    }
    nodeLabels.sort((a, b) => a.rank - b.rank);
    this.labels = [...nodeLabels, ...this.labels];
    const properties = document.createDocumentFragment();
    for (const property of data.properties || []) {
      const tr = document.createElement("tr");
      const name = document.createElement("td");
      name.textContent = shorten(property.iri);
      const value = document.createElement("td");
      value.textContent = property.value;
      tr.append(name, value);
      properties.appendChild(tr);
    }
    $("properties").tBodies[0].replaceChildren(properties);
    this.fit();
  }

  /** Draw the graph of `target` ({component} or {node}); true when it could. On a failure
   * the old drawing goes (it would seem to answer) and the status says why. */
  async show(target, remember = true) {
    const search = new URLSearchParams(target);
    $("graph-status").textContent = "loading…";
    try {
      const data = await getJson(`/api/graph?${search}`);
      if (remember && this.key) this.history.push(this.key);
      this.key = target;
      $("graph-back").disabled = this.history.length === 0;
      this.draw(data);
      const what = target.component ? `component ${target.component}` : shorten(target.node);
      $("graph-status").textContent = `${what}: ${data.nodes.length} nodes, ${data.edges.length} edges`;
      $("graph-status").classList.remove("failed");
      if (target.component) $("component").value = target.component;
      this.onStatus(target);
      return true;
    } catch (err) {
      const what = target.component ? `component ${target.component}` : shorten(target.node);
      // The endpoint's message without its status line ("404 Not Found").
      const reason = err.message.split("\n").slice(1).join(" ").trim() || err.message;
      this.nothing(`Cannot show ${what}: ${reason}`);
      return false;
    }
  }

  /** No graph: the old drawing cleared, `message` in its place. */
  nothing(message) {
    this.canvas.replaceChildren();
    $("properties").tBodies[0].replaceChildren();
    this.key = null;
    $("graph-status").textContent = message;
    $("graph-status").classList.add("failed");
  }

  back() {
    const previous = this.history.pop();
    if (previous) this.show(previous, false);
    $("graph-back").disabled = this.history.length === 0;
  }
}
