// The answer of a query: a table with filtering, sorting and paging (only one page is ever
// in the DOM, so 10,000 rows show as fast as 100), a chart of numeric columns, and downloads
// in every format the endpoint writes for this kind of answer.

import { postQuery, saveResponse } from "./api.js";
import { COUNT, drawChart, measureColumns, numericColumns } from "./chart.js";
import { MAX_SERIES, drawSeries } from "./series.js";
import { readNTriples, termText, termTitle } from "./terms.js";

const $ = (id) => document.getElementById(id);
const FORMATS = {
  select: [["csv", "CSV"], ["tsv", "TSV"], ["json", "SPARQL JSON"], ["xml", "SPARQL XML"]],
  ask: [["json", "SPARQL JSON"], ["xml", "SPARQL XML"], ["csv", "CSV"], ["tsv", "TSV"]],
  graph: [["ttl", "Turtle"], ["nt", "N-Triples"], ["jsonld", "JSON-LD"], ["rdfxml", "RDF/XML"]],
};
const SUFFIX = { csv: "csv", tsv: "tsv", json: "srj", xml: "srx", ttl: "ttl", nt: "nt", jsonld: "jsonld", rdfxml: "rdf" };

/** Read a /sparql response into {kind, vars, rows, boolean}. */
export async function readAnswer(response) {
  const type = response.headers.get("content-type") || "";
  const body = await response.text();
  if (type.includes("json")) {
    const data = JSON.parse(body);
    if ("boolean" in data) return { kind: "ask", vars: [], rows: [], boolean: data.boolean };
    const vars = data.head.vars;
    const rows = data.results.bindings.map((b) => vars.map((v) => b[v]));
    return { kind: "select", vars, rows };
  }
  return { kind: "graph", vars: ["subject", "predicate", "object"], rows: readNTriples(body) };
}

export class ResultView {
  constructor({ onIri, locate, onLocate }) {
    this.onIri = onIri; // an IRI cell clicked: show its graph
    this.locate = locate; // term -> the component it names, or null
    this.onLocate = onLocate; // a row naming a component clicked
    this.answer = null;
    this.view = [];
    this.page = 0;
    this.sort = null;
    this.mode = "table";
    $("filter").addEventListener("input", () => this.refilter());
    $("page-size").addEventListener("change", () => { this.page = 0; this.renderTable(); });
    $("page-first").addEventListener("click", () => this.goto(0));
    $("page-prev").addEventListener("click", () => this.goto(this.page - 1));
    $("page-next").addEventListener("click", () => this.goto(this.page + 1));
    $("page-last").addEventListener("click", () => this.goto(Infinity));
    $("show-table").addEventListener("click", () => this.showMode("table"));
    $("show-chart").addEventListener("click", () => this.showMode("chart"));
    $("chart-x").addEventListener("change", () => {
      this.fillSeries();
      this.renderChart();
    });
    $("chart-y").addEventListener("change", () => this.renderChart());
    $("chart-series").addEventListener("change", () => this.renderChart());
    $("download").addEventListener("click", () => this.download());
  }

  clear() {
    this.answer = null;
    $("results").tHead.replaceChildren();
    $("results").tBodies[0].replaceChildren();
    $("result-tools").hidden = true;
    $("downloads").hidden = true;
    $("error").hidden = true;
    $("no-results").hidden = true;
    $("chart").replaceChildren();
  }

  showError(message) {
    this.clear();
    $("status").textContent = "failed";
    $("error").textContent = message;
    $("error").hidden = false;
  }

  show(answer, { text, seconds, truncated }) {
    this.clear();
    this.answer = answer;
    this.text = text;
    this.sort = null;
    this.page = 0;
    $("filter").value = "";
    const note = truncated ? ` — cut at the row cap of ${Number(truncated).toLocaleString()}` : "";
    this.setDownloads(answer.kind);
    if (answer.kind === "ask") {
      $("status").textContent = `ASK: ${answer.boolean} (${seconds} s)`;
      return;
    }
    const what = answer.kind === "graph" ? "triple(s)" : "row(s)";
    this.summary = `${answer.rows.length.toLocaleString()} ${what} in ${seconds} s${note}`;
    if (!answer.rows.length) {
      $("status").textContent = this.summary;
      $("no-results").textContent = answer.kind === "graph"
        ? "No results: the query made no triples."
        : "No results: nothing in the graph matches the query.";
      $("no-results").hidden = false;
      return;
    }
    $("result-tools").hidden = false;
    // Numbers by column, from their datatypes: a wire number is text in every row.
    this.numeric = new Set(numericColumns(answer));
    $("show-chart").disabled = answer.kind !== "select";
    if (this.mode === "chart" && $("show-chart").disabled) this.mode = "table";
    this.refilter();
    this.fillChartChoices();
    this.showMode(this.mode);
  }

