// Everything the 3D view draws, by label and by IRI, for search, zoom and pick: components, the
// placed items of no component (platform elements, jigs, tables), points of interest (guides'
// keys and corners, taping spots, bench pins, tool slots), harness nodes (by their label and by
// each connector at them) and wires. Each thing says how to highlight it and where it is: its
// objects (indices into the scene's objects), a point, or a path.

// When two things share a label, the first kind here keeps it (a component over its items).
const ORDER = ["component", "item", "point", "harness node", "wire"];

export class Things {
  constructor() {
    this.byName = new Map();
    this.list = [];
  }

  add(thing) {
    this.list.push(thing);
    for (const name of [thing.label, thing.iri, ...(thing.aliases || [])]) {
      if (!name) continue;
      const known = this.byName.get(name);
      if (!known || ORDER.indexOf(thing.group) < ORDER.indexOf(known.group)) this.byName.set(name, thing);
    }
  }

  /** The thing a label or IRI names (exactly, else without regard to case), or null. */
  find(name) {
    const key = String(name || "").trim();
    if (this.byName.has(key)) return this.byName.get(key);
    const lower = key.toLowerCase();
    for (const [known, thing] of this.byName) if (known.toLowerCase() === lower) return thing;
    return null;
  }

  /** The thing made of a scene's route or harness node (`part`). */
  of(part) {
    return this.list.find((thing) => thing.route === part || thing.node === part) || null;
  }

  /** The labels to offer in a search field: each thing's label and aliases, sorted, once. */
  labels() {
    const names = new Set();
    for (const thing of this.list) for (const n of [thing.label, ...(thing.aliases || [])]) if (n) names.add(n);
    return [...names].sort((a, b) => a.localeCompare(b, undefined, { numeric: true }));
  }
}

/** The things of a scene: `points` and `harnesses` as the view placed them (positions in the
 * view's root frame), `paths` the wires' paths. */
export function sceneThings(data, points, harnesses, paths) {
  const things = new Things();
  for (const component of data.components) {
    if (component.objects.length) {
      things.add({ group: "component", kind: "component", label: component.label, iri: component.iri,
        objects: component.objects, component });
    }
  }
  data.objects.forEach((object, index) => {
    if (object.component === null || object.component === undefined) {
      things.add({ group: "item", kind: "item", label: object.label, iri: object.iri, objects: [index] });
    }
  });
  for (const p of points) things.add({ group: "point", kind: p.kind, label: p.label, iri: p.iri, position: p.position });
  data.harnesses.forEach((harness, i) => {
    harness.nodes.forEach((node, j) => {
      const named = node.connectors.length && node.connectors.join() !== node.label;
      const label = named ? `${node.label} (${node.connectors.join(", ")})` : node.label;
      things.add({ group: "harness node", kind: "harness node", label, iri: node.iri,
        aliases: [node.label, ...node.connectors], position: harnesses[i].positions[j], node });
    });
  });
  data.routes.forEach((route, i) => {
    things.add({ group: "wire", kind: "wire", label: `wire ${route.label}`, iri: route.iri,
      aliases: [route.label], route, path: paths[i] });
  });
  return things;
}
