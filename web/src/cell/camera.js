// Where the 3D view looks from (methods of CellView): the view presets in the axes of the frame
// most objects hang from, the perspective or orthographic camera, fitting everything or one
// thing into the view.

import * as THREE from "three";
import { pieces } from "./tasks.js";

// The view presets, in the axes of the frame most objects hang from (a cabinet's plate: x to
// the right, y up, z out of it): face on, from above, from the right, and from a corner.
export const PRESETS = {
  front: (b) => ({ eye: b.z.clone(), up: b.y.clone() }),
  top: (b) => ({ eye: b.y.clone(), up: b.z.clone().negate() }),
  side: (b) => ({ eye: b.x.clone(), up: b.y.clone() }),
  iso: (b) => ({ eye: b.x.clone().add(b.y).add(b.z).normalize(), up: b.y.clone() }),
};

export const camera = {
  /** The orthographic camera's box: `half` high each way, as wide as the view is. */
  frustum() {
    const half = this.half || 1;
    const aspect = this.camera.aspect || 1;
    Object.assign(this.camera, { left: -half * aspect, right: half * aspect, top: half, bottom: -half, zoom: 1 });
    this.camera.updateProjectionMatrix();
  },

  /** Look from a preset direction (front, top, side, iso; null: the first view) at everything. */
  view(preset) {
    this.preset = PRESETS[preset] ? preset : null;
    this.container.dataset.preset = this.preset || "";
    this.fit();
  },

  /** An orthographic camera (no perspective: parallel edges stay parallel, sizes compare), or not. */
  setOrthographic(on) {
    const aspect = this.camera.aspect || 1;
    this.camera = on ? new THREE.OrthographicCamera(-1, 1, 1, -1, 0.001, 1000) : new THREE.PerspectiveCamera(40, aspect, 0.001, 1000);
    this.camera.aspect = aspect;
    this.controls.dispose();
    this.makeControls();
    this.controlsUp = null;
    this.container.dataset.projection = on ? "orthographic" : "perspective";
    this.fit();
  },

  /** Everything drawn (not the frame axes, which reach to the world's origin), in world coordinates. */
  contentBox() {
    const box = new THREE.Box3();
    this.root.updateMatrixWorld(true);
    const parts = [this.objects.group, this.routes.lines, ...this.harnesses.map((h) => h.group)];
    if (this.points.length) parts.push(this.pointMesh, this.haloMesh);
    for (const part of parts) {
      part.traverse((object) => {
        if (!object.geometry || !object.visible || (object.isInstancedMesh && object.count === 0)) return;
        if (object.isInstancedMesh) {
          if (!object.boundingBox) object.computeBoundingBox();
          box.union(object.boundingBox.clone().applyMatrix4(object.matrixWorld));
        } else {
          box.expandByObject(object);
        }
      });
    }
    return box;
  },

  /**
   * How to look at the cell: towards the z axis of the frame most objects hang from (a cabinet's
   * mounting plate, a platform's top), its y axis up on the screen, from a little above and to
   * the right. A cell without objects (a harness) is looked at along its thinnest side.
   */
  viewAxes(size) {
    const plate = this.plateBasis();
    if (plate) {
      const { x, y, z } = plate;
      if (this.preset) return PRESETS[this.preset]({ x, y, z });
      return { eye: z.clone().addScaledVector(y, 0.3).addScaledVector(x, 0.25).normalize(), up: y };
    }
    if (this.preset) {
      return PRESETS[this.preset]({ x: new THREE.Vector3(1, 0, 0), y: new THREE.Vector3(0, 1, 0), z: new THREE.Vector3(0, 0, 1) });
    }
    const thinnest = size.x <= size.y && size.x <= size.z ? 0 : size.y <= size.z ? 1 : 2;
    const eye = [new THREE.Vector3(1, 0.3, 0.25), new THREE.Vector3(0.2, 1, 0.45), new THREE.Vector3(0.25, 0.3, 1)][thinnest];
    return { eye: eye.normalize(), up: thinnest === 1 ? new THREE.Vector3(0, 0, -1) : new THREE.Vector3(0, 1, 0) };
  },

  /** The axes (world) of the frame most objects hang from, or null when no object hangs from one. */
  plateBasis() {
    const parents = new Map();
    const parentOf = new Map(this.data.frames.map((f) => [f.name, f.parent]));
    for (const object of this.data.objects) {
      const parent = parentOf.get(object.frame);
      if (parent) parents.set(parent, (parents.get(parent) || 0) + 1);
    }
    if (!parents.size) return null;
    const [frame] = [...parents].sort((a, b) => b[1] - a[1])[0];
    const matrix = new THREE.Matrix4().multiplyMatrices(this.root.matrixWorld, this.matrixOf(frame) || new THREE.Matrix4());
    const x = new THREE.Vector3();
    const y = new THREE.Vector3();
    const z = new THREE.Vector3();
    matrix.extractBasis(x, y, z);
    return { x, y, z };
  },

  /** Look at `box` (world coordinates), or at everything. */
  fit(box = null) {
    const target = box || this.contentBox();
    if (target.isEmpty()) return;
    const centre = target.getCenter(new THREE.Vector3());
    const size = target.getSize(new THREE.Vector3());
    const radius = Math.max(size.length() / 2, 0.02);
    const { eye, up } = this.viewAxes(size);
    let distance = (radius / Math.sin(THREE.MathUtils.degToRad(40 / 2))) * 1.05;
    if (this.camera.isOrthographicCamera) {
      // The same part of the cell in view as the perspective camera shows at the fitted distance.
      this.half = radius * 1.05;
      this.frustum();
      distance = radius * 4;
    }
    this.camera.up.copy(up);
    this.camera.position.copy(centre).addScaledVector(eye, distance);
    this.camera.near = distance / 1000;
    this.camera.far = distance * 100;
    this.camera.updateProjectionMatrix();
    if (!this.controlsUp || !this.controlsUp.equals(up)) {
      this.controls.dispose(); // OrbitControls takes the camera's up when made
      this.makeControls();
      this.controlsUp = up.clone();
    }
    this.controls.target.copy(centre);
    this.controls.update();
    this.requestRender();
  },

  /** Where a thing is, as a box in the root's frame (null when it is nowhere). */
  whereIs(thing) {
    const box = new THREE.Box3();
    const corner = new THREE.Vector3();
    for (const part of pieces(thing)) {
      if (part.position) box.expandByPoint(part.position);
      for (const p of part.path || []) box.expandByPoint(p);
    }
    for (const index of thing.objects || []) {
      const object = this.data.objects[index];
      const m = this.matrixOf(object.frame);
      if (!m) continue;
      const [x0, y0, z0, x1, y1, z1] = object.box || [0, 0, 0, 0, 0, 0];
      for (const x of [x0, x1]) for (const y of [y0, y1]) for (const z of [z0, z1]) box.expandByPoint(corner.set(x, y, z).applyMatrix4(m));
    }
    return box.isEmpty() ? null : box;
  },

  /** Bring the camera close to a thing, with some of its neighbourhood around it. */
  zoomTo(thing) {
    const box = this.whereIs(thing);
    if (!box) return;
    const size = box.getSize(new THREE.Vector3()).length();
    // A point (a key, a pin, a node) is shown with a twentieth of the cell around it.
    box.expandByScalar(size > 0 ? Math.max(size * 0.3, this.size * 0.01) : this.size * 0.05);
    box.applyMatrix4(this.root.matrixWorld);
    this.fit(box);
  }
};
