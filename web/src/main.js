// The cadkg workbench: a SPARQL editor with tabs, completion and permalinks, the named queries,
// the results (table, chart, downloads), the graph view and the 3D view of the cell. Everything
// it loads comes from this endpoint; the 3D view's code is loaded when it is first opened.

import "./style.css";
import { EndpointError, getJson, postQuery } from "./api.js";
import { setTerms, sparqlCompletion } from "./completion.js";
import { createEditor, setText } from "./editor.js";
import { setUnits } from "./facts.js";
import { GraphView } from "./graphview.js";
import { installLayout } from "./layout.js";
import { NamedQueries } from "./named.js";
import { prologue, setPrefixes } from "./prefixes.js";
import { ResultView, readAnswer } from "./results.js";
import { Tabs, permalink } from "./tabs.js";

const $ = (id) => document.getElementById(id);
const STARTER = "SELECT DISTINCT ?label ?component WHERE {\n  ?component a ck:Component ; ck:label ?label .\n}\nORDER BY ?label\nLIMIT 100\n";
const state = { running: false, cell: null, cellLoading: null, labels: new Map(), graphLabels: new Map(), pending: null };

// -- the 3D view, loaded on first use -----------------------------------------------------------

async function cellView() {
  if (!state.cellLoading) {
    state.cellLoading = import("./cell/view.js").then(({ CellView }) => {
      // ?drawing=instanced or ?drawing=meshes: the other ways of drawing (benchmarks/bench_page.py).
      const drawing = new URLSearchParams(location.search).get("drawing") || "merged";
      state.cell = new CellView($("cell-view"), { onIri: (iri) => graph.show({ node: iri }), drawing });
      return state.cell.load();
    });
  }
  await state.cellLoading;
  return state.cell;
}

function showPane(which) {
  $("view-graph").classList.toggle("active", which === "graph");
  $("view-3d").classList.toggle("active", which === "3d");
  $("graph-pane").hidden = which !== "graph";
  $("cell-pane").hidden = which !== "3d";
  if (which === "3d") {
    cellView().then((view) => {
      view.resize();
      if (state.pending) {
        view.locate(state.pending);
        state.pending = null;
      }
    }).catch((err) => { $("cell-status").textContent = err.message; });
  }
}

// -- components a result names ----------------------------------------------------------------

function locate(term) {
  if (!term) return null;
  if (term.type === "literal") return state.labels.get(term.value) || null;
  if (term.type === "uri") return state.labels.get(term.value) || null;
  return null;
}

function onLocate(named) {
  if ($("cell-pane").hidden) {
    state.pending = named;
    showPane("3d");
  } else {
    cellView().then((view) => view.locate(named));
  }
}

// -- running queries ------------------------------------------------------------------------------

const graph = new GraphView({ onStatus: () => {} });
const results = new ResultView({ onIri: (iri) => { showPane("graph"); graph.show({ node: iri }); }, locate, onLocate });
let editor = null;
let tabs = null;
const named = new NamedQueries({
  getText: () => editor.state.doc.toString(),
  setText: (text) => setText(editor, text),
  onChange: (value) => { tabs.update({ named: value, title: value ? value.name : tabs.active.title }); renderTabs(); },
});

function updatePermalink() {
  const link = permalink(tabs.active);
  $("permalink").value = link;
  return link;
}

async function run() {
  if (state.running) return;
  state.running = true;
  try {
    await named.settle();
    const text = editor.state.doc.toString();
    const link = updatePermalink();
    history.replaceState(null, "", link);
    const started = performance.now();
    $("status").textContent = "running…";
    $("error").hidden = true;
    let response;
    try {
      response = await postQuery(text);
    } catch (err) {
      results.showError(err instanceof EndpointError ? err.message : String(err));
      return;
    }
    const answer = await readAnswer(response);
    const seconds = ((performance.now() - started) / 1000).toFixed(2);
    results.show(answer, { text, seconds, truncated: response.headers.get("x-cadkg-truncated") });
  } finally {
    state.running = false;
  }
}

