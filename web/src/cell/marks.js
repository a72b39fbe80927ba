// Things marked in the 3D view by a feature of the page (the plan's next tasks, what changed):
// a component's or item's objects painted its colour, a wire as a thin tube, a point as a ball,
// each see-through so the picked thing stands out. Each feature keeps its own marks.

import * as THREE from "three";
import { balls, tube } from "./build.js";
import { pieces } from "./tasks.js";

export class Marks {
  constructor(view) {
    this.view = view;
    this.owners = new Map();
    this.group = new THREE.Group();
    this.group.name = "marks";
    view.root.add(this.group);
    view.marks = new Map();
  }

  /** Mark things for one owner: [{thing, colour (THREE.Color)}]; an empty list clears them. */
  set(owner, entries) {
    this.owners.set(owner, entries);
    this.apply();
  }

  apply() {
    const view = this.view;
    const colours = new Map();
    this.group.clear();
    for (const entries of this.owners.values()) {
      for (const { thing: marked, colour } of entries) for (const thing of pieces(marked)) {
        for (const index of thing.objects || []) colours.set(index, colour);
        if (thing.path && thing.path.length > 1) {
          const line = tube(thing.path, view.size * 0.001, colour);
          line.traverse((o) => { if (o.material) Object.assign(o.material, { transparent: true, opacity: 0.6 }); });
          this.group.add(line);
        } else if (thing.position) {
          const ball = balls([{ position: thing.position, colour }], Math.max(view.size * 0.009, 0.003), "mark");
          Object.assign(ball.material, { transparent: true, opacity: 0.5, depthWrite: false });
          this.group.add(ball);
        }
      }
    }
    view.marks = colours;
    view.paintObjects();
  }
}
