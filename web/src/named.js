// The named queries as examples. Picking one puts its text in the editor with its parameters
// bound as the VALUES block the server itself adds (so what is shown is what runs), and a
// field per parameter. Editing the text keeps the block, and so the parameter; changing a
// field rewrites the block in place. A block edited away by hand detaches the fields.

import { getJson } from "./api.js";

const $ = (id) => document.getElementById(id);

export class NamedQueries {
  constructor({ getText, setText, onChange }) {
    this.getText = getText;
    this.setText = setText;
    this.onChange = onChange; // (named) -> the tab keeps it
    this.queries = {};
    this.named = null;
    this.dirty = false;
  }

  /** The named queries, the cell's own (and cadkg's, for any cell) first; those of other
   * profiles only with the "other cells'" box ticked. `owners`: query name -> its profile. */
  async load(profile = "", owners = {}) {
    this.profile = profile;
    this.owners = owners;
    const own = [];
    const others = [];
    for (const q of await getJson("/api/queries")) {
      this.queries[q.name] = q;
      const owner = owners[q.name] || "";
      const option = new Option(owner && owner !== profile ? `${q.name} (${owner})` : q.name, q.name);
      option.title = q.description;
      (!profile || !owner || owner === profile ? own : others).push(option);
    }
    $("examples").append(...own);
    this.others = document.createElement("optgroup");
    this.others.label = "other cells' queries";
    this.others.append(...others);
    $("examples-all-box").hidden = others.length === 0;
    $("examples-all").addEventListener("change", () => this.showOthers($("examples-all").checked));
  }

  /** Offer the other profiles' queries too, or not. */
  showOthers(on) {
    $("examples-all").checked = on;
    if (on && !this.others.parentNode) $("examples").appendChild(this.others);
    if (!on && this.others.parentNode) this.others.remove();
  }

  isOthers(name) {
    const owner = (this.owners || {})[name] || "";
    return Boolean(this.profile && owner && owner !== this.profile);
  }

  /** A parameter's example value: the one its description gives, unless a query of cadkg's
   * own (for any cell) gives a component label this cell does not have (the examples are the
   * IEMA cabinet's); then the first of this cell's component labels. */
  example(param, name) {
    const match = /e\.g\.\s*([^\s,;)]+)/.exec(param.description || "");
    const given = match ? match[1] : "";
    const labels = this.labels || [];
    const own = !(this.owners || {})[name];
    if (param.name !== "label" || !own || !labels.length || labels.includes(given)) return given;
    return labels[0];
  }

  /** Pick a named query: its text, bound with the example values, replaces the editor's. */
  async pick(name) {
    const query = this.queries[name];
    if (!query) return this.show(null);
    const params = {};
    for (const p of query.params) params[p.name] = this.example(p, name);
    const bound = await this.bind(name, params);
    this.named = { name, params, values: bound.values };
    this.setText(bound.text);
    this.show(this.named);
    this.onChange(this.named);
  }

  async bind(name, params) {
    return getJson(`/api/queries/${encodeURIComponent(name)}/bound?${new URLSearchParams(params)}`);
  }

  /** Show the fields of a tab's named query (none for a query of one's own). */
  show(named) {
    this.named = named;
    this.dirty = false;
    const box = $("params");
    box.replaceChildren();
    if (named && this.isOthers(named.name)) this.showOthers(true); // a tab or link of another cell's query
    $("examples").value = named ? named.name : "";
    const query = named ? this.queries[named.name] : null;
    $("example-help").textContent = query ? query.description : "";
    if (!query) {
      $("binding").hidden = true;
      return;
    }
    for (const p of query.params) {
      const input = document.createElement("input");
      input.name = p.name;
      input.id = `param-${p.name}`;
      input.placeholder = p.name;
      input.title = `${p.name} (${p.type}): ${p.description}`;
      input.value = named.params[p.name] ?? "";
      if (p.name === "label") input.setAttribute("list", "component-labels");
      input.addEventListener("input", () => { this.dirty = true; });
      input.addEventListener("change", () => this.rebind());
      box.appendChild(input);
    }
    this.describe();
  }

  describe() {
    const note = $("binding");
    if (!this.named || !this.named.values) {
      note.hidden = true;
      return;
    }
    const attached = this.getText().includes(this.named.values);
    note.hidden = false;
    note.classList.toggle("detached", !attached);
    note.textContent = attached
      ? `Parameters bound in the query by ${this.named.values}`
      : "The parameters' VALUES block was edited in the text: the fields no longer apply to it.";
    for (const input of $("params").querySelectorAll("input")) input.disabled = !attached;
  }

  /** Bind the fields' values anew, one binding after the other (a field's change and a run's
   * settle may both ask; the later must not be overwritten by the earlier). */
  rebind() {
    this.binding = (this.binding || Promise.resolve()).then(() => this.rebindNow(), () => this.rebindNow());
    return this.binding;
  }

  /** The old VALUES block in the text becomes the new one. */
  async rebindNow() {
    const named = this.named;
    if (!named) return;
    const params = {};
    for (const input of $("params").querySelectorAll("input")) params[input.name] = input.value;
    const text = this.getText();
    if (!text.includes(named.values)) {
      this.describe();
      return;
    }
    const bound = await this.bind(named.name, params);
    this.dirty = false;
    const updated = { ...named, params, values: bound.values };
    this.named = updated;
    this.setText(text.replace(named.values, bound.values));
    this.onChange(updated);
    this.describe();
  }

  /** Before a run: fields typed into but not yet bound are bound now. */
  async settle() {
    if (this.named && this.dirty) await this.rebind();
    else if (this.binding) await this.binding;
  }
}
