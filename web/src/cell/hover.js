// Hover: what is under the pointer is named beside it, and a component or item is lit (its
// objects a light blue, the picked thing keeping its own highlight). Looked up at most once per
// frame, and not while a button is held (a drag turns the view).

const $ = (id) => document.getElementById(id);

export class Hover {
  constructor(view) {
    this.view = view;
    this.tip = document.createElement("div");
    this.tip.className = "cell-hover";
    this.tip.hidden = true;
    view.container.appendChild(this.tip);
    this.pending = null;
    const canvas = view.renderer.domElement;
    canvas.addEventListener("pointermove", (event) => {
      if (event.buttons) return;
      const first = !this.pending;
      this.pending = { x: event.clientX, y: event.clientY };
      if (first) requestAnimationFrame(() => this.look());
    });
    canvas.addEventListener("pointerleave", () => {
      this.pending = null;
      this.show(null);
    });
  }

  look() {
    const at = this.pending;
    this.pending = null;
    if (!at || !this.view.objects) return;
    const { hit } = this.view.hitAt(at.x, at.y);
    const what = hit ? this.view.whatIs(hit) : null;
    this.show(what, at);
  }

  /** Name and light what is under the pointer (null: nothing). */
  show(what, at = null) {
    const view = this.view;
    const before = view.hovered;
    view.hovered = what;
    this.tip.hidden = !what;
    view.container.dataset.hovered = what ? what.iri || what.label : "";
    view.renderer.domElement.style.cursor = what ? "pointer" : "";
    if (what && at) {
      const rect = view.container.getBoundingClientRect();
      this.tip.textContent = what.kind === "component" || what.kind === "item" ? what.label : `${what.label} (${what.kind})`;
      this.tip.style.left = `${at.x - rect.left}px`;
      this.tip.style.top = `${at.y - rect.top}px`;
    }
    const same = (before && before.objects) === (what && what.objects)
      || (before && what && before.iri === what.iri && before.label === what.label);
    if (!same && !$("cell-measure").checked) view.paintObjects();
  }
}
