// The 3D view of the cell: what /api/scene gives, drawn with three.js; meshes streamed as
// binary STL from /api/mesh. Click an object for its label and facts (a DESCRIBE); pick a
// component for its pins with their screw and hole poses (cad_service); step through the
// the robot's wires in the order group_connection_provider gives them. It renders only when something changed.

import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { STLLoader } from "three/examples/jsm/loaders/STLLoader.js";
import { EndpointError, getJson } from "../api.js";
import { shorten } from "../prefixes.js";
import { factsOf, valueText } from "../facts.js";
import { isTypedNumber, termTitle } from "../terms.js";
import { COLOURS, axes, balls, buildHarness, buildRoutes, tube, worldMatrices } from "./build.js";
import { Labels } from "./labels.js";
import { Occlusion } from "./occlusion.js";
import { ScaleBar, buildGround } from "./ground.js";
import { tagsOf } from "./tags.js";
import { Hover } from "./hover.js";
import { ModelTree } from "./tree.js";
import { Marks } from "./marks.js";
import { PlanSteps } from "./plan.js";
import { ChangeFeed } from "./changes.js";
import { Objects } from "./objects.js";
import { Measure } from "./measure.js";
import { sceneThings } from "./things.js";

const $ = (id) => document.getElementById(id);
const CLIENT = "web-3d";
const MESH_REQUESTS = 6;
const MOVING_MS = 40;
// Where a harness's node positions come from (the scene's `coordinates`).
const COORDINATES = {
  graph: "their poses in the cell",
  file: "the coordinates of their harness file",
  layout: "a layout (the graph has no coordinates)",
};

/** Whether WebGL is drawn on the CPU here (SwiftShader, llvmpipe). */
function softwareRenderer() {
  const gl = document.createElement("canvas").getContext("webgl2");
  const info = gl && gl.getExtension("WEBGL_debug_renderer_info");
  const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : "";
  if (gl) gl.getExtension("WEBGL_lose_context")?.loseContext();
  return /swiftshader|llvmpipe|software/i.test(name);
}

// The view presets, in the axes of the frame most objects hang from (a cabinet's plate: x to
// the right, y up, z out of it): face on, from above, from the right, and from a corner.
const PRESETS = {
  front: (b) => ({ eye: b.z.clone(), up: b.y.clone() }),
  top: (b) => ({ eye: b.y.clone(), up: b.z.clone().negate() }),
  side: (b) => ({ eye: b.x.clone(), up: b.y.clone() }),
  iso: (b) => ({ eye: b.x.clone().add(b.y).add(b.z).normalize(), up: b.y.clone() }),
};

function vector(p) {
  return new THREE.Vector3(p.position.x, p.position.y, p.position.z);
}

export class CellView {
  constructor(container, { onIri, drawing = "merged" }) {
    this.container = container;
    this.onIri = onIri;
    this.drawing = drawing;
    this.pickables = [];
    this.extras = new THREE.Group();
    this.frameNeeded = false;
    container.cellView = this; // for the browser tests and the benchmark
    try {
      this.renderer = new THREE.WebGLRenderer({ antialias: false, preserveDrawingBuffer: true });
    } catch (err) {
      throw new EndpointError(`this browser cannot draw 3D (WebGL): ${err.message}`);
    }
    this.renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
    container.appendChild(this.renderer.domElement);
    this.labels = new Labels(container);
    this.occlusion = new Occlusion(this.renderer);
    this.scaleBar = new ScaleBar(container);
    this.camera = new THREE.PerspectiveCamera(40, 1, 0.001, 1000);
    this.scene = new THREE.Scene();
    this.scene.background = new THREE.Color("#eef1f6");
    this.scene.add(new THREE.HemisphereLight(0xffffff, 0x8d99ae, 1.6));
    const sun = new THREE.DirectionalLight(0xffffff, 1.4);
    sun.position.set(1, 2, 3);
    this.scene.add(sun);
    // ROS frames are z up; three.js's are y up.
    this.root = new THREE.Group();
    this.root.rotation.x = -Math.PI / 2;
    this.scene.add(this.root);
    this.root.add(this.extras);
    this.makeControls();
    this.installPicking();
    this.hover = new Hover(this);
    this.installControls();
    new ResizeObserver(() => this.resize()).observe(container);
  }

