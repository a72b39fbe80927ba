// What the browser tests and the page benchmark ask the 3D view (methods of CellView): where a
// thing is on the screen, and how long picking and drawing take.

import * as THREE from "three";

export const probes = {
  /** Where a component's first object (or a harness node of that label or connector, or a
   * point of interest) is on the screen, in client coordinates; null when there is none. */
  screenPosition(label) {
    const centre = new THREE.Vector3();
    const component = this.data.components.find((c) => c.label === label);
    if (component && component.objects.length) {
      const object = this.data.objects[component.objects[0]];
      if (object.box) {
        const [x0, y0, z0, x1, y1, z1] = object.box;
        centre.set((x0 + x1) / 2, (y0 + y1) / 2, (z0 + z1) / 2);
      }
      centre.applyMatrix4(this.matrixOf(object.frame));
    } else {
      // Anything else drawn: a point or a node where it is, an item at its box's middle, a
      // wire at its middle keypoint (on the line, where a click finds it).
      const thing = this.things.find(label);
      const box = thing && this.whereIs(thing);
      if (!box) return null;
      if (thing.path) centre.copy(thing.path[Math.floor(thing.path.length / 2)]);
      else box.getCenter(centre);
    }
    this.root.localToWorld(centre);
    centre.project(this.camera);
    const rect = this.renderer.domElement.getBoundingClientRect();
    return { x: rect.left + ((centre.x + 1) / 2) * rect.width, y: rect.top + ((1 - centre.y) / 2) * rect.height };
  },

  /** Milliseconds to pick what is under `count` points across the view (median), as a click does. */
  measurePick(count = 20) {
    const raycaster = new THREE.Raycaster();
    raycaster.params.Line.threshold = this.camera.position.distanceTo(this.controls.target) * 0.006;
    const visible = this.pickables.filter((o) => o.visible);
    const times = [];
    let hits = 0;
    for (let i = 0; i < count; i++) {
      const start = performance.now();
      raycaster.setFromCamera(new THREE.Vector2(-0.8 + (1.6 * i) / count, 0.1), this.camera);
      hits += raycaster.intersectObjects(visible, false).length > 0;
      times.push(performance.now() - start);
    }
    times.sort((a, b) => a - b);
    return { median: times[Math.floor(count / 2)], hits };
  },

  /** Milliseconds per frame (median of `frames`) while the camera turns around the cell, with
   * everything drawn, and (`moving`) as while the camera is dragged. */
  measure(frames = 30) {
    // The cell's own drawing: the grid and plate under it are left out, as the recorded figures were.
    const ground = Boolean(this.ground && this.ground.visible);
    if (this.ground) this.ground.visible = false;
    const full = this.measureFrames(frames);
    const visible = this.routes.lines.visible;
    this.routes.lines.visible = false;
    const moving = this.measureFrames(frames);
    this.routes.lines.visible = visible;
    if (this.ground) this.ground.visible = ground;
    return { ...full, moving: moving.median };
  },

  measureFrames(frames) {
    const gl = this.renderer.getContext();
    const pixel = new Uint8Array(4);
    const times = [];
    const target = this.controls.target.clone();
    const offset = this.camera.position.clone().sub(target);
    for (let i = 0; i < frames; i++) {
      offset.applyAxisAngle(new THREE.Vector3(0, 1, 0), (2 * Math.PI) / frames);
      this.camera.position.copy(target).add(offset);
      this.camera.lookAt(target);
      const start = performance.now();
      this.renderer.render(this.scene, this.camera);
      gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, pixel); // waits for the frame
      times.push(performance.now() - start);
    }
    times.sort((a, b) => a - b);
    return { median: times[Math.floor(times.length / 2)], calls: this.renderer.info.render.calls, triangles: this.renderer.info.render.triangles };
  }
};
