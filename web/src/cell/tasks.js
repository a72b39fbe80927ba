// What each operation of the plan works on, as the 3D view draws it, asked of the graph: the
// task's operation (ck:doesWork), the jigs and guides of its spots (a taping operation's taping
// spots) and the cables of the connector it involves (a harness's connector: the cables leaving
// its pins; a guide group: its branch's cables). A harness, a guide group or a connector is not
// drawn as a thing of its own, so its task is shown as these things together.

import { postQuery } from "../api.js";

const query = (plan) => `SELECT DISTINCT ?key ?op ?jig ?guide ?tape ?cable WHERE {
  GRAPH <${plan}> { ?task ck:taskKey ?key ; ck:doesWork ?op }
  ?op a ck:Operation .
  BIND(EXISTS { ?op a ck:TapeOperation } AS ?tape)
  { ?op ck:atSpot ?spot . ?spot ck:label ?jig ; ck:guideId ?guide }
  UNION { ?op ck:involves/ck:hasPin ?pin . ?c ck:fromPin ?pin ; ck:label ?cable }
  UNION { ?op ck:involves ?connector . ?b ck:hasConnector ?connector ; ck:containsCable/ck:label ?cable }
}`;

/** The drawn things one row names: a cable's route, or a spot's jig and its guide's key (a
 * taping operation: its taping spot). */
function named(things, row) {
  const value = (name) => (row[name] ? row[name].value : "");
  if (row.cable) return [things.find(value("cable"))];
  const jig = value("jig");
  const spot = `${jig}.${value("guide")}`;
  if (value("tape") === "true") {
    return [things.find(jig), things.list.find((t) => t.kind === "tape-spot" && t.label.startsWith(`${spot}:`))];
  }
  return [things.find(jig), things.find(`${jig} guide ${value("guide")}`)];
}

/** Each planned task's things (by task key) as one thing of kind "operation": its `parts`,
 * their objects together, the operation's IRI. */
export async function taskThings(things, plan) {
  const rows = (await (await postQuery(query(plan))).json()).results.bindings;
  const tasks = new Map();
  for (const row of rows) {
    const key = row.key.value;
    if (!tasks.has(key)) tasks.set(key, { iri: row.op.value, parts: new Set() });
    for (const thing of named(things, row)) if (thing) tasks.get(key).parts.add(thing);
  }
  const out = new Map();
  for (const [key, { iri, parts }] of tasks) {
    if (!parts.size) continue;
    // Listed as the pick panel would read them: the jigs, their guides or spots, the routes.
    const rank = (t) => ["item", "point", "wire"].indexOf(t.group);
    const list = [...parts].sort((a, b) => rank(a) - rank(b) || a.label.localeCompare(b.label, undefined, { numeric: true }));
    const objects = [...new Set(list.flatMap((t) => t.objects || []))];
    out.set(key, { group: "task", kind: "operation", iri, parts: list, objects });
  }
  return out;
}

/** The drawn pieces of a thing: a task's parts, else the thing itself. */
export const pieces = (thing) => thing.parts || [thing];