  setDownloads(kind) {
    const select = $("download-format");
    select.replaceChildren(...FORMATS[kind].map(([value, label]) => new Option(label, value)));
    $("downloads").hidden = false;
  }

  async download() {
    const format = $("download-format").value;
    try {
      const response = await postQuery(this.text, { accept: "*/*", format });
      await saveResponse(response, `query.${SUFFIX[format]}`);
    } catch (err) {
      this.showError(err.message);
    }
  }

  refilter() {
    const needle = $("filter").value.trim().toLowerCase();
    const rows = this.answer.rows;
    this.view = needle
      ? rows.filter((row) => row.some((t) => t && (termText(t).toLowerCase().includes(needle)
          || (t.type === "uri" && t.value.toLowerCase().includes(needle)))))
      : rows.slice();
    if (this.sort) this.applySort();
    this.page = 0;
    this.renderTable();
    if (this.mode === "chart") this.renderChart();
  }

  applySort() {
    const { index, direction } = this.sort;
    const numeric = this.numeric.has(index);
    const sign = direction === "asc" ? 1 : -1;
    const collator = new Intl.Collator(undefined, { numeric: true });
    this.view.sort((x, y) => {
      const a = x[index];
      const b = y[index];
      if (!a || !b) return (a ? -1 : b ? 1 : 0);
      return sign * (numeric ? Number(a.value) - Number(b.value) : collator.compare(termText(a), termText(b)));
    });
  }

  sortBy(index) {
    const again = this.sort && this.sort.index === index && this.sort.direction === "asc";
    this.sort = { index, direction: again ? "desc" : "asc" };
    this.applySort();
    this.page = 0;
    this.renderTable();
  }

  goto(page) {
    const size = Number($("page-size").value);
    const last = Math.max(0, Math.ceil(this.view.length / size) - 1);
    this.page = Math.min(Math.max(0, page), last);
    this.renderTable();
  }

  renderTable() {
    const { vars } = this.answer;
    const size = Number($("page-size").value);
    const pages = Math.max(1, Math.ceil(this.view.length / size));
    const filtered = this.view.length !== this.answer.rows.length;
    $("status").textContent = filtered
      ? `${this.view.length.toLocaleString()} of ${this.summary}`
      : this.summary;
    $("page-info").textContent = `page ${this.page + 1} of ${pages}`;
    $("page-first").disabled = $("page-prev").disabled = this.page === 0;
    $("page-next").disabled = $("page-last").disabled = this.page >= pages - 1;

    const head = document.createElement("tr");
    vars.forEach((variable, index) => {
      const th = document.createElement("th");
      th.textContent = variable;
      th.dataset.variable = variable;
      if (this.sort && this.sort.index === index) {
        th.className = `sorted-${this.sort.direction}`;
        th.setAttribute("aria-sort", this.sort.direction === "asc" ? "ascending" : "descending");
      }
      th.addEventListener("click", () => this.sortBy(index));
      head.appendChild(th);
    });
    $("results").tHead.replaceChildren(head);

    const body = document.createDocumentFragment();
    for (const row of this.view.slice(this.page * size, (this.page + 1) * size)) {
      const tr = document.createElement("tr");
      let named = null;
      for (const [index, term] of row.entries()) {
        const td = document.createElement("td");
        td.textContent = termText(term);
        td.title = termTitle(term);
        if (term && term.type === "uri") {
          td.className = "iri";
          td.addEventListener("click", (event) => {
            event.stopPropagation();
            this.onIri(term.value);
          });
        } else if (term && this.numeric.has(index)) {
          td.className = "num";
        }
        named = named || this.locate(term);
        tr.appendChild(td);
      }
      if (named) {
        tr.classList.add("locatable");
        tr.title = `${named.label}: click the row to show it in the 3D view`;
        tr.addEventListener("click", () => {
          for (const other of tr.parentNode.querySelectorAll("tr.picked")) other.classList.remove("picked");
          tr.classList.add("picked");
          this.onLocate(named);
        });
      }
      body.appendChild(tr);
    }
    $("results").tBodies[0].replaceChildren(body);
  }

