// The three.js objects of a cell scene (the JSON of /api/scene): frames composed into world
// matrices, objects drawn instanced (one InstancedMesh per distinct mesh, so a cabinet's
// thousands of items cost a few hundred draw calls), all wires in one merged line geometry,
// points of interest and harness nodes instanced, frame axes in one line geometry.
// Poses are ROS's (z up, metres); the caller turns the root group to three.js's y up.

import * as THREE from "three";

const BOX = new THREE.BoxGeometry(1, 1, 1).translate(0.5, 0.5, 0.5); // a unit box from its corner
const MARK = new THREE.BoxGeometry(0.01, 0.01, 0.01);
const BALL = new THREE.SphereGeometry(1, 12, 8);
export const COLOURS = {
  item: new THREE.Color("#9aa8bf"),
  highlight: new THREE.Color("#f7c873"),
  screw: new THREE.Color("#dc2626"),
  hole: new THREE.Color("#1d4ed8"),
  picked: new THREE.Color("#e0457b"),
  robot: new THREE.Color("#d97706"),
  human: new THREE.Color("#7c8799"),
  key: new THREE.Color("#2457c5"),
  "key-corner": new THREE.Color("#7c3aed"),
  "tape-spot": new THREE.Color("#facc15"),
  "bench-pin": new THREE.Color("#16a34a"),
  node: new THREE.Color("#2457c5"),
  connector: new THREE.Color("#d97706"),
  segment: new THREE.Color("#475467"),
};

/** World matrices of every frame of the scene (a frame whose parent is unknown hangs from the origin). */
export function worldMatrices(frames) {
  const local = new Map(frames.map((f) => [f.name, f]));
  const world = new Map();
  const compose = (name, depth = 0) => {
    if (world.has(name)) return world.get(name);
    const frame = local.get(name);
    const matrix = new THREE.Matrix4();
    if (frame && depth < 256) {
      const [x, y, z] = frame.t;
      const [qx, qy, qz, qw] = frame.q;
      matrix.compose(new THREE.Vector3(x, y, z), new THREE.Quaternion(qx, qy, qz, qw), new THREE.Vector3(1, 1, 1));
      if (frame.parent !== name) matrix.premultiply(compose(frame.parent, depth + 1));
    }
    world.set(name, matrix);
    return matrix;
  };
  for (const frame of frames) compose(frame.name);
  return (name) => world.get(name) || (local.has(name) ? compose(name) : null);
}

/** A colour per component, close to the item grey, so neighbours can be told apart. */
function tint(index) {
  if (index === null || index === undefined) return COLOURS.item.clone();
  const hue = ((index * 0.618034) % 1 + 1) % 1;
  return new THREE.Color().setHSL(hue, 0.28, 0.62);
}

/**
 * The placed objects: one InstancedMesh per distinct mesh (geometry given later by `setGeometry`),
 * one for boxes, one for unplaced marks; `instanced: false` draws one Mesh per object (the
 * benchmark's baseline). Returns {group, handles, pick(object, instanceId) -> object index}.
 */
