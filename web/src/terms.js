// RDF terms of an answer: SPARQL JSON results and N-Triples, read into one shape
// ({type: "uri" | "literal" | "bnode" | "triple", value, datatype, "xml:lang"}).

import { shorten } from "./prefixes.js";

const XSD = "http://www.w3.org/2001/XMLSchema#";
const NUMERIC = new Set(["integer", "decimal", "double", "float", "int", "long", "short", "byte",
  "nonNegativeInteger", "positiveInteger", "negativeInteger", "nonPositiveInteger", "unsignedInt",
  "unsignedLong", "unsignedShort", "unsignedByte"].map((t) => XSD + t));

/** A number by its datatype: a string that only looks like one (a wire number "1500.51", a
 * harness id "000971619") is not. */
export function isTypedNumber(term) {
  return Boolean(term && term.type === "literal" && NUMERIC.has(term.datatype) && !Number.isNaN(Number(term.value)));
}

export function termText(term) {
  if (!term) return "";
  if (term.type === "uri") return shorten(term.value);
  if (term.type === "bnode") return `_:${term.value}`;
  if (term.type === "triple") {
    const t = term.value;
    return `<< ${termText(t.subject)} ${termText(t.predicate)} ${termText(t.object)} >>`;
  }
  return term.value;
}

/** The full text of a term, as a tooltip shows it. */
export function termTitle(term) {
  if (!term) return "";
  if (term.type === "literal") {
    if (term["xml:lang"]) return `"${term.value}"@${term["xml:lang"]}`;
    if (term.datatype) return `"${term.value}"^^${shorten(term.datatype)}`;
  }
  return term.type === "uri" ? term.value : termText(term);
}

const UNESCAPE = { t: "\t", b: "\b", n: "\n", r: "\r", f: "\f", '"': '"', "'": "'", "\\": "\\" };

function unescape(text) {
  return text.replace(/\\(u[0-9A-Fa-f]{4}|U[0-9A-Fa-f]{8}|.)/g, (_, code) =>
    code.length > 1 ? String.fromCodePoint(parseInt(code.slice(1), 16)) : UNESCAPE[code] ?? code);
}

const TERM = /\s*(?:<([^>]*)>|_:(\S+)|"((?:[^"\\]|\\.)*)"(?:@([A-Za-z0-9-]+)|\^\^<([^>]*)>)?|(<<))/y;

function readTerm(line, state) {
  TERM.lastIndex = state.at;
  const m = TERM.exec(line);
  if (!m) throw new Error(`cannot read N-Triples at: ${line.slice(state.at, state.at + 40)}`);
  state.at = TERM.lastIndex;
  if (m[1] !== undefined) return { type: "uri", value: m[1] };
  if (m[2] !== undefined) return { type: "bnode", value: m[2] };
  if (m[6]) {
    const subject = readTerm(line, state);
    const predicate = readTerm(line, state);
    const object = readTerm(line, state);
    state.at = line.indexOf(">>", state.at) + 2;
    return { type: "triple", value: { subject, predicate, object } };
  }
  const term = { type: "literal", value: unescape(m[3]) };
  if (m[4]) term["xml:lang"] = m[4];
  if (m[5]) term.datatype = m[5];
  return term;
}

/** N-Triples text as rows of [subject, predicate, object] terms. */
export function readNTriples(text) {
  const rows = [];
  for (const line of text.split("\n")) {
    const trimmed = line.trim();
    if (!trimmed || trimmed.startsWith("#")) continue;
    const state = { at: 0 };
    rows.push([readTerm(trimmed, state), readTerm(trimmed, state), readTerm(trimmed, state)]);
  }
  return rows;
}
