// The model tree: everything the 3D view draws, by kind (components, items, guides' keys,
// taping spots, bench pins, harness nodes, wires), each kind and each thing with a box to show
// or hide it and a button to isolate it (hide everything else); a name's click shows it as a
// search does. A kind lists its first LIST things; the search field finds the rest.

import { applyHidden } from "./hiding.js";

const LIST = 300;
const NAMES = {
  component: "components", item: "items", key: "guides' keys", "key-corner": "key corners", "tape-spot": "taping spots",
  "bench-pin": "bench pins", "harness node": "harness nodes", wire: "wires",
};

function button(text, title, onClick) {
  const b = document.createElement("button");
  b.type = "button";
  b.className = "quiet";
  b.textContent = text;
  b.title = title;
  b.addEventListener("click", (event) => {
    event.preventDefault();
    onClick();
  });
  return b;
}

export class ModelTree {
  constructor(view, element) {
    this.view = view;
    this.element = element;
    this.hidden = new Set();
    this.kinds = new Map();
    for (const thing of view.things.list) {
      if (!this.kinds.has(thing.kind)) this.kinds.set(thing.kind, []);
      this.kinds.get(thing.kind).push(thing);
    }
    this.render();
  }

  /** Whether the tree hides what a pick or a label names (a thing, or what whatIs gives). */
  hides(what) {
    if (!what || !this.hidden.size) return false;
    if (this.hidden.has(what)) return true;
    const things = this.view.things;
    // A harness segment is hidden with either of its nodes.
    if (what.ends) return what.ends.some((node) => this.hidden.has(things.of(node)));
    const thing = (what.node && things.of(what.node)) || (what.route && things.of(what.route)) || things.find(what.label) || things.find(what.iri);
    return this.hidden.has(thing);
  }

  isHidden(thing) {
    return this.hidden.has(thing);
  }

  set(hidden) {
    this.hidden = new Set(hidden);
    applyHidden(this.view, this.hidden);
    this.render();
    this.view.container.dataset.hidden = String(this.hidden.size);
  }

  /** Show (`on`) or hide some things. */
  show(things, on) {
    const hidden = new Set(this.hidden);
    for (const thing of things) if (on) hidden.delete(thing); else hidden.add(thing);
    this.set(hidden);
  }

  /** Hide everything but these things. */
  isolate(things) {
    const keep = new Set(things);
    this.set(this.view.things.list.filter((thing) => !keep.has(thing)));
  }

  row(name, things, open) {
    const row = document.createElement("div");
    row.className = "row";
    const box = document.createElement("input");
    box.type = "checkbox";
    box.checked = things.some((thing) => !this.hidden.has(thing));
    box.indeterminate = box.checked && things.some((thing) => this.hidden.has(thing));
    box.title = "Show or hide";
    box.addEventListener("click", (event) => event.stopPropagation());
    box.addEventListener("change", () => this.show(things, box.checked));
    const label = document.createElement("span");
    label.className = "name";
    label.textContent = name;
    label.title = name;
    if (open) label.addEventListener("click", open);
    row.append(box, label, button("isolate", `Show only ${name}`, () => this.isolate(things)));
    row.dataset.name = name;
    return row;
  }

  render() {
    const openKinds = new Set([...this.element.querySelectorAll("details[open]")].map((d) => d.dataset.kind));
    this.element.replaceChildren();
    const top = document.createElement("div");
    top.className = "row";
    top.append(button("show all", "Show everything", () => this.set([])));
    this.element.appendChild(top);
    for (const [kind, things] of this.kinds) {
      const details = document.createElement("details");
      details.dataset.kind = kind;
      details.open = openKinds.has(kind);
      const summary = document.createElement("summary");
      summary.appendChild(this.row(`${NAMES[kind] || kind} (${things.length})`, things));
      details.appendChild(summary);
      for (const thing of things.slice(0, LIST)) {
        details.appendChild(this.row(thing.label, [thing], () => this.view.locate({ label: thing.label, iri: thing.iri })));
      }
      if (things.length > LIST) {
        const more = document.createElement("p");
        more.className = "more";
        more.textContent = `and ${things.length - LIST} more: find them by name`;
        details.appendChild(more);
      }
      this.element.appendChild(details);
    }
  }
}
