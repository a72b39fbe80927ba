// What changed in the served graph (/api/changes, Server-Sent Events after every rebuild,
// reload, load_files, update or assignment): the latest change set listed over the view
// ("what changed": added, changed, removed, each with its kind and identity), and what of it is
// drawn marked: added things green, changed ones amber. A click on a listed thing shows it.
// Things the drawn scene does not have yet (added by a rebuild) are listed, and the list says
// that reloading the page draws them. A graph that cannot change (built in memory, served
// without the token) is not followed.

import * as THREE from "three";
import { getJson } from "../api.js";

const $ = (id) => document.getElementById(id);
const COLOURS = { added: new THREE.Color("#16a34a"), changed: new THREE.Color("#f59e0b") };

const RETRY_MS = 15000;

export class ChangeFeed {
  constructor(view) {
    this.view = view;
    this.source = null;
    // Only a graph that can change is followed (/api/info says: a store directory, or the token).
    getJson("/api/info").then((info) => { if (info.changes) this.connect(); }).catch(() => {});
    $("changes-clear").addEventListener("click", () => {
      $("changes").hidden = true;
      view.markers.set("changes", []);
    });
  }

  /** Follow the feed; when the endpoint goes away, try again after a while, not at once. */
  connect() {
    this.source = new EventSource("/api/changes");
    this.source.addEventListener("changes", (event) => this.show(JSON.parse(event.data)));
    this.source.addEventListener("error", () => {
      this.close();
      this.retry = setTimeout(() => this.connect(), RETRY_MS);
    });
    this.view.container.dataset.following = "true";
  }

  thingOf(entry) {
    const things = this.view.things;
    return things.find(entry.iri) || things.find(entry.id);
  }

  show(changes) {
    const list = $("changes-list");
    list.replaceChildren();
    const marks = [];
    let undrawn = 0;
    for (const how of ["added", "changed", "removed"]) {
      for (const entry of changes[how] || []) {
        const thing = how === "removed" ? null : this.thingOf(entry);
        if (thing) marks.push({ thing, colour: COLOURS[how] });
        else if (how !== "removed") undrawn += 1;
        const item = document.createElement("li");
        item.className = how;
        const attributes = Object.keys(entry.attributes || {});
        item.textContent = `${how} ${entry.kind} ${entry.id}${attributes.length ? `: ${attributes.join(", ")}` : ""}`;
        if (thing) {
          item.classList.add("drawn");
          item.addEventListener("click", () => this.view.locate({ label: thing.label, iri: thing.iri }));
        }
        list.appendChild(item);
      }
    }
    const count = list.children.length;
    $("changes-count").textContent = count ? `${count} thing(s), ${changes.old || "?"} → ${changes.new || "?"}` : "nothing";
    $("changes-note").textContent = undrawn ? `${undrawn} of them not in the drawn scene: reload the page to draw them` : "";
    $("changes").hidden = false;
    this.view.container.dataset.changed = marks.map((m) => m.thing.iri || m.thing.label).join(" ");
    this.view.markers.set("changes", marks);
  }

  close() {
    if (this.source) this.source.close();
    this.source = null;
  }
}
