// The 3D view of the cell: what /api/scene gives, drawn with three.js; meshes streamed as
// binary STL from /api/mesh. Click an object for its label and facts (a DESCRIBE); pick a
// component for its pins with their screw and hole poses (cad_service); step through
// the robot's wires in the order group_connection_provider gives them. It renders only when something changed.

import * as THREE from "three";
import { OrbitControls } from "three/examples/jsm/controls/OrbitControls.js";
import { EndpointError } from "../api.js";
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
import { pieces } from "./tasks.js";
import { PRESETS, camera } from "./camera.js";
import { loading } from "./loading.js";
import { probes } from "./probes.js";
import { pickFacts } from "./pickfacts.js";
import { cabinet } from "./cabinet.js";

const $ = (id) => document.getElementById(id);
const MOVING_MS = 40;

/** Whether WebGL is drawn on the CPU here (SwiftShader, llvmpipe). */
function softwareRenderer() {
  const gl = document.createElement("canvas").getContext("webgl2");
  const info = gl && gl.getExtension("WEBGL_debug_renderer_info");
  const name = info ? String(gl.getParameter(info.UNMASKED_RENDERER_WEBGL)) : "";
  if (gl) gl.getExtension("WEBGL_lose_context")?.loseContext();
  return /swiftshader|llvmpipe|software/i.test(name);
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
    if (this.plan) this.plan.review.showPick(what);
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

  /** Show what was picked, all else as it was: its objects coloured, a wire as a tube, a point
   * or a harness node ringed by a ball drawn over everything. */
  highlight(what) {
    this.paintObjects(what);
    this.clearExtras();
    for (const part of what ? pieces(what) : []) {
      if (part.route) this.addRoute(this.routes.paths[this.data.routes.indexOf(part.route)]);
      if (part.position) {
        const marker = balls([{ position: part.position, colour: COLOURS.picked }], Math.max(this.size * 0.012, 0.004), "picked");
        Object.assign(marker.material, { depthTest: false, transparent: true, opacity: 0.55 });
        marker.renderOrder = 9;
        this.extras.add(marker);
      }
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
}

Object.assign(CellView.prototype, camera, loading, probes, pickFacts, cabinet);
