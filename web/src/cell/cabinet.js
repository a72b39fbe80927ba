// What the IEMA cabinet's services add to the 3D view (methods of CellView): a component's pins
// at their screw and hole poses (cad_service), and the robot's wires one by one in the order
// group_connection_provider hands them out.

import * as THREE from "three";
import { getJson } from "../api.js";
import { COLOURS, balls } from "./build.js";

const $ = (id) => document.getElementById(id);
const CLIENT = "web-3d";

function vector(p) {
  return new THREE.Vector3(p.position.x, p.position.y, p.position.z);
}

export const cabinet = {
  /** The pins of a component: screws (orange) and holes (blue) at their poses, named. */
  async showPins(label) {
    const component = this.data.components.find((c) => c.label === label);
    if (!component || !component.frame || this.data.profile !== "iema") return;
    const result = await getJson(`/api/cad_service?${new URLSearchParams({ label, client: CLIENT })}`);
    if (!result.success) return;
    const frame = this.matrixOf(component.frame) || new THREE.Matrix4();
    const radius = Math.max(this.size * 0.002, 0.0015);
    const screws = [];
    const holes = [];
    for (const pin of result.pins) {
      for (const [pose, list] of [[pin.screw, screws], [pin.hole, holes]]) {
        if (pose) list.push({ position: vector(pose).applyMatrix4(frame), pin });
      }
    }
    for (const [list, colour, kind] of [[screws, COLOURS.screw, "screw"], [holes, COLOURS.hole, "hole"]]) {
      if (!list.length) continue;
      const mesh = balls(list.map((p) => ({ position: p.position, colour })), radius, `${kind}s`);
      // Screws and holes lie inside their component's box: drawn over it, as markers.
      Object.assign(mesh.material, { depthTest: false, transparent: true });
      mesh.renderOrder = 10;
      mesh.userData.pinList = list;
      mesh.userData.kind = kind;
      this.extras.add(mesh);
    }
    this.extraLabels = screws.map((p) => ({ text: `${p.pin.pin}`, position: p.position, className: "pin" }));
    for (const mesh of this.extras.children) if (mesh.userData.pinList) this.pickables.unshift(mesh);
    $("cell-status").dataset.pins = String(result.pins.length);
    this.setLabels();
  },

  /** The next wire the robot makes, in the order group_connection_provider hands them out (the
   * scene's routes, robot's first to last): its path as a tube, its ends as the pins. The page
   * keeps its own place, so looking at wires moves no cursor of the served cell. */
  async nextWire() {
    const robot = this.data.routes.filter((r) => r.performer === "robot");
    this.wireIndex = this.wireIndex === undefined ? 0 : this.wireIndex + 1;
    if (this.wireIndex >= robot.length) {
      this.wireIndex = undefined;
      $("cell-status").textContent = "the connection list is done; Next wire starts it again";
      return;
    }
    const route = robot[this.wireIndex];
    const frame = this.matrixOf(route.frame) || new THREE.Matrix4();
    const path = [];
    for (let i = 0; i + 2 < route.points.length; i += 3) {
      path.push(new THREE.Vector3(route.points[i], route.points[i + 1], route.points[i + 2]).applyMatrix4(frame));
    }
    await this.select({ kind: "wire", label: `wire ${route.label} (list position ${route.position})`, iri: route.iri });
    this.addRoute(path);
    const box = new THREE.Box3().setFromPoints(path).expandByScalar(this.size * 0.03);
    this.fit(box.applyMatrix4(this.root.matrixWorld)); // the wire, end to end
    this.extraLabels = [
      { text: route.origin, position: path[0] },
      { text: route.destination, position: path[path.length - 1] },
    ];
    this.setLabels();
  }
};
