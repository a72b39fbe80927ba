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

  async load() {
    const select = $("examples");
    for (const q of await getJson("/api/queries")) {
      this.queries[q.name] = q;
      const option = new Option(q.name, q.name);
      option.title = q.description;
      select.appendChild(option);
    }
  }

  example(param) {
    const match = /e\.g\.\s*([^\s,;)]+)/.exec(param.description || "");
    return match ? match[1] : "";
  }

  /** Pick a named query: its text, bound with the example values, replaces the editor's. */
  async pick(name) {
    const query = this.queries[name];
    if (!query) return this.show(null);
    const params = {};
    for (const p of query.params) params[p.name] = this.example(p);
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

  /** Bind the fields' values anew: the old VALUES block in the text becomes the new one. */
  async rebind() {
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
  }
}