export function buildObjects(scene, matrixOf, { instanced = true } = {}) {
  const group = new THREE.Group();
  group.name = "objects";
  const buckets = new Map(); // key -> {geometry, entries: [{index, matrix}]}
  const put = (key, geometry, index, matrix) => {
    if (!buckets.has(key)) buckets.set(key, { geometry, entries: [] });
    buckets.get(key).entries.push({ index, matrix });
  };
  scene.objects.forEach((object, index) => {
    const world = matrixOf(object.frame);
    if (!world) return;
    if (object.mesh !== null && object.mesh !== undefined) {
      put(`mesh:${object.mesh}`, null, index, world);
    } else if (object.box) {
      const [x0, y0, z0, x1, y1, z1] = object.box;
      const inner = new THREE.Matrix4().compose(new THREE.Vector3(x0, y0, z0), new THREE.Quaternion(),
        new THREE.Vector3(Math.max(x1 - x0, 1e-4), Math.max(y1 - y0, 1e-4), Math.max(z1 - z0, 1e-4)));
      put("box", BOX, index, world.clone().multiply(inner));
    } else {
      put("mark", MARK, index, world);
    }
  });
  const material = new THREE.MeshLambertMaterial({ color: 0xffffff });
  const owners = new Map(); // THREE object -> object indices by instance
  const handles = new Map(); // mesh index -> objects to give their geometry
  const colourOf = (index) => tint(scene.objects[index].component);
  for (const [key, bucket] of buckets) {
    const placeholder = bucket.geometry || MARK; // until its mesh file has come
    const meshes = [];
    if (instanced) {
      const mesh = new THREE.InstancedMesh(placeholder, material, bucket.entries.length);
      bucket.entries.forEach(({ index, matrix }, i) => {
        mesh.setMatrixAt(i, matrix);
        mesh.setColorAt(i, colourOf(index));
      });
      mesh.instanceMatrix.needsUpdate = true;
      mesh.computeBoundingSphere();
      mesh.visible = Boolean(bucket.geometry);
      owners.set(mesh, bucket.entries.map((e) => e.index));
      meshes.push(mesh);
    } else {
      for (const { index, matrix } of bucket.entries) {
        const mesh = new THREE.Mesh(placeholder, new THREE.MeshLambertMaterial({ color: colourOf(index) }));
        mesh.matrixAutoUpdate = false;
        mesh.matrix.copy(matrix);
        mesh.visible = Boolean(bucket.geometry);
        owners.set(mesh, [index]);
        meshes.push(mesh);
      }
    }
    for (const mesh of meshes) group.add(mesh);
    if (key.startsWith("mesh:")) handles.set(Number(key.slice(5)), meshes);
  }
  const setGeometry = (meshIndex, geometry) => {
    for (const mesh of handles.get(meshIndex) || []) {
      mesh.geometry = geometry;
      mesh.visible = true;
      if (mesh.isInstancedMesh) {
        mesh.boundingBox = null;
        mesh.computeBoundingSphere();
      }
    }
  };
  let painted = new Set();
  // Colour some objects (index -> THREE.Color); every other object takes its own colour again.
  const paint = (colours) => {
    const touched = new Set([...painted, ...colours.keys()]);
    for (const [mesh, list] of owners) {
      let changed = false;
      list.forEach((index, i) => {
        if (!touched.has(index)) return;
        const c = colours.get(index) || colourOf(index);
        if (mesh.isInstancedMesh) mesh.setColorAt(i, c);
        else mesh.material.color.copy(c);
        changed = true;
      });
      if (changed && mesh.isInstancedMesh) mesh.instanceColor.needsUpdate = true;
    }
    painted = new Set(colours.keys());
  };
  return {
    group,
    setGeometry,
    meshCount: group.children.length,
    pick: (object, instanceId) => (owners.get(object) || [])[object.isInstancedMesh ? instanceId : 0],
    paint,
  };
}

/** Every route as one LineSegments: keypoints in a frame, or the origins of frames in turn. */
export function buildRoutes(routes, matrixOf) {
  const positions = [];
  const colours = [];
  const segmentRoute = [];
  const point = new THREE.Vector3();
  const pathOf = (route) => {
    if (route.via) {
      return route.via.map((name) => matrixOf(name)).filter(Boolean).map((m) => new THREE.Vector3().setFromMatrixPosition(m));
    }
    const matrix = matrixOf(route.frame) || new THREE.Matrix4();
    const out = [];
    for (let i = 0; i + 2 < route.points.length; i += 3) {
      out.push(point.set(route.points[i], route.points[i + 1], route.points[i + 2]).clone().applyMatrix4(matrix));
    }
    return out;
  };
  const paths = routes.map(pathOf);
  paths.forEach((path, r) => {
    const colour = routes[r].performer === "human" ? COLOURS.human : COLOURS.robot;
    for (let i = 0; i + 1 < path.length; i++) {
      positions.push(path[i].x, path[i].y, path[i].z, path[i + 1].x, path[i + 1].y, path[i + 1].z);
      colours.push(colour.r, colour.g, colour.b, colour.r, colour.g, colour.b);
      segmentRoute.push(r);
    }
  });
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.Float32BufferAttribute(positions, 3));
  geometry.setAttribute("color", new THREE.Float32BufferAttribute(colours, 3));
  const lines = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true, transparent: true, opacity: 0.8 }));
  lines.name = "routes";
  return { lines, paths, pick: (index) => segmentRoute[Math.floor(index / 2)] };
}

