// The cadkg endpoint's page: a SPARQL editor, the named queries, a sortable result table with
// downloads, and a graph view of a component or any node. Plain JavaScript, no dependencies:
// everything it loads comes from this endpoint.
"use strict";

const PREFIXES = {
  ck: "https://w3id.org/cadkg#",
  rdf: "http://www.w3.org/1999/02/22-rdf-syntax-ns#",
  rdfs: "http://www.w3.org/2000/01/rdf-schema#",
  owl: "http://www.w3.org/2002/07/owl#",
  xsd: "http://www.w3.org/2001/XMLSchema#",
};
const STARTER = "SELECT DISTINCT ?label ?component WHERE {\n  ?component a ck:Component ; ck:label ?label .\n}\nORDER BY ?label\nLIMIT 100\n";
const RESULTS_ACCEPT = "application/sparql-results+json, text/turtle;q=0.9";
const SVG = "http://www.w3.org/2000/svg";

const $ = (id) => document.getElementById(id);
const state = { named: null, queries: {}, rows: [], vars: [], sort: null, history: [], graphKey: null };

function prologue(prefixes) {
  return Object.entries(prefixes).map(([p, iri]) => `PREFIX ${p}: <${iri}>`).join("\n") + "\n\n";
}

function shorten(iri) {
  for (const [p, ns] of Object.entries(PREFIXES)) {
    if (iri.startsWith(ns)) return `${p}:${iri.slice(ns.length)}`;
  }
  return iri;
}

async function getJson(url) {
  const response = await fetch(url, { headers: { Accept: "application/json" } });
  const body = await response.text();
  if (!response.ok) {
    let message = body;
    try { message = JSON.parse(body).error || body; } catch (e) { /* a plain-text error */ }
    throw new Error(`${response.status}: ${message}`);
  }
  return JSON.parse(body);
}

// -- the editor and the named queries ------------------------------------------------------

async function loadInfo() {
  try {
    const info = await getJson("/api/info");
    Object.assign(PREFIXES, info.prefixes || {});
    $("info").textContent = `${info.triples.toLocaleString()} triples · ${info.named_graphs.length} named graphs · ` +
      `generation ${info.generation} · ${info.update ? "read-write" : "read-only"} · ` +
      `limits ${info.limits.timeout_s} s, ${info.limits.max_rows.toLocaleString()} rows`;
  } catch (err) {
    $("info").textContent = `cannot reach the endpoint: ${err.message}`;
  }
  if (!$("query").value) $("query").value = prologue(PREFIXES) + STARTER;
}

async function loadExamples() {
  const queries = await getJson("/api/queries");
  const select = $("examples");
  for (const q of queries) {
    state.queries[q.name] = q;
    const option = document.createElement("option");
    option.value = q.name;
    option.textContent = q.name;
    option.title = q.description;
    select.appendChild(option);
  }
}

function pickExample() {
  const name = $("examples").value;
  const params = $("params");
  params.replaceChildren();
  if (!name) {
    state.named = null;
    $("example-help").textContent = "";
    return;
  }
  const q = state.queries[name];
  state.named = q;
  $("query").value = q.text;
  $("example-help").textContent = q.description;
  for (const p of q.params) {
    const input = document.createElement("input");
    input.name = p.name;
    input.id = `param-${p.name}`;
    input.placeholder = p.name;
    input.title = p.description;
    const example = /e\.g\.\s*(\S+)/.exec(p.description);
    if (example) input.value = example[1];
    input.addEventListener("keydown", (e) => { if (e.key === "Enter") run(); });
    params.appendChild(input);
  }
}

function currentRequest() {
  // A named query left as it is runs by name (its parameters bound by the server);
  // anything else is SPARQL text for /sparql.
  const text = $("query").value;
  if (state.named && text === state.named.text) {
    const search = new URLSearchParams();
    for (const input of $("params").querySelectorAll("input")) search.set(input.name, input.value);
    return { url: `/api/queries/${encodeURIComponent(state.named.name)}`, search };
  }
  return { url: "/sparql", search: new URLSearchParams({ query: text }) };
}