// -- tabs -----------------------------------------------------------------------------------------

function renderTabs() {
  const list = $("tab-list");
  list.replaceChildren();
  for (const tab of tabs.tabs) {
    const button = document.createElement("button");
    button.type = "button";
    button.className = `tab${tab === tabs.active ? " active" : ""}`;
    button.setAttribute("role", "tab");
    button.dataset.id = tab.id;
    button.textContent = tab.title;
    button.addEventListener("click", () => tabs.select(tab.id));
    if (tabs.tabs.length > 1) {
      const close = document.createElement("span");
      close.className = "close";
      close.textContent = "×";
      close.title = "Close this tab";
      close.addEventListener("click", (event) => {
        event.stopPropagation();
        tabs.close(tab.id);
        renderTabs();
      });
      button.appendChild(close);
    }
    list.appendChild(button);
  }
}

function switchTo(tab) {
  if (editor && editor.state.doc.toString() !== tab.text) setText(editor, tab.text);
  named.show(tab.named);
  results.clear();
  $("status").textContent = "No query run yet.";
  renderTabs();
  updatePermalink();
}

// -- start ----------------------------------------------------------------------------------------

async function loadInfo() {
  try {
    const info = await getJson("/api/info");
    $("info").textContent = `${info.triples.toLocaleString()} triples · ${info.named_graphs.length} named graphs · `
      + `generation ${info.generation} · ${info.update ? "read-write" : "read-only"} · `
      + `limits ${info.limits.timeout_s} s, ${info.limits.max_rows.toLocaleString()} rows`;
  } catch (err) {
    $("info").textContent = `cannot reach the endpoint: ${err.message}`;
  }
}

async function loadCell() {
  // The cell's name and profile: the header names them, and the page offers the profile's own
  // queries and controls.
  try {
    const cell = await getJson("/api/cell");
    $("cell-name").textContent = cell.name || "(unnamed cell)";
    $("cell-profile").textContent = cell.profile || "no profile";
    $("cell-profile").title = cell.title || "";
    $("cell-title").title = cell.description || "";
    $("cell-title").hidden = false;
    document.title = `${cell.name || "cadkg"} · cadkg workbench`;
    document.body.dataset.profile = cell.profile;
    $("cell-show").textContent = cell.profile === "iema" ? "Show pins" : "Show";
    return cell;
  } catch (err) {
    return { profile: "", queries: {} };
  }
}

async function loadTerms() {
  try {
    const terms = await getJson("/api/terms");
    setPrefixes(terms.prefixes);
    setTerms(terms);
    setUnits(terms.properties);
    const list = $("component-labels");
    list.replaceChildren(...terms.components.map((label) => new Option(label)));
    named.labels = terms.components;
    const example = terms.components.length ? `e.g. ${terms.components[0]}` : "no components";
    $("component").placeholder = example;
    document.body.dataset.terms = "ready";
  } catch (err) {
    document.body.dataset.terms = "failed";
  }
}

async function loadGraphLabels() {
  // What the graph view can show by name: everything with a label (a component with pins as
  // its pins and wires, anything else as its neighbours), so its list offers nothing it cannot.
  // Sorted here, not by the store: Virtuoso sorts at most 10,000 rows under a LIMIT.
  try {
    const answer = await readAnswer(await postQuery(
      "SELECT ?l (SAMPLE(?s) AS ?node) (MAX(?p) AS ?pins) WHERE { ?s ck:label ?l FILTER(isIRI(?s)) "
      + "BIND(EXISTS { ?s a ck:Component . ?pin ck:pinOf ?s } AS ?p) } GROUP BY ?l LIMIT 20000",
    ));
    const collator = new Intl.Collator(undefined, { numeric: true });
    const rows = answer.rows.filter(([label, node]) => label && node);
    rows.sort(([a], [b]) => collator.compare(a.value, b.value));
    for (const [label, node, pins] of rows) {
      state.graphLabels.set(label.value, { node: node.value, pins: pins && pins.value === "true" });
    }
    $("graph-labels").replaceChildren(...[...state.graphLabels.keys()].map((label) => new Option(label)));
  } catch (err) {
    /* the field still takes component labels */
  }
}

