// Prefixes: the standard ones and the cell's own (cell:), from /api/terms; shortening IRIs for
// display and declaring a prefix in a query when a completion uses it.

export const prefixes = {
  ck: "https://w3id.org/cadkg#",
  rdf: "http://www.w3.org/1999/02/22-rdf-syntax-ns#",
  rdfs: "http://www.w3.org/2000/01/rdf-schema#",
  owl: "http://www.w3.org/2002/07/owl#",
  xsd: "http://www.w3.org/2001/XMLSchema#",
};
let ordered = null; // namespaces, longest first, so cell:item/ loses to a longer match

export function setPrefixes(more) {
  Object.assign(prefixes, more);
  ordered = null;
}

export function shorten(iri) {
  if (!ordered) ordered = Object.entries(prefixes).sort((a, b) => b[1].length - a[1].length);
  for (const [prefix, namespace] of ordered) {
    if (iri.startsWith(namespace) && iri.length > namespace.length) return `${prefix}:${iri.slice(namespace.length)}`;
  }
  return iri;
}

const DECLARATION = /^\s*PREFIX\s+([A-Za-z][\w.-]*)?:\s*<([^>]*)>/gim;

/** The prefixes a query declares, by name. */
export function declared(text) {
  const found = {};
  for (const match of text.matchAll(DECLARATION)) found[match[1] || ""] = match[2];
  return found;
}

/** The PREFIX lines of the given names, one a line. */
export function prologue(names) {
  return names.filter((n) => prefixes[n]).map((n) => `PREFIX ${n}: <${prefixes[n]}>`).join("\n");
}

/** The change that declares `name` in `text` (after its last PREFIX line), or null when it is declared. */
export function declaration(text, name) {
  if (name in declared(text) || !prefixes[name]) return null;
  let at = 0;
  for (const match of text.matchAll(DECLARATION)) at = match.index + match[0].length + 1;
  const line = `PREFIX ${name}: <${prefixes[name]}>\n`;
  return { from: Math.min(at, text.length), insert: at > text.length ? `\n${line}` : line };
}
