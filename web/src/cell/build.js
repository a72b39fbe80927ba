// The three.js objects of a cell scene (the JSON of /api/scene) besides its placed objects
// (cell/objects.js): frames composed into world matrices, all wires in one line geometry,
// points of interest and harness nodes instanced, frame axes in one line geometry.
// Poses are ROS's (z up, metres); the caller turns the root group to three.js's y up.

import * as THREE from "three";

const BALL = new THREE.SphereGeometry(1, 12, 8);
export const COLOURS = {
  highlight: new THREE.Color("#f7c873"),
  hover: new THREE.Color("#cfe0ff"),
  screw: new THREE.Color("#dc2626"),
  hole: new THREE.Color("#1d4ed8"),
  picked: new THREE.Color("#e0457b"),
  measure: new THREE.Color("#0f766e"),
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

// Wire colours by their codes: IEC 60757 (BK, BU, GNYE ...), as connection lists write them,
// and the German ones of KBL and VEC files (sw, bl, gnge ...). A white wire is drawn light grey
// on the light background.
const WIRE = {
  BK: "#1f1f1f", BN: "#8b4513", RD: "#d62828", OG: "#f77f00", YE: "#f2c500", GN: "#2a9d3a",
  BU: "#1f5fd6", VT: "#7b2cbf", GY: "#8a8f98", WH: "#d4d4d4", PK: "#f48fb1", TQ: "#1abc9c",
  GD: "#c9a227", SR: "#b0b7c3", GNYE: "#9acd32",
  SW: "#1f1f1f", BR: "#8b4513", RT: "#d62828", OR: "#f77f00", GE: "#f2c500", BL: "#1f5fd6",
  VI: "#7b2cbf", GR: "#8a8f98", WS: "#d4d4d4", RS: "#f48fb1", GNGE: "#9acd32",
};

/** The colour of a wire's code (its first colour when striped, "ws/rt"), or null when unknown. */
export function wireColour(code) {
  if (!code) return null;
  const text = String(code).toUpperCase().replace(/[^A-Z/-]/g, "");
  const found = WIRE[text] || WIRE[text.split(/[/-]/)[0]];
  return found ? new THREE.Color(found) : null;
}

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
    // A human's wire grey (the robot does not lay it); the robot's in their own colours.
    const colour = routes[r].performer === "human" ? COLOURS.human : wireColour(routes[r].colour) || COLOURS.robot;
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