  // -- loading -----------------------------------------------------------------------------

  async load() {
    $("cell-status").textContent = "loading the cell…";
    const started = performance.now();
    const response = await fetch("/api/scene", { headers: { Accept: "application/json" } });
    if (!response.ok) throw new EndpointError(`the 3D scene: ${response.status} ${await response.text()}`);
    this.generation = response.headers.get("x-cadkg-generation") || "";
    this.data = await response.json();
    const read = performance.now();
    this.build();
    const built = performance.now();
    this.placeGround();
    this.fit();
    this.describeScene();
    let moved = false;
    const onMove = () => { moved = true; };
    this.controls.addEventListener("start", onMove);
    await this.loadMeshes();
    this.controls.removeEventListener("start", onMove);
    if (!moved) this.fit(); // now with the meshes' own sizes
    this.placeGround();
    this.setLabels(); // the tags, at the meshes' own boxes
    this.describeScene();
    // Milliseconds from the start: scene read, objects built, every mesh in (benchmarks/bench_page.py).
    this.timings = { scene: read - started, built: built - started, meshes: performance.now() - started };
    this.container.dataset.ready = "true";
    return this;
  }

  build() {
    const data = this.data;
    this.matrixOf = worldMatrices(data.frames);
    this.objects = new Objects(data, this.matrixOf, this.drawing);
    this.root.add(this.objects.group);
    this.pickables.push(...this.objects.group.children);
    this.routes = buildRoutes(data.routes, this.matrixOf);
    this.root.add(this.routes.lines);
    this.pickables.push(this.routes.lines);
    this.size = this.extent();
    const points = data.points.map((p) => ({ ...p, position: this.pointAt(p) }));
    this.points = points;
    const radius = this.size * 0.006;
    const solid = points.filter((p) => p.kind !== "tape-spot");
    const halos = points.filter((p) => p.kind === "tape-spot");
    this.pointMesh = balls(solid.map((p) => ({ position: p.position, colour: COLOURS[p.kind] || COLOURS.key,
      scale: p.kind === "key-corner" ? 0.7 : 1 })), radius, "points");
    this.pointMesh.userData.points = solid;
    // A taping spot: a see-through halo around its guide's key, so the key shows inside it.
    this.haloMesh = balls(halos.map((p) => ({ position: p.position, colour: COLOURS[p.kind] })), radius * 2.2, "halos");
    Object.assign(this.haloMesh.material, { transparent: true, opacity: 0.45, depthWrite: false });
    this.haloMesh.userData.points = halos;
    this.haloMesh.userData.halo = radius * 2.2;
    this.root.add(this.pointMesh, this.haloMesh);
    this.pickables.push(this.pointMesh, this.haloMesh);
    this.harnesses = data.harnesses.map((h) => buildHarness(h, this.matrixOf, Math.max(this.size, 0.2) * 0.008));
    for (const h of this.harnesses) {
      this.root.add(h.group);
      this.pickables.push(h.nodes, h.lines);
    }
    this.axes = axes(data.frames.map((f) => this.matrixOf(f.name)), this.size * 0.02);
    this.axes.visible = $("layer-axes").checked;
    this.root.add(this.axes);
    this.things = sceneThings(data, this.points, this.harnesses, this.routes.paths);
    this.tree = new ModelTree(this, $("cell-tree"));
    this.markers = new Marks(this);
    this.plan = new PlanSteps(this);
    this.changes = new ChangeFeed(this);
    this.ruler = new Measure(this);
    this.root.add(this.ruler.group);
    const names = this.things.labels();
    $("cell-labels").replaceChildren(...names.map((name) => new Option(name)));
    $("cell-component").placeholder = names.length ? `e.g. ${names[0]}` : "nothing drawn";
    this.setLabels();
  }

  /** Where a point of interest is: at its frame's origin, or at its position in that frame. */
  pointAt(p) {
    const matrix = this.matrixOf(p.frame) || new THREE.Matrix4();
    return p.position ? new THREE.Vector3(...p.position).applyMatrix4(matrix) : new THREE.Vector3().setFromMatrixPosition(matrix);
  }