async function run() {
  const request = currentRequest();
  const started = performance.now();
  $("status").textContent = "running…";
  $("error").hidden = true;
  $("graph-text").hidden = true;
  $("downloads").hidden = true;
  let response;
  try {
    response = request.url === "/sparql"
      ? await fetch("/sparql", {
          method: "POST",
          headers: { Accept: RESULTS_ACCEPT, "Content-Type": "application/x-www-form-urlencoded" },
          body: request.search.toString(),
        })
      : await fetch(`${request.url}?${request.search}`, { headers: { Accept: RESULTS_ACCEPT } });
  } catch (err) {
    return showError(`cannot reach the endpoint: ${err.message}`);
  }
  const seconds = ((performance.now() - started) / 1000).toFixed(2);
  const body = await response.text();
  if (!response.ok) return showError(`${response.status} ${response.statusText}\n${body}`);
  const type = response.headers.get("content-type") || "";
  const truncated = response.headers.get("x-cadkg-truncated");
  const note = truncated ? ` — cut at the row cap of ${Number(truncated).toLocaleString()}` : "";
  if (!type.includes("json")) {
    clearTable();
    $("graph-text").textContent = body;
    $("graph-text").hidden = false;
    $("status").textContent = `graph answer in ${seconds} s${note}`;
    return;
  }
  const data = JSON.parse(body);
  if ("boolean" in data) {
    clearTable();
    $("status").textContent = `ASK: ${data.boolean} (${seconds} s)`;
    return;
  }
  state.vars = data.head.vars;
  state.rows = data.results.bindings;
  state.sort = null;
  renderTable();
  $("status").textContent = `${state.rows.length.toLocaleString()} row(s) in ${seconds} s${note}`;
  setDownloads(request);
}

function setDownloads(request) {
  for (const format of ["csv", "tsv", "json", "xml"]) {
    const search = new URLSearchParams(request.search);
    search.set("format", format);
    $(`download-${format}`).href = `${request.url}?${search}`;
  }
  $("downloads").hidden = false;
}

function showError(message) {
  clearTable();
  $("status").textContent = "failed";
  $("error").textContent = message;
  $("error").hidden = false;
}

// -- the result table -----------------------------------------------------------------------

function clearTable() {
  $("results").tHead.replaceChildren();
  $("results").tBodies[0].replaceChildren();
}

function cellText(term) {
  if (!term) return "";
  if (term.type === "uri") return shorten(term.value);
  if (term.type === "bnode") return `_:${term.value}`;
  if (term.type === "triple") return `<< ${cellText(term.value.subject)} ${cellText(term.value.predicate)} ${cellText(term.value.object)} >>`;
  return term.value;
}

function isNumeric(term) {
  return term && term.type === "literal" && term.value !== "" && !Number.isNaN(Number(term.value));
}

function compareTerms(a, b, numeric) {
  if (!a && !b) return 0;
  if (!a) return 1;
  if (!b) return -1;
  if (numeric) return Number(a.value) - Number(b.value);
  return cellText(a).localeCompare(cellText(b), undefined, { numeric: true });
}

function sortBy(variable) {
  const direction = state.sort && state.sort.variable === variable && state.sort.direction === "asc" ? "desc" : "asc";
  state.sort = { variable, direction };
  const numeric = state.rows.every((row) => !row[variable] || isNumeric(row[variable]));
  const sign = direction === "asc" ? 1 : -1;
  state.rows.sort((x, y) => sign * compareTerms(x[variable], y[variable], numeric));
  renderTable();
}

function renderTable() {
  const head = document.createElement("tr");
  for (const variable of state.vars) {
    const th = document.createElement("th");
    th.textContent = variable;
    th.dataset.variable = variable;
    if (state.sort && state.sort.variable === variable) {
      th.className = `sorted-${state.sort.direction}`;
      th.setAttribute("aria-sort", state.sort.direction === "asc" ? "ascending" : "descending");
    }
    th.addEventListener("click", () => sortBy(variable));
    head.appendChild(th);
  }
  $("results").tHead.replaceChildren(head);
  const rows = document.createDocumentFragment();
  for (const binding of state.rows) {
    const tr = document.createElement("tr");
    for (const variable of state.vars) {
      const td = document.createElement("td");
      const term = binding[variable];
      td.textContent = cellText(term);
      if (term && term.type === "uri") {
        td.className = "iri";
        td.title = `${term.value} — click for its graph`;
        td.addEventListener("click", () => showGraph({ node: term.value }));
      } else if (isNumeric(term)) {
        td.className = "num";
      }
      tr.appendChild(td);
    }
    rows.appendChild(tr);
  }
  $("results").tBodies[0].replaceChildren(rows);
}

// -- the graph view -----------------------------------------------------------------------------