/** A thick tube along a path, for the wire being looked at. */
export function tube(path, radius, colour) {
  const group = new THREE.Group();
  for (let i = 0; i + 1 < path.length; i++) {
    const curve = new THREE.LineCurve3(path[i], path[i + 1]);
    group.add(new THREE.Mesh(new THREE.TubeGeometry(curve, 1, radius, 8, false),
      new THREE.MeshBasicMaterial({ color: colour })));
  }
  return group;
}

/** Instanced balls at points (world positions), one colour each. */
export function balls(points, radius, name) {
  const mesh = new THREE.InstancedMesh(BALL, new THREE.MeshLambertMaterial({ color: 0xffffff }), Math.max(points.length, 1));
  mesh.count = points.length;
  const matrix = new THREE.Matrix4();
  points.forEach((p, i) => {
    const r = radius * (p.scale || 1);
    matrix.compose(p.position, new THREE.Quaternion(), new THREE.Vector3(r, r, r));
    mesh.setMatrixAt(i, matrix);
    mesh.setColorAt(i, p.colour);
  });
  mesh.instanceMatrix.needsUpdate = true;
  if (mesh.instanceColor) mesh.instanceColor.needsUpdate = true;
  mesh.computeBoundingSphere();
  mesh.name = name;
  return mesh;
}

/** Red, green and blue axes of many frames in one LineSegments. */
export function axes(matrices, length) {
  const positions = [];
  const colours = [];
  const origin = new THREE.Vector3();
  const tip = new THREE.Vector3();
  const rgb = [[1, 0.2, 0.2], [0.1, 0.7, 0.2], [0.2, 0.4, 1]];
  for (const matrix of matrices) {
    origin.setFromMatrixPosition(matrix);
    for (let axis = 0; axis < 3; axis++) {
      tip.set(axis === 0 ? length : 0, axis === 1 ? length : 0, axis === 2 ? length : 0).applyMatrix4(matrix);
      positions.push(origin.x, origin.y, origin.z, tip.x, tip.y, tip.z);
      colours.push(...rgb[axis], ...rgb[axis]);
    }
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.Float32BufferAttribute(positions, 3));
  geometry.setAttribute("color", new THREE.Float32BufferAttribute(colours, 3));
  return new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ vertexColors: true }));
}

/** A harness topology: nodes as balls, segments as lines; returns what picking needs. */
export function buildHarness(harness, matrixOf, size) {
  const matrix = (harness.frame && matrixOf(harness.frame)) || new THREE.Matrix4();
  const positions = harness.nodes.map((n) => new THREE.Vector3(...n.position).applyMatrix4(matrix));
  const group = new THREE.Group();
  group.name = `harness ${harness.label}`;
  const nodes = balls(positions.map((position, i) => ({
    position, colour: harness.nodes[i].kind === "connector" ? COLOURS.connector : COLOURS.node,
  })), size, "harness-nodes");
  group.add(nodes);
  const linePositions = [];
  for (const s of harness.segments) {
    const a = positions[s.from];
    const b = positions[s.to];
    linePositions.push(a.x, a.y, a.z, b.x, b.y, b.z);
  }
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute("position", new THREE.Float32BufferAttribute(linePositions, 3));
  const lines = new THREE.LineSegments(geometry, new THREE.LineBasicMaterial({ color: COLOURS.segment }));
  lines.name = "harness-segments";
  group.add(lines);
  return { group, nodes, lines, positions };
}
