// The facts of a picked thing as an engineer reads them: one row per fact, however many named
// graphs state it (the graphs listed on demand), the type and label first and the rest by
// property, numbers without float noise, rounded to their unit's precision and followed by the
// unit the ontology gives the property ("..., in metres." in its comment).

import { postQuery } from "./api.js";
import { shorten } from "./prefixes.js";
import { readAnswer } from "./results.js";
import { isTypedNumber, termText } from "./terms.js";

const LIMIT = 200;
// A unit as the ontology's comments name it: its symbol and the decimals worth showing (a
// tenth of a millimetre, a hundredth of a square millimetre, a ten-thousandth of a radian).
const UNITS = [
  [/\bin square millimetres\b/i, "mm²", 2],
  [/\bin metres\b/i, "m", 4],
  [/\bin radians\b/i, "rad", 4],
];
const FIRST = ["rdf:type", "ck:label", "rdfs:label"];
const units = new Map(); // property IRI -> [symbol, decimals]

/** Learn the units of the ontology's properties from their comments (/api/terms). */
export function setUnits(properties) {
  units.clear();
  for (const term of properties || []) {
    const found = UNITS.find(([pattern]) => pattern.test(term.comment || ""));
    if (found) units.set(term.iri, [found[1], found[2]]);
  }
}

/** A number as it is worth reading: 12 significant digits at most (no 0.11299999999999999),
 * and at most `decimals` after the point. */
export function roundNumber(value, decimals = null) {
  let n = Number(value.toPrecision(12));
  if (decimals !== null) n = Number(n.toFixed(decimals));
  return String(Object.is(n, -0) ? 0 : n);
}

/** The text of a fact's value: a number rounded with its unit, anything else as the table shows it. */
export function valueText(property, term) {
  if (!isTypedNumber(term)) return termText(term);
  const [symbol, decimals] = units.get(property) || ["", null];
  // An integer as written: an id of many digits must keep every one.
  const text = /^[+-]?\d+$/.test(term.value.trim()) ? term.value.trim() : roundNumber(Number(term.value), decimals);
  return symbol ? `${text} ${symbol}` : text;
}

function rank(property) {
  const index = FIRST.indexOf(shorten(property));
  return index < 0 ? FIRST.length : index;
}

/** The facts about `iri`: [{p, o, graphs}], each fact once, sorted. */
export async function factsOf(iri) {
  const answer = await readAnswer(await postQuery(
    `SELECT ?p ?o (GROUP_CONCAT(DISTINCT STR(?g); separator=" ") AS ?graphs) WHERE {
       <${iri}> ?p ?o . OPTIONAL { GRAPH ?g { <${iri}> ?p ?o } }
     } GROUP BY ?p ?o LIMIT ${LIMIT}`,
  ));
  const collator = new Intl.Collator(undefined, { numeric: true });
  const facts = answer.rows.map(([p, o, graphs]) => ({
    p, o, graphs: graphs && graphs.value ? graphs.value.split(" ").sort() : [],
  }));
  facts.sort((a, b) => rank(a.p.value) - rank(b.p.value)
    || collator.compare(shorten(a.p.value), shorten(b.p.value))
    || collator.compare(termText(a.o), termText(b.o)));
  return facts;
}
