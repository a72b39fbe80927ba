// What the model tree hides, applied to what is drawn: objects left out of the merged
// geometry, points and harness nodes shrunk to nothing, a wire's or a segment's lines folded to
// a point. Picking skips what is hidden (the view asks `hides`).

import * as THREE from "three";

const ZERO = new THREE.Matrix4().makeScale(0, 0, 0);

/** Show or shrink each instance of an instanced mesh (`hidden(i)`), keeping its matrices. */
function shrink(mesh, hidden) {
  if (!mesh.userData.matrices) {
    mesh.userData.matrices = Array.from({ length: mesh.count }, (_, i) => { const m = new THREE.Matrix4(); mesh.getMatrixAt(i, m); return m; });
  }
  mesh.userData.matrices.forEach((matrix, i) => mesh.setMatrixAt(i, hidden(i) ? ZERO : matrix));
  mesh.instanceMatrix.needsUpdate = true;
}

/** Fold each segment of a LineSegments (`hidden(i)`) to its first end, keeping its positions. */
function fold(lines, hidden) {
  const attribute = lines.geometry.attributes.position;
  if (!lines.userData.positions) lines.userData.positions = attribute.array.slice();
  const original = lines.userData.positions;
  for (let segment = 0; segment * 6 < original.length; segment++) {
    const k = segment * 6;
    for (let j = 0; j < 6; j++) attribute.array[k + j] = hidden(segment) ? original[k + (j % 3)] : original[k + j];
  }
  attribute.needsUpdate = true;
}

/** Apply a set of hidden things (from view.things) to the view's drawing. */
export function applyHidden(view, hidden) {
  const objects = new Set();
  const points = new Set();
  const routes = new Set();
  const nodes = new Set();
  for (const thing of hidden) {
    for (const index of thing.objects || []) objects.add(index);
    if (thing.route) routes.add(thing.route);
    if (thing.node) nodes.add(thing.node);
    if (thing.position && !thing.node) points.add(thing.label);
  }
  // The merged geometry is made anew: what is picked is the new one.
  view.pickables = view.pickables.filter((o) => o.parent !== view.objects.group);
  view.objects.hide(objects);
  view.pickables.push(...view.objects.group.children);
  for (const mesh of [view.pointMesh, view.haloMesh]) {
    const list = mesh.userData.points;
    if (list.length) shrink(mesh, (i) => points.has(list[i].label));
  }
  const routeOf = view.routes.pick;
  if (view.data.routes.length) fold(view.routes.lines, (segment) => routes.has(view.data.routes[routeOf(segment * 2)]));
  view.harnesses.forEach((h, i) => {
    const harness = view.data.harnesses[i];
    if (!harness.nodes.length) return;
    shrink(h.nodes, (j) => nodes.has(harness.nodes[j]));
    const gone = (s) => nodes.has(harness.nodes[s.from]) || nodes.has(harness.nodes[s.to]);
    if (harness.segments.length) fold(h.lines, (k) => gone(harness.segments[k]));
  });
  view.setLabels();
  view.requestRender();
}
