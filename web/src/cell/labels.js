// Names over the 3D view: HTML labels placed at projected points after each frame, a few
// hundred at most (tags of components and items, pins of the chosen component, connectors,
// keys). A label behind the camera, off the view, behind solid geometry (cell/occlusion.js,
// checked when the view rests) or over one placed before it is hidden, so none is drawn over
// another. An entry marked `over` belongs to something drawn over everything (the picked
// component's pins, a measure) and is never hidden by geometry; one with a `margin` (metres) is
// hidden by geometry that far in front of it (a tag on its own face: little), else by a margin of
// the view's choosing (a key's ball pokes out of its guide).

import * as THREE from "three";

export class Labels {
  constructor(container) {
    this.layer = document.createElement("div");
    this.layer.className = "cell-labels";
    container.appendChild(this.layer);
    this.entries = [];
  }

  set(entries) {
    this.layer.replaceChildren();
    this.entries = entries.map((entry) => {
      const element = document.createElement("div");
      element.className = `cell-label${entry.className ? ` ${entry.className}` : ""}`;
      element.textContent = entry.text;
      this.layer.appendChild(element);
      return { ...entry, element, behind: false };
    });
  }

  /** Which labels solid geometry hides now (`hidden(points)`: a boolean per world point). */
  occlude(root, hidden) {
    const checked = this.entries.filter((entry) => !entry.over);
    const flags = hidden(checked.map((entry) => root.localToWorld(entry.position.clone())), checked.map((entry) => entry.margin));
    checked.forEach((entry, i) => { entry.behind = flags[i]; });
  }

  update(camera, root, container) {
    const width = container.clientWidth;
    const height = container.clientHeight;
    const point = new THREE.Vector3();
    const taken = [];
    for (const entry of this.entries) {
      point.copy(entry.position);
      root.localToWorld(point);
      point.project(camera);
      const x = ((point.x + 1) / 2) * width;
      const y = ((1 - point.y) / 2) * height;
      // The label's box as CSS draws it: centred above the point (an estimate of its width).
      const w = entry.text.length * 6.6 + 8;
      const box = { x: x - w / 2, y: y - 22, w, h: 17 };
      const free = !taken.some((b) => box.x < b.x + b.w && b.x < box.x + box.w && box.y < b.y + b.h && b.y < box.y + box.h);
      const visible = point.z < 1 && Math.abs(point.x) <= 1 && Math.abs(point.y) <= 1 && free && !entry.behind;
      entry.element.hidden = !visible;
      entry.element.classList.toggle("behind", entry.behind);
      if (visible) {
        taken.push(box);
        entry.element.style.left = `${x}px`;
        entry.element.style.top = `${y}px`;
      }
    }
  }
}
