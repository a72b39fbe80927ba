// The facts of what was picked in the 3D view (methods of CellView): one row per fact, the named
// graphs stating it when "graphs" is ticked, IRIs clickable into the graph view.

import { shorten } from "../prefixes.js";
import { factsOf, valueText } from "../facts.js";
import { isTypedNumber, termTitle } from "../terms.js";

const $ = (id) => document.getElementById(id);

export const pickFacts = {
  async describe(iri) {
    const body = $("pick-facts").tBodies[0];
    body.replaceChildren();
    this.facts = [];
    if (!iri || iri.startsWith("_:")) return;
    try {
      this.facts = await factsOf(iri);
      this.showFacts();
    } catch (err) {
      const tr = document.createElement("tr");
      tr.textContent = err.message;
      body.appendChild(tr);
    }
  },

  /** The picked thing's facts, one row each; the named graphs stating it with "graphs" ticked. */
  showFacts() {
    const body = $("pick-facts").tBodies[0];
    const graphs = $("pick-graphs").checked;
    body.replaceChildren();
    for (const { p, o, graphs: stated } of this.facts || []) {
      const tr = document.createElement("tr");
      const name = document.createElement("td");
      name.textContent = shorten(p.value);
      const value = document.createElement("td");
      value.textContent = valueText(p.value, o);
      value.title = termTitle(o);
      if (o.type === "uri") {
        value.className = "iri";
        value.addEventListener("click", () => this.onIri(o.value));
      } else if (isTypedNumber(o)) {
        value.className = "num";
      }
      tr.append(name, value);
      if (graphs) {
        const where = document.createElement("td");
        where.className = "graphs";
        where.textContent = stated.map(shorten).join(", ");
        tr.appendChild(where);
      }
      body.appendChild(tr);
    }
    $("pick-facts").dataset.count = String((this.facts || []).length);
  }
};
