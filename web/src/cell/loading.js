// Loading the cell's meshes and saying what the 3D view holds (methods of CellView): the STL
// files six at a time, the objects made again once every mesh is in; the scene's summary, or a
// message over the view where there is nothing to draw.

import { STLLoader } from "three/examples/jsm/loaders/STLLoader.js";

const $ = (id) => document.getElementById(id);
const MESH_REQUESTS = 6;
// Where a harness's node positions come from (the scene's `coordinates`).
const COORDINATES = {
  graph: "their poses in the cell",
  file: "the coordinates of their harness file",
  layout: "a layout (the graph has no coordinates)",
};

export const loading = {
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
  },

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
  },

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
};
