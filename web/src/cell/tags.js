// Tags: the label of every component and placed item, at the middle of its box's face towards
// the front (the plate's normal: a cabinet's front, a platform's top), so solid geometry in
// front of it hides it (cell/occlusion.js) and its own body does not.

import * as THREE from "three";

/** The tags of a view's components and items: [{text, position (root frame), className}]. */
export function tagsOf(view) {
  const plate = view.plateBasis();
  const normal = plate ? plate.z : null;
  const world = view.root.matrixWorld;
  const out = [];
  for (const thing of view.things.list) {
    if (thing.group !== "component" && thing.group !== "item") continue;
    if (!thing.label || view.isHidden(thing)) continue;
    const box = view.whereIs(thing);
    if (!box) continue;
    box.applyMatrix4(world);
    const centre = box.getCenter(new THREE.Vector3());
    if (normal) {
      const half = box.getSize(new THREE.Vector3()).multiplyScalar(0.5);
      centre.addScaledVector(normal, Math.abs(normal.x) * half.x + Math.abs(normal.y) * half.y + Math.abs(normal.z) * half.z);
    }
    out.push({ text: thing.label, position: view.root.worldToLocal(centre), className: "tag", margin: view.size * 0.002 });
  }
  return out;
}