  showMode(mode) {
    this.mode = mode;
    $("show-table").classList.toggle("active", mode === "table");
    $("show-chart").classList.toggle("active", mode === "chart");
    $("table-view").hidden = mode !== "table";
    $("pager").hidden = mode !== "table";
    $("chart-view").hidden = mode !== "chart";
    if (mode === "chart") this.renderChart();
  }

  /** The chart's choices and its default: a measure (a numeric column that is not an id or a
   * position, one named like a count or a length first) over the first text column that tells
   * the rows apart; without a measure, the count of rows per value of the text column that
   * groups them best (fewest values, more than one). */
  fillChartChoices() {
    this.fillAxes();
    this.fillSeries();
  }

  /** The series a chart may have: every measure side by side (two or more), or the rows split
   * by a text column of 2 to 10 values other than x. The default: the measures when there are
   * several, else the grouping column of fewest values, else one series. */
  fillSeries() {
    const { vars, rows } = this.answer;
    const select = $("chart-series");
    const x = Number($("chart-x").value);
    const measures = measureColumns(this.answer);
    const distinct = (i) => new Set(rows.map((r) => (r[i] ? r[i].value : ""))).size;
    const groups = vars.map((_, i) => i).filter((i) => i !== x && !this.numeric.has(i) && !measures.includes(i)
      && rows.some((r) => r[i] && r[i].type === "literal") && distinct(i) >= 2 && distinct(i) <= MAX_SERIES && distinct(i) < rows.length);
    groups.sort((a, b) => distinct(a) - distinct(b));
    const options = [new Option("(one)", "")];
    if (measures.length >= 2) options.push(new Option("every measure", "measures"));
    for (const i of groups) options.push(new Option(`by ${vars[i]}`, `group:${i}`));
    select.replaceChildren(...options);
    const [cx, cy] = ["x", "y"].map((name) => vars.indexOf(name));
    const path = this.numeric.has(cx) && this.numeric.has(cy);
    select.value = path || x < 0 ? "" : measures.length >= 2 ? "measures" : groups.length ? `group:${groups[0]}` : "";
  }

  fillAxes() {
    const { vars, rows } = this.answer;
    const numeric = [...this.numeric];
    const measures = measureColumns(this.answer);
    const xs = $("chart-x");
    const ys = $("chart-y");
    xs.replaceChildren(new Option("(row number)", "-1"), ...vars.map((v, i) => new Option(v, String(i))));
    ys.replaceChildren(new Option("(count of rows)", String(COUNT)), ...numeric.map((i) => new Option(vars[i], String(i))));
    const distinct = (i) => new Set(rows.map((r) => (r[i] ? r[i].value : ""))).size;
    const texts = vars.map((_, i) => i).filter((i) => !this.numeric.has(i) && rows.some((r) => r[i] && r[i].type === "literal"));
    const anyText = vars.map((_, i) => i).filter((i) => !this.numeric.has(i));
    const [cx, cy] = ["x", "y"].map((name) => vars.indexOf(name));
    if (this.numeric.has(cx) && this.numeric.has(cy)) { // coordinates: draw them as a path
      xs.value = String(cx);
      ys.value = String(cy);
      return;
    }
    if (measures.length) {
      const label = [...texts, ...anyText].find((i) => distinct(i) > 1) ?? anyText[0] ?? -1;
      xs.value = String(label);
      ys.value = String(measures[0]);
      return;
    }
    const groups = [...texts, ...anyText].filter((i) => distinct(i) > 1 && distinct(i) < rows.length);
    groups.sort((a, b) => distinct(a) - distinct(b));
    const x = groups[0] ?? anyText.find((i) => distinct(i) > 1) ?? anyText[0];
    xs.value = String(x ?? -1);
    ys.value = String(COUNT);
  }

  renderChart() {
    if (!this.answer || !this.answer.rows.length || $("chart-y").value === "") return;
    const [xi, yi] = [Number($("chart-x").value), Number($("chart-y").value)];
    const series = $("chart-series").value;
    const choice = series === "measures" ? { measures: measureColumns(this.answer) }
      : series.startsWith("group:") ? { group: Number(series.slice(6)) } : null;
    const note = choice && xi >= 0 ? drawSeries($("chart"), this.view, this.answer.vars, xi, yi, choice)
      : drawChart($("chart"), this.view, this.answer.vars, xi, yi);
    $("chart-note").textContent = note;
  }
}