  /** The size of the cell: the diagonal of everything placed (frames, harness nodes). */
  extent() {
    // What is drawn: objects, points, wires, harness nodes; the frames only when there is
    // nothing else (a frame may be far off, as ELIMCO's drawing origin is metres away).
    const box = new THREE.Box3();
    const at = (name) => new THREE.Vector3().setFromMatrixPosition(this.matrixOf(name) || new THREE.Matrix4());
    for (const o of this.data.objects) box.expandByPoint(at(o.frame));
    for (const p of this.data.points) box.expandByPoint(this.pointAt(p));
    for (const h of this.data.harnesses) for (const n of h.nodes) box.expandByPoint(new THREE.Vector3(...n.position));
    for (const r of this.routes.paths) for (const p of r) box.expandByPoint(p);
    if (box.isEmpty()) for (const f of this.data.frames) box.expandByPoint(at(f.name));
    return box.isEmpty() ? 1 : Math.max(box.getSize(new THREE.Vector3()).length(), 0.05);
  }

  async loadMeshes() {
    const loader = new STLLoader();
    const queue = this.data.meshes.map((mesh, index) => ({ mesh, index }));
    let failed = 0;
    const worker = async () => {
      while (queue.length) {
        const { mesh, index } = queue.shift();
        const path = mesh.path.split("/").map(encodeURIComponent).join("/");
        try {
          const response = await fetch(`/api/mesh/${path}?g=${encodeURIComponent(this.generation)}`);
          if (!response.ok) throw new Error(String(response.status));
          const geometry = loader.parse(await response.arrayBuffer());
          geometry.computeVertexNormals();
          this.objects.setGeometry(index, geometry);
        } catch (err) {
          failed += 1;
        }
        done += 1;
        // A frame of a large cell can take longer than a mesh: the view is drawn again once,
        // when every mesh is in, not after each.
        if (done % 25 === 0) $("cell-status").textContent = `loading meshes: ${done} of ${total}…`;
      }
    };
    const total = queue.length;
    let done = 0;
    await Promise.all(Array.from({ length: MESH_REQUESTS }, worker));
    this.meshFailures = failed;
    this.pickables = this.pickables.filter((o) => o.parent !== this.objects.group);
    this.objects.finish();
    this.pickables.push(...this.objects.group.children);
    this.requestRender();
  }

  describeScene() {
    const d = this.data;
    const parts = [`${d.profile} cell`, `${d.objects.length.toLocaleString()} objects`
      + ` (${d.meshes.length.toLocaleString()} distinct meshes)`];
    if (d.routes.length) parts.push(`${d.routes.length.toLocaleString()} wires`);
    if (d.points.length) parts.push(`${d.points.length} points of interest`);
    for (const h of d.harnesses) {
      parts.push(`harness ${h.label}: ${h.nodes.length} nodes at ${COORDINATES[h.coordinates] || COORDINATES.layout}`);
    }
    parts.push(`${d.frames.length.toLocaleString()} frames`);
    const problems = [...d.problems];
    if (this.meshFailures) problems.push(`${this.meshFailures} mesh(es) could not be loaded`);
    $("cell-status").textContent = parts.join(" · ") + (problems.length ? ` — ${problems.join("; ")}` : "");
    const empty = !d.objects.length && !d.routes.length && !d.points.length && !d.harnesses.length;
    if (empty) {
      $("cell-status").textContent = `${d.profile || "this"} cell: nothing to draw`
        + (problems.length ? ` — ${problems.join("; ")}` : "");
    }
    this.showEmpty(empty ? `Nothing to draw: the ${d.profile || ""} cell's graph places no objects, wires, `
      + "points or harnesses in 3D. Its facts are in the graph: query them, or open them in the graph view." : null);
  }

  /** A message over the view in place of a blank canvas (null: none). */
  showEmpty(message) {
    let note = this.container.querySelector(".cell-empty");
    if (!message) {
      if (note) note.remove();
      return;
    }
    if (!note) {
      note = document.createElement("div");
      note.className = "cell-empty";
      this.container.appendChild(note);
    }
    note.textContent = message;
  }

