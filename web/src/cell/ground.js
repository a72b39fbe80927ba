// What the cell stands on, and how large it is: a grid with a faint plate under (or behind) the
// cell, in the plane it is laid out in (a cabinet's mounting plate, a platform's top, a bench
// of pins, a harness laid flat), and a scale bar over the view's lower left corner. Neither is
// picked, measured, fitted to or hides a label.

import * as THREE from "three";

/** The largest of 1, 2, 5 times a power of ten that is at most `value`. */
export function niceBelow(value) {
  const power = 10 ** Math.floor(Math.log10(value));
  return [5, 2, 1].map((m) => m * power).find((step) => step <= value) || power;
}

/** The grid's axes: the plate's (`plate`, world) or, without one, the world's with the normal
 * along the content's thinnest side. */
function axesOf(plate, size) {
  if (plate) return { u: plate.x, v: plate.y, n: plate.z };
  const unit = [new THREE.Vector3(1, 0, 0), new THREE.Vector3(0, 1, 0), new THREE.Vector3(0, 0, 1)];
  const sizes = [size.x, size.y, size.z];
  const thinnest = sizes.indexOf(Math.min(...sizes));
  const [u, v] = unit.filter((_, i) => i !== thinnest);
  return { u, v, n: unit[thinnest] };
}

/** The grid and plate for a content box (world), as a group in world coordinates. */
export function buildGround(box, plate) {
  const group = new THREE.Group();
  group.name = "ground";
  if (box.isEmpty()) return group;
  const size = box.getSize(new THREE.Vector3());
  const { u, v, n } = axesOf(plate, size);
  const corners = [];
  for (const x of [box.min.x, box.max.x]) for (const y of [box.min.y, box.max.y]) for (const z of [box.min.z, box.max.z]) corners.push(new THREE.Vector3(x, y, z));
  const range = (axis) => [Math.min(...corners.map((c) => c.dot(axis))), Math.max(...corners.map((c) => c.dot(axis)))];
  const [u0, u1] = range(u);
  const [v0, v1] = range(v);
  const [n0] = range(n);
  const step = niceBelow(Math.max(u1 - u0, v1 - v0, 0.02) / 12);
  const from = (a) => Math.floor(a / step) * step - step;
  const to = (a) => Math.ceil(a / step) * step + step;
  const [a0, a1, b0, b1] = [from(u0), to(u1), from(v0), to(v1)];
  const depth = n0 - Math.max(size.length() * 0.005, 0.001);
  const at = (a, b, d = depth) => u.clone().multiplyScalar(a).addScaledVector(v, b).addScaledVector(n, d);
  const lines = [];
  for (let a = a0; a <= a1 + step / 2; a += step) lines.push(at(a, b0), at(a, b1));
  for (let b = b0; b <= b1 + step / 2; b += step) lines.push(at(a0, b), at(a1, b));
  const grid = new THREE.LineSegments(new THREE.BufferGeometry().setFromPoints(lines),
    new THREE.LineBasicMaterial({ color: 0xb8c1d1, transparent: true, opacity: 0.7 }));
  grid.name = "grid";
  // The plate a little behind its grid, so the lines stay on top of it.
  const back = depth - step * 0.02;
  const quad = [at(a0, b0, back), at(a1, b0, back), at(a1, b1, back), at(a0, b1, back)];
  const plateGeometry = new THREE.BufferGeometry().setFromPoints([quad[0], quad[1], quad[2], quad[0], quad[2], quad[3]]);
  const slab = new THREE.Mesh(plateGeometry, new THREE.MeshBasicMaterial({ color: 0xe2e7ef, side: THREE.DoubleSide }));
  slab.name = "plate";
  group.add(slab, grid);
  group.userData.step = step;
  return group;
}

/** The scale bar: a round length and its bar, as long as that length is at the view's centre. */
export class ScaleBar {
  constructor(container) {
    this.element = document.createElement("div");
    this.element.className = "scale-bar";
    this.bar = document.createElement("span");
    this.bar.className = "bar";
    this.text = document.createElement("span");
    this.text.className = "text";
    this.element.append(this.bar, this.text);
    container.appendChild(this.element);
  }

  update(camera, target, height) {
    const span = camera.isOrthographicCamera
      ? (camera.top - camera.bottom) / camera.zoom
      : 2 * camera.position.distanceTo(target) * Math.tan(THREE.MathUtils.degToRad(camera.fov / 2));
    this.element.hidden = !(span > 0) || !height;
    if (this.element.hidden) return;
    const perPixel = span / height;
    const metres = niceBelow(perPixel * 120);
    this.bar.style.width = `${Math.round(metres / perPixel)}px`;
    this.text.textContent = metres >= 1 ? `${metres} m` : `${Number((metres * 1000).toPrecision(3))} mm`;
    this.element.dataset.metres = String(metres);
  }
}
