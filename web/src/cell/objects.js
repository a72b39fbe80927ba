// The placed objects of the cell (items, platform elements), three ways:
//
// - "merged" (the page's): every object's mesh, transformed to its frame, copied into a few
//   large geometries of at most CHUNK vertices each. A frame then costs a handful of draw calls
//   whatever the cell's size: on a software renderer (no GPU) the 10k-wire cabinet draws 4.4×
//   faster than instanced (benchmarks/README.md). Until the mesh files have come, an object
//   is drawn as its box, so the cell shows at once;
// - "instanced": one InstancedMesh per distinct mesh file (a cabinet's thousands of items share
//   a few hundred): few draw calls on a GPU, one per distinct mesh on a software renderer;
// - "meshes": one three.js Mesh per object, the plain way (the benchmark's baseline).
//
// Each keeps which object a triangle (or an instance) belongs to, for picking, and can paint
// some objects a colour and give every other its own back.

import * as THREE from "three";

export const DRAWINGS = ["merged", "instanced", "meshes"];
const CHUNK = 400000; // vertices of one merged geometry (14 MB of positions, normals, colours)
const BOX = new THREE.BoxGeometry(1, 1, 1).translate(0.5, 0.5, 0.5).toNonIndexed(); // from its corner
const MARK = new THREE.BoxGeometry(0.01, 0.01, 0.01).toNonIndexed();
export const ITEM_GREY = new THREE.Color("#9aa8bf");

/** A colour per component, close to the item grey, so neighbours can be told apart. */
function tint(index) {
  if (index === null || index === undefined) return ITEM_GREY.clone();
  const hue = ((index * 0.618034) % 1 + 1) % 1;
  return new THREE.Color().setHSL(hue, 0.28, 0.62);
}

function boxMatrix(box) {
  const [x0, y0, z0, x1, y1, z1] = box;
  return new THREE.Matrix4().compose(new THREE.Vector3(x0, y0, z0), new THREE.Quaternion(),
    new THREE.Vector3(Math.max(x1 - x0, 1e-4), Math.max(y1 - y0, 1e-4), Math.max(z1 - z0, 1e-4)));
}

export class Objects {
  constructor(scene, matrixOf, drawing = "merged") {
    this.scene = scene;
    this.drawing = DRAWINGS.includes(drawing) ? drawing : "merged";
    this.group = new THREE.Group();
    this.group.name = "objects";
    this.material = new THREE.MeshLambertMaterial({ color: 0xffffff, vertexColors: this.drawing === "merged" });
    this.geometries = new Map(); // mesh index -> geometry, as they come
    this.colours = scene.objects.map((o) => tint(o.component));
    this.painted = new Map();
    this.hidden = new Set(); // object indices the model tree hides
    this.placed = []; // [object index, world matrix]
    scene.objects.forEach((object, index) => {
      const world = matrixOf(object.frame);
      if (world) this.placed.push([index, world]);
    });
    this.owners = new Map(); // three.js object -> object indices (by instance or by triangle)
    if (this.drawing === "merged") this.merge();
    else this.separate();
  }

  /** What an object is drawn as now: its mesh, else its box, else a small mark. */
  shape(index, world) {
    const object = this.scene.objects[index];
    const geometry = object.mesh !== null && object.mesh !== undefined ? this.geometries.get(object.mesh) : null;
    if (geometry) return [geometry, world];
    if (object.box) return [BOX, world.clone().multiply(boxMatrix(object.box))];
    return [MARK, world];
  }

  merge() {
    for (const mesh of this.group.children) mesh.geometry.dispose();
    this.group.clear();
    this.owners.clear();
    this.ranges = new Map(); // object index -> [mesh, first vertex, vertices]
    let parts = [];
    let vertices = 0;
    const flush = () => {
      if (parts.length) this.group.add(this.chunk(parts, vertices));
      parts = [];
      vertices = 0;
    };
    for (const [index, world] of this.placed) {
      if (this.hidden.has(index)) continue;
      const [geometry, matrix] = this.shape(index, world);
      const count = geometry.attributes.position.count;
      if (vertices + count > CHUNK) flush();
      parts.push({ index, geometry, matrix });
      vertices += count;
    }
    flush();
  }

  chunk(parts, vertices) {
    const positions = new Float32Array(vertices * 3);
    const normals = new Float32Array(vertices * 3);
    const colours = new Float32Array(vertices * 3);
    const triangles = new Int32Array(vertices / 3);
    const point = new THREE.Vector3();
    const turn = new THREE.Matrix3();
    let at = 0;
    const mesh = new THREE.Mesh(new THREE.BufferGeometry(), this.material);
    for (const { index, geometry, matrix } of parts) {
      const source = geometry.attributes.position;
      const normal = geometry.attributes.normal;
      const colour = this.painted.get(index) || this.colours[index];
      turn.getNormalMatrix(matrix);
      this.ranges.set(index, [mesh, at, source.count]);
      for (let i = 0; i < source.count; i++, at++) {
        const k = at * 3;
        point.fromBufferAttribute(source, i).applyMatrix4(matrix);
        positions[k] = point.x;
        positions[k + 1] = point.y;
        positions[k + 2] = point.z;
        point.fromBufferAttribute(normal, i).applyMatrix3(turn).normalize();
        normals[k] = point.x;
        normals[k + 1] = point.y;
        normals[k + 2] = point.z;
        colours[k] = colour.r;
        colours[k + 1] = colour.g;
        colours[k + 2] = colour.b;
      }
      triangles.fill(index, (at - source.count) / 3, at / 3);
    }
    mesh.geometry.setAttribute("position", new THREE.BufferAttribute(positions, 3));
    mesh.geometry.setAttribute("normal", new THREE.BufferAttribute(normals, 3));
    mesh.geometry.setAttribute("color", new THREE.BufferAttribute(colours, 3));
    mesh.geometry.computeBoundingSphere();
    this.owners.set(mesh, triangles);
    return mesh;
  }