  // -- drawing -----------------------------------------------------------------------------

  /**
   * Orbit controls. While the camera moves in a cell whose frames take long (over MOVING_MS),
   * the wires are left out of the frames (a level of detail in time), and drawn again when it
   * stops.
   */
  makeControls() {
    this.controls = new OrbitControls(this.camera, this.renderer.domElement);
    this.controls.addEventListener("change", () => this.requestRender());
    this.controls.addEventListener("start", () => {
      if (this.routes && this.lastFrame > MOVING_MS && this.routes.lines.visible) {
        this.routes.lines.visible = false;
        this.lightened = true;
      }
    });
    this.controls.addEventListener("end", () => {
      if (this.lightened) {
        this.routes.lines.visible = $("layer-routes").checked;
        this.lightened = false;
        this.requestRender();
      }
    });
  }

  resize() {
    const width = this.container.clientWidth;
    const height = this.container.clientHeight;
    if (!width || !height) return;
    this.renderer.setSize(width, height);
    this.camera.aspect = width / height;
    if (this.camera.isOrthographicCamera) this.frustum();
    this.camera.updateProjectionMatrix();
    this.requestRender();
  }

  /** The orthographic camera's box: `half` high each way, as wide as the view is. */
  frustum() {
    const half = this.half || 1;
    const aspect = this.camera.aspect || 1;
    Object.assign(this.camera, { left: -half * aspect, right: half * aspect, top: half, bottom: -half, zoom: 1 });
    this.camera.updateProjectionMatrix();
  }