/** The graph view of a label typed or picked: a component's pins and wires, else the node's
 * neighbours; a label the graph does not have says so and clears the old drawing. */
async function showLabel(label) {
  const known = state.graphLabels.get(label);
  if (!known) {
    graph.nothing(`Nothing in the graph is labelled “${label}”; the list offers every label there is.`);
    return;
  }
  await graph.show(known.pins ? { component: label } : { node: known.node });
}

async function loadLocatable() {
  // Which result values name a component (its IRI, its label, an item of it): read once.
  try {
    const response = await postQuery(
      "SELECT DISTINCT ?c ?label ?item WHERE { ?c a ck:Component ; ck:label ?label . OPTIONAL { ?c ck:hasItem ?item } }",
    );
    const answer = await readAnswer(response);
    for (const [c, label, item] of answer.rows) {
      const entry = { label: label.value, iri: c.value };
      state.labels.set(label.value, entry);
      state.labels.set(c.value, entry);
      if (item) state.labels.set(item.value, entry);
    }
  } catch (err) {
    /* rows are then not linked to the 3D view */
  }
}

function start() {
  installLayout();
  const starter = `${prologue(["ck", "rdfs"])}\n\n${STARTER}`;
  tabs = new Tabs({ starter, onSwitch: switchTo });
  editor = createEditor($("query"), {
    doc: tabs.active.text,
    completion: sparqlCompletion,
    onRun: run,
    onChange: (text) => {
      tabs.update({ text });
      named.describe();
    },
  });
  $("query").editorView = editor; // for the browser tests
  $("run").addEventListener("click", run);
  $("examples").addEventListener("change", async () => {
    const name = $("examples").value;
    if (!name) {
      tabs.update({ named: null });
      named.show(null);
      return;
    }
    if (tabs.active.pristine !== undefined && tabs.active.text !== tabs.active.pristine) {
      // A query of one's own is kept: the example opens in a tab of its own.
      tabs.add("", null, true);
    }
    try {
      await named.pick(name);
      tabs.update({ pristine: editor.state.doc.toString() });
    } catch (err) {
      results.showError(err.message);
    }
  });
  $("tab-add").addEventListener("click", () => {
    tabs.add(`${prologue(["ck", "rdfs"])}\n\nSELECT * WHERE {\n  \n}\nLIMIT 100\n`);
    renderTabs();
  });
  $("copy-permalink").addEventListener("click", async () => {
    const link = updatePermalink();
    $("permalink").select();
    try {
      await navigator.clipboard.writeText(link);
      $("copied").hidden = false;
      setTimeout(() => { $("copied").hidden = true; }, 1500);
    } catch (err) {
      /* the link is selected in its field for Ctrl+C */
    }
  });
  $("show-graph").addEventListener("click", () => {
    const label = $("component").value.trim();
    if (label) showLabel(label);
  });
  $("component").addEventListener("keydown", (e) => { if (e.key === "Enter") $("show-graph").click(); });
  $("graph-back").addEventListener("click", () => graph.back());
  $("view-graph").addEventListener("click", () => showPane("graph"));
  $("view-3d").addEventListener("click", () => showPane("3d"));
  window.addEventListener("hashchange", openLink);

  const queries = loadCell().then((cell) => named.load(cell.profile, cell.queries)).catch(() => {});
  Promise.all([loadInfo(), loadTerms(), queries, loadLocatable(), loadGraphLabels()]).then(() => {
    named.show(tabs.active.named);
    renderTabs();
    updatePermalink();
    openLink();
    document.body.dataset.ready = "true";
  });
  renderTabs();
  updatePermalink();
}

function openLink() {
  if (location.hash.includes("query=") && tabs.openLink(location.hash)) run();
}

start();
