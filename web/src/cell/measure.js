// The distance between two points picked in the 3D view: a point of interest or a harness node
// at its pose in the graph (exactly), anything else where the click met its surface. A third
// pick starts again. Positions are in the view's root frame: metres, as the poses are.

import * as THREE from "three";
import { COLOURS, balls } from "./build.js";

const $ = (id) => document.getElementById(id);

/** A distance as an engineer reads it: millimetres to a tenth under a metre, else metres. */
export function distanceText(metres) {
  return metres < 1 ? `${(metres * 1000).toFixed(1)} mm` : `${metres.toFixed(4)} m`;
}

export class Measure {
  constructor(view) {
    this.view = view;
    this.group = new THREE.Group();
    this.group.name = "measure";
    this.points = [];
    this.labels = [];
  }

  /** Take a picked point ({position, label}); the second gives the distance. */
  add(point) {
    if (!point) return;
    if (this.points.length === 2) this.points = [];
    this.points.push(point);
    this.draw();
  }

  clear() {
    this.points = [];
    this.draw();
  }

  draw() {
    const view = this.view;
    this.group.clear();
    this.labels = [];
    delete view.container.dataset.distance;
    if (this.points.length) {
      const radius = Math.max(view.size * 0.005, 0.002);
      const markers = balls(this.points.map((p) => ({ position: p.position, colour: COLOURS.measure })), radius, "measured");
      Object.assign(markers.material, { depthTest: false, transparent: true });
      markers.renderOrder = 11;
      this.group.add(markers);
      this.labels = this.points.map((p, i) => ({ text: `${"AB"[i]}: ${p.label}`, position: p.position, className: "measure" }));
    }
    if (this.points.length === 2) {
      const [a, b] = this.points.map((p) => p.position);
      const line = new THREE.Line(new THREE.BufferGeometry().setFromPoints([a, b]),
        new THREE.LineBasicMaterial({ color: COLOURS.measure, depthTest: false }));
      line.renderOrder = 11;
      this.group.add(line);
      const metres = a.distanceTo(b);
      const text = distanceText(metres);
      this.labels.push({ text, position: a.clone().add(b).multiplyScalar(0.5), className: "measure distance" });
      view.container.dataset.distance = String(metres);
      $("cell-status").textContent = `distance from ${this.points[0].label} to ${this.points[1].label}: ${text}`;
    } else if (this.points.length === 1) {
      $("cell-status").textContent = `measuring from ${this.points[0].label}: pick the second point`;
    }
    view.setLabels();
  }
}