  /** Look from a preset direction (front, top, side, iso; null: the first view) at everything. */
  view(preset) {
    this.preset = PRESETS[preset] ? preset : null;
    this.container.dataset.preset = this.preset || "";
    this.fit();
  }

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
  }

  /** The view as a PNG file of the user's (the drawing; the HTML labels are not in it). */
  screenshot() {
    this.render();
    const link = document.createElement("a");
    link.href = this.renderer.domElement.toDataURL("image/png");
    link.download = `cell-${this.data.profile || "view"}.png`;
    document.body.appendChild(link);
    link.click();
    link.remove();
  }

  requestRender() {
    if (this.frameNeeded) return;
    this.frameNeeded = true;
    requestAnimationFrame(() => {
      this.frameNeeded = false;
      this.render();
    });
  }

  render() {
    const started = performance.now();
    this.renderer.render(this.scene, this.camera);
    this.lastFrame = performance.now() - started;
    this.labels.update(this.camera, this.root, this.container);
    this.scaleBar.update(this.camera, this.controls.target, this.container.clientHeight);
    this.counted();
    // Which labels solid geometry hides: checked once the view rests.
    clearTimeout(this.occluding);
    this.occluding = setTimeout(() => this.occludeLabels(), 120);
  }

  counted() {
    this.frames = (this.frames || 0) + 1;
    this.container.dataset.frames = String(this.frames); // the tests wait for the view to settle
  }

  occludeLabels() {
    if (!this.objects) return;
    const margin = this.size * 0.01;
    this.labels.occlude(this.root, (points, margins) => this.occlusion.hidden(this.scene, this.camera, this.objects.group, points, margin, margins));
    this.labels.update(this.camera, this.root, this.container);
    this.container.dataset.behind = String(this.labels.entries.filter((e) => e.behind).length);
    this.counted();
  }

  /** The grid and plate under the cell (made again when the meshes have come). */
  placeGround() {
    if (this.ground) this.scene.remove(this.ground);
    this.root.updateMatrixWorld(true);
    this.ground = buildGround(this.contentBox(), this.plateBasis());
    this.ground.visible = $("layer-ground").checked;
    this.scene.add(this.ground);
    this.requestRender();
  }

  /** Whether the model tree hides a thing (or what a pick or a label names). */
  isHidden(thing) {
    return Boolean(this.tree && this.tree.hides(thing));
  }

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
  }

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
  }

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
  }

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
  }

  setLabels() {
    const show = $("layer-labels").checked;
    // The picked thing's and the measure's first: they are drawn over everything.
    const entries = [...(this.extraLabels || []), ...(this.ruler ? this.ruler.labels : [])].map((e) => ({ ...e, over: true }));
    if (show) {
      this.harnesses.forEach((h, i) => {
        // The harness's name over the middle of its top edge.
        if (!h.positions.length || this.data.harnesses[i].nodes.every((node) => this.isHidden({ node }))) return;
        const box = new THREE.Box3().setFromPoints(h.positions);
        const position = new THREE.Vector3((box.min.x + box.max.x) / 2, box.max.y + this.size * 0.05, box.max.z);
        entries.push({ text: `harness ${this.data.harnesses[i].label}`, position, className: "title" });
      });
      for (const h of this.harnesses) {
        h.positions.forEach((position, i) => {
          const node = this.data.harnesses[this.harnesses.indexOf(h)].nodes[i];
          if (node.kind === "connector" && !this.isHidden({ node })) entries.push({ text: node.connectors.join(", ") || node.label, position });
        });
      }
      for (const p of this.points) if ((p.kind === "key" || p.kind === "bench-pin") && !this.isHidden(p)) entries.push({ text: p.label, position: p.position });
      if ($("layer-tags").checked && this.things) entries.push(...tagsOf(this));
    }
    this.labels.set(entries.slice(0, 400));
    this.requestRender();
  }

  // -- picking and what it shows -----------------------------------------------------------

  /** What is under a point of the screen: every hit (of things not hidden), and the one a click means. */
  hitAt(clientX, clientY) {
    const rect = this.renderer.domElement.getBoundingClientRect();
    const ndc = new THREE.Vector2(((clientX - rect.left) / rect.width) * 2 - 1, -((clientY - rect.top) / rect.height) * 2 + 1);
    const raycaster = new THREE.Raycaster();
    raycaster.setFromCamera(ndc, this.camera);
    raycaster.params.Line.threshold = this.camera.position.distanceTo(this.controls.target) * 0.006;
    const visible = this.pickables.filter((o) => o.visible && (!o.parent || o.parent.visible));
    const hits = raycaster.intersectObjects(visible, false).filter((h) => !this.tree || !this.tree.hides(this.whatIs(h)));
    // A pin sits inside its component's box: a ray through both means the pin. A ray
    // through a halo's middle means the key inside it.
    let hit = hits.find((h) => h.object.userData.pinList) || hits[0];
    if (hit && hit.object.userData.halo && hits[1] && hits[1].distance - hit.distance < 2 * hit.object.userData.halo) {
      hit = hits[1];
    }
    return { hits, hit };
  }

  installPicking() {
    const canvas = this.renderer.domElement;
    let down = null;
    canvas.addEventListener("pointerdown", (e) => { down = { x: e.clientX, y: e.clientY }; });
    canvas.addEventListener("pointerup", (e) => {
      if (!down || Math.hypot(e.clientX - down.x, e.clientY - down.y) > 4) return;
      const { hits, hit } = this.hitAt(e.clientX, e.clientY);
      if ($("cell-measure").checked) {
        // A pose the graph gives (a pin, a key, a node) before a wire or a surface in front of it.
        const exact = hits.find((h) => this.whatIs(h)?.position) || hits[0];
        this.ruler.add(exact ? this.measured(exact) : null);
        return;
      }
      this.select(hit ? this.whatIs(hit) : null);
    });
  }

  /** Where a pick for a measure is: a point or a node at its pose, else where the ray met. */
  measured(hit) {
    const what = this.whatIs(hit);
    if (what && what.position) return { position: what.position.clone(), label: what.label };
    return { position: this.root.worldToLocal(hit.point.clone()), label: what ? what.label : "a point" };
  }

  /** What a ray hit: {label, iri, kind, component?}. */
  whatIs(hit) {
    const object = hit.object;
    if (object === this.routes.lines) {
      const route = this.data.routes[this.routes.pick(hit.index)];
      return route && this.things.of(route);
    }
    if (object.userData.points) {
      const p = object.userData.points[hit.instanceId];
      return p && { kind: p.kind, label: p.label, iri: p.iri, position: p.position };
    }
    if (object.userData.pinList) {
      const p = object.userData.pinList[hit.instanceId];
      return p && { kind: "pin", label: `${p.pin.label}:${p.pin.pin} (${object.userData.kind})`, iri: p.pin.iri };
    }
    for (const [i, h] of this.harnesses.entries()) {
      const harness = this.data.harnesses[i];
      if (object === h.nodes) {
        const node = harness.nodes[hit.instanceId];
        return node && this.things.of(node);
      }
      if (object === h.lines) {
        const segment = harness.segments[Math.floor(hit.index / 2)];
        return segment && { kind: "segment", label: `segment ${segment.label}`, iri: segment.iri,
          ends: [harness.nodes[segment.from], harness.nodes[segment.to]] };
      }
    }
    const index = this.objects.pick(hit);
    if (index === undefined) return null;
    const item = this.data.objects[index];
    const component = item.component !== null ? this.data.components[item.component] : null;
    return {
      kind: component ? "component" : "item",
      label: component ? component.label : item.label,
      iri: component ? component.iri : item.iri,
      item: item.iri,
      objects: component ? component.objects : [index],
      component,
    };
  }

  async select(what) {
    const panel = $("cell-pick");
    if (!what) {
      this.picked = null;
      panel.hidden = true;
      delete panel.dataset.iri;
      this.highlight(null);
      return;
    }
    panel.hidden = false;
    this.picked = what;
    $("pick-zoom").hidden = !this.whereIs(what);
    $("pick-title").textContent = `${what.label}`;
    $("pick-iri").textContent = what.iri || "";
    panel.dataset.iri = what.iri || "";
    panel.dataset.kind = what.kind;
    this.highlight(what);
    if (what.component) await this.showPins(what.component.label);
    await this.describe(what.iri);
  }

  async describe(iri) {
    const body = $("pick-facts").tBodies[0];
    body.replaceChildren();
    this.facts = [];
    if (!iri || iri.startsWith("_:")) return;
    try {
      this.facts = await factsOf(iri);
      this.showFacts();
    } catch (err) {
      const tr = document.createElement("tr");
      tr.textContent = err.message;
      body.appendChild(tr);
    }
  }

  /** The picked thing's facts, one row each; the named graphs stating it with "graphs" ticked. */
  showFacts() {
    const body = $("pick-facts").tBodies[0];
    const graphs = $("pick-graphs").checked;
    body.replaceChildren();
    for (const { p, o, graphs: stated } of this.facts || []) {
      const tr = document.createElement("tr");
      const name = document.createElement("td");
      name.textContent = shorten(p.value);
      const value = document.createElement("td");
      value.textContent = valueText(p.value, o);
      value.title = termTitle(o);
      if (o.type === "uri") {
        value.className = "iri";
        value.addEventListener("click", () => this.onIri(o.value));
      } else if (isTypedNumber(o)) {
        value.className = "num";
      }
      tr.append(name, value);
      if (graphs) {
        const where = document.createElement("td");
        where.className = "graphs";
        where.textContent = stated.map(shorten).join(", ");
        tr.appendChild(where);
      }
      body.appendChild(tr);
    }
    $("pick-facts").dataset.count = String((this.facts || []).length);
  }

  /** Show what was picked, all else as it was: its objects coloured, a wire as a tube, a point
   * or a harness node ringed by a ball drawn over everything. */
  highlight(what) {
    this.paintObjects(what);
    this.clearExtras();
    if (what && what.route) this.addRoute(this.routes.paths[this.data.routes.indexOf(what.route)]);
    if (what && what.position) {
      const marker = balls([{ position: what.position, colour: COLOURS.picked }], Math.max(this.size * 0.012, 0.004), "picked");
      Object.assign(marker.material, { depthTest: false, transparent: true, opacity: 0.55 });
      marker.renderOrder = 9;
      this.extras.add(marker);
    }
    this.container.dataset.highlighted = what ? what.iri || what.label : "";
    this.requestRender();
  }

  /** The picked thing's objects in the highlight colour, the hovered one's in a lighter one. */
  paintObjects(picked = this.picked) {
    const colours = new Map(this.marks || []);
    for (const index of (this.hovered && this.hovered.objects) || []) colours.set(index, COLOURS.hover);
    for (const index of (picked && picked.objects) || []) colours.set(index, COLOURS.highlight);
    this.objects.paint(colours);
    this.requestRender();
  }

  clearExtras() {
    this.pickables = this.pickables.filter((o) => !o.userData.pinList);
    this.extras.clear();
    this.extraLabels = [];
    this.setLabels();
  }

  addRoute(path) {
    if (path && path.length > 1) this.extras.add(tube(path, this.size * 0.0015, COLOURS.picked));
  }

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
  }

  /** Show what a search or a result row names (a label or an IRI of anything drawn): highlight
   * it, look at it, show its facts (and a component's pins). */
  async locate(named) {
    const thing = this.things.find(named.label) || this.things.find(named.iri);
    if (!thing) {
      $("cell-status").textContent = `${named.label || named.iri} is not drawn in the 3D view; `
        + "search offers everything that is";
      return;
    }
    this.zoomTo(thing);
    await this.select(thing);
  }

  /** Where a thing is, as a box in the root's frame (null when it is nowhere). */
  whereIs(thing) {
    const box = new THREE.Box3();
    const corner = new THREE.Vector3();
    if (thing.position) box.expandByPoint(thing.position);
    for (const p of thing.path || []) box.expandByPoint(p);
    for (const index of thing.objects || []) {
      const object = this.data.objects[index];
      const m = this.matrixOf(object.frame);
      if (!m) continue;
      const [x0, y0, z0, x1, y1, z1] = object.box || [0, 0, 0, 0, 0, 0];
      for (const x of [x0, x1]) for (const y of [y0, y1]) for (const z of [z0, z1]) box.expandByPoint(corner.set(x, y, z).applyMatrix4(m));
    }
    return box.isEmpty() ? null : box;
  }

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

  installControls() {
    const layer = (id, apply) => $(id).addEventListener("change", () => { apply($(id).checked); this.requestRender(); });
    layer("layer-objects", (on) => { this.objects.group.visible = on; });
    layer("layer-routes", (on) => { this.routes.lines.visible = on; });
    layer("layer-points", (on) => { this.pointMesh.visible = on; this.haloMesh.visible = on; });
    layer("layer-harness", (on) => { for (const h of this.harnesses) h.group.visible = on; });
    layer("layer-axes", (on) => { this.axes.visible = on; });
    layer("layer-ground", (on) => { if (this.ground) this.ground.visible = on; });
    layer("layer-tags", () => this.setLabels());
    layer("layer-labels", () => this.setLabels());
    $("cell-fit").addEventListener("click", () => this.fit());
    $("cell-tree-toggle").addEventListener("click", () => {
      $("cell-tree").hidden = !$("cell-tree").hidden;
      $("cell-tree-toggle").classList.toggle("active", !$("cell-tree").hidden);
    });
    for (const preset of Object.keys(PRESETS)) $(`view-${preset}`).addEventListener("click", () => this.view(preset));
    $("view-ortho").addEventListener("change", () => this.setOrthographic($("view-ortho").checked));
    $("cell-screenshot").addEventListener("click", () => this.screenshot());
    $("cell-measure").addEventListener("change", () => this.ruler.clear());
    $("pick-graphs").addEventListener("change", () => this.showFacts());
    $("pick-zoom").addEventListener("click", () => {
      if (this.picked) this.zoomTo(this.picked);
    });
    $("cell-show").addEventListener("click", () => {
      const label = $("cell-component").value.trim();
      if (label) this.locate({ label });
    });
    $("cell-component").addEventListener("keydown", (e) => { if (e.key === "Enter") $("cell-show").click(); });
    $("cell-next-wire").addEventListener("click", () => this.nextWire().catch((err) => {
      $("cell-status").textContent = err.message;
    }));
  }

  // -- for tests and the benchmark ---------------------------------------------------------

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
  }

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
  }

  /** Milliseconds per frame (median of `frames`) while the camera turns around the cell, with
   * everything drawn, and (`moving`) as while the camera is dragged. */
  measure(frames = 30) {
    const full = this.measureFrames(frames);
    const visible = this.routes.lines.visible;
    this.routes.lines.visible = false;
    const moving = this.measureFrames(frames);
    this.routes.lines.visible = visible;
    return { ...full, moving: moving.median };
  }

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
}