  separate() {
    const buckets = new Map();
    for (const [index, world] of this.placed) {
      const object = this.scene.objects[index];
      const key = object.mesh !== null && object.mesh !== undefined ? object.mesh : object.box ? "box" : "mark";
      const matrix = key === "box" ? world.clone().multiply(boxMatrix(object.box)) : world;
      if (!buckets.has(key)) buckets.set(key, []);
      buckets.get(key).push([index, matrix]);
    }
    this.handles = new Map(); // mesh index -> three.js objects waiting for its geometry
    for (const [key, entries] of buckets) {
      const ready = key === "box" ? BOX : key === "mark" ? MARK : null;
      const made = [];
      if (this.drawing === "instanced") {
        const mesh = new THREE.InstancedMesh(ready || MARK, this.material, entries.length);
        entries.forEach(([index, matrix], i) => {
          mesh.setMatrixAt(i, matrix);
          mesh.setColorAt(i, this.colours[index]);
        });
        mesh.computeBoundingSphere();
        this.owners.set(mesh, entries.map(([index]) => index));
        made.push(mesh);
      } else {
        for (const [index, matrix] of entries) {
          const mesh = new THREE.Mesh(ready || MARK, new THREE.MeshLambertMaterial({ color: this.colours[index] }));
          mesh.matrixAutoUpdate = false;
          mesh.matrix.copy(matrix);
          this.owners.set(mesh, [index]);
          made.push(mesh);
        }
      }
      for (const mesh of made) {
        mesh.visible = Boolean(ready);
        this.group.add(mesh);
      }
      if (!ready) this.handles.set(key, made);
    }
  }

  /** A mesh file has come: drawn now (instanced, meshes) or at the next `finish` (merged). */
  setGeometry(meshIndex, geometry) {
    const flat = geometry.index ? geometry.toNonIndexed() : geometry;
    this.geometries.set(meshIndex, flat);
    for (const mesh of (this.handles && this.handles.get(meshIndex)) || []) {
      mesh.geometry = flat;
      mesh.visible = true;
      if (mesh.isInstancedMesh) {
        mesh.boundingBox = null;
        mesh.computeBoundingSphere();
      }
    }
  }

  /** Every mesh file has come (or failed): the merged geometry is made again with them. */
  finish() {
    if (this.drawing === "merged") this.merge();
  }

  /** Hide some objects (a set of indices), showing every other. */
  hide(indices) {
    this.hidden = new Set(indices);
    if (this.drawing === "merged") {
      this.merge();
      return;
    }
    const zero = new THREE.Matrix4().makeScale(0, 0, 0);
    for (const [mesh, list] of this.owners) {
      if (!mesh.isInstancedMesh) {
        mesh.visible = !this.hidden.has(list[0]);
        continue;
      }
      if (!mesh.userData.matrices) {
        mesh.userData.matrices = list.map((_, i) => { const m = new THREE.Matrix4(); mesh.getMatrixAt(i, m); return m; });
      }
      list.forEach((index, i) => mesh.setMatrixAt(i, this.hidden.has(index) ? zero : mesh.userData.matrices[i]));
      mesh.instanceMatrix.needsUpdate = true;
    }
  }

  /** The object a ray hit, or undefined. */
  pick(hit) {
    const owner = this.owners.get(hit.object);
    if (!owner) return undefined;
    if (hit.object.isInstancedMesh) return owner[hit.instanceId];
    return owner instanceof Int32Array ? owner[hit.faceIndex] : owner[0];
  }

  /** Colour some objects (index -> THREE.Color); every other object takes its own colour again. */
  paint(colours) {
    const touched = new Set([...this.painted.keys(), ...colours.keys()]);
    this.painted = new Map(colours);
    const changed = new Set();
    for (const index of touched) {
      const colour = colours.get(index) || this.colours[index];
      if (this.drawing === "merged") {
        const range = this.ranges.get(index);
        if (!range) continue;
        const [mesh, first, count] = range;
        const attribute = mesh.geometry.attributes.color;
        for (let i = first; i < first + count; i++) attribute.setXYZ(i, colour.r, colour.g, colour.b);
        changed.add(attribute);
        continue;
      }
      for (const [mesh, list] of this.owners) {
        list.forEach((owner, i) => {
          if (owner !== index) return;
          if (mesh.isInstancedMesh) {
            mesh.setColorAt(i, colour);
            changed.add(mesh.instanceColor);
          } else {
            mesh.material.color.copy(colour);
          }
        });
      }
    }
    for (const attribute of changed) attribute.needsUpdate = true;
  }
}