async function loadComponents() {
  try {
    const response = await fetch("/api/queries/components", { headers: { Accept: "application/sparql-results+json" } });
    const data = await response.json();
    const list = $("component-labels");
    const seen = new Set();
    for (const row of data.results.bindings) {
      if (seen.has(row.label.value)) continue;
      seen.add(row.label.value);
      const option = document.createElement("option");
      option.value = row.label.value;
      list.appendChild(option);
    }
  } catch (err) {
    /* the view still works with a typed label */
  }
}

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

function layout(data) {
  // Centre in the middle; a component's pins on an inner ring; everything else on an outer
  // ring, each placed near the mean angle of the inner nodes it is joined to.
  const positions = new Map([[data.center, { x: 0, y: 0, angle: 0 }]]);
  const inner = data.nodes.filter((n) => n.kind === "pin");
  const outer = data.nodes.filter((n) => n.id !== data.center && n.kind !== "pin");
  inner.sort((a, b) => a.label.localeCompare(b.label, undefined, { numeric: true }));
  for (const [id, p] of ring(inner, 170)) positions.set(id, p);
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
    positions.set(w.node.id, { x: 330 * Math.cos(angle), y: 330 * Math.sin(angle), angle });
  }
  const radius = inner.length ? 330 : 300;
  for (const [id, p] of ring(free, radius, -Math.PI / 2 + step / 2)) positions.set(id, p);
  return positions;
}

function drawGraph(data) {
  const canvas = $("graph");
  canvas.replaceChildren();
  const positions = layout(data);
  const edges = svg("g", { class: "edges" }, canvas);
  for (const edge of data.edges) {
    const a = positions.get(edge.source);
    const b = positions.get(edge.target);
    if (!a || !b) continue;
    svg("line", { x1: a.x, y1: a.y, x2: b.x, y2: b.y, class: `edge ${edge.kind}` }, edges);
    if (edge.kind === "pin") continue; // the ring says it
    const label = svg("text", { x: (a.x + b.x) / 2, y: (a.y + b.y) / 2 - 3, class: "edge-label", "text-anchor": "middle" }, edges);
    label.textContent = edge.label;
  }
  const nodes = svg("g", { class: "nodes" }, canvas);
  for (const node of data.nodes) {
    const p = positions.get(node.id);
    if (!p) continue;
    const group = svg("g", { class: `node kind-${node.kind}`, transform: `translate(${p.x},${p.y})`, "data-id": node.id }, nodes);
    const radius = node.id === data.center ? 22 : node.kind === "pin" ? 9 : 14;
    svg("circle", { r: radius }, group);
    svg("title", {}, group).textContent = node.id;
    const text = svg("text", { y: -radius - 4, "text-anchor": "middle" }, group);
    text.textContent = node.label;
    group.addEventListener("click", () => {
      if (node.id === data.center) return;
      showGraph(node.kind === "component" ? { component: node.label } : { node: node.id });
    });
  }
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
}

async function showGraph(target, remember = true) {
  const search = new URLSearchParams(target);
  $("graph-status").textContent = "loading…";
  try {
    const data = await getJson(`/api/graph?${search}`);
    if (remember && state.graphKey) state.history.push(state.graphKey);
    state.graphKey = target;
    $("graph-back").disabled = state.history.length === 0;
    drawGraph(data);
    const what = target.component ? `component ${target.component}` : shorten(target.node);
    $("graph-status").textContent = `${what}: ${data.nodes.length} nodes, ${data.edges.length} edges`;
    if (target.component) $("component").value = target.component;
  } catch (err) {
    $("graph-status").textContent = err.message;
  }
}

function back() {
  const previous = state.history.pop();
  if (previous) showGraph(previous, false);
  $("graph-back").disabled = state.history.length === 0;
}

document.addEventListener("DOMContentLoaded", () => {
  $("run").addEventListener("click", run);
  $("query").addEventListener("keydown", (e) => {
    if (e.key === "Enter" && (e.ctrlKey || e.metaKey)) {
      e.preventDefault();
      run();
    }
  });
  $("examples").addEventListener("change", pickExample);
  $("show-graph").addEventListener("click", () => {
    const label = $("component").value.trim();
    if (label) showGraph({ component: label });
  });
  $("component").addEventListener("keydown", (e) => {
    if (e.key === "Enter") $("show-graph").click();
  });
  $("graph-back").addEventListener("click", back);
  loadInfo();
  loadExamples();
  loadComponents();
});
