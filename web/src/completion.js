// Completions for the SPARQL editor: keywords, declared and known prefixes, the ontology's
// classes and properties (by prefixed name or by local name), variables of the query, and the
// component labels of the store inside a string. A term from an undeclared prefix declares it.

import { declaration, declared, prefixes } from "./prefixes.js";

const KEYWORDS = [
  "SELECT", "DISTINCT", "REDUCED", "WHERE", "OPTIONAL", "FILTER", "UNION", "MINUS", "GRAPH", "BIND", "VALUES",
  "ORDER BY", "GROUP BY", "HAVING", "LIMIT", "OFFSET", "ASK", "CONSTRUCT", "DESCRIBE", "PREFIX", "FROM", "NAMED",
  "AS", "NOT EXISTS", "EXISTS", "COUNT", "SUM", "MIN", "MAX", "AVG", "SAMPLE", "GROUP_CONCAT", "STR", "LANG",
  "DATATYPE", "BOUND", "IF", "COALESCE", "REGEX", "CONTAINS", "STRSTARTS", "STRENDS", "LCASE", "UCASE",
  "CONCAT", "STRLEN", "SUBSTR", "REPLACE", "isIRI", "isLiteral", "ASC", "DESC",
];

const terms = { classes: [], properties: [], components: [] };
let byNamespace = new Map();

export function setTerms(data) {
  terms.classes = data.classes || [];
  terms.properties = data.properties || [];
  terms.components = data.components || [];
  byNamespace = new Map();
  for (const [kind, list] of [["class", terms.classes], ["property", terms.properties]]) {
    for (const term of list) {
      const split = Math.max(term.iri.lastIndexOf("#"), term.iri.lastIndexOf("/")) + 1;
      const namespace = term.iri.slice(0, split);
      const local = term.iri.slice(split);
      if (!/^[A-Za-z_][\w-]*$/.test(local)) continue;
      if (!byNamespace.has(namespace)) byNamespace.set(namespace, []);
      byNamespace.get(namespace).push({ ...term, local, kind: term.kind ? `${term.kind} property` : kind });
    }
  }
}

function prefixOf(namespace) {
  for (const [name, iri] of Object.entries(prefixes)) if (iri === namespace) return name;
  return null;
}

/** Insert `text` in place of from..to, declaring `prefix` first when the query lacks it. */
function applyWithPrefix(text, prefix) {
  return (view, completion, from, to) => {
    const change = declaration(view.state.doc.toString(), prefix);
    const changes = [{ from, to, insert: text }];
    let shift = 0;
    if (change) {
      changes.push(change);
      if (change.from <= from) shift = change.insert.length;
    }
    view.dispatch({ changes, selection: { anchor: from + shift + text.length }, userEvent: "input.complete" });
  };
}

function termOption(term, prefix, boost = 0) {
  const label = `${prefix}:${term.local}`;
  return {
    label,
    type: term.kind === "class" ? "class" : "property",
    detail: term.label || term.kind,
    info: term.comment || undefined,
    apply: applyWithPrefix(label, prefix),
    boost,
  };
}

function inString(before) {
  let quote = null;
  let start = -1;
  for (let i = 0; i < before.length; i++) {
    const c = before[i];
    if (quote) {
      if (c === "\\") i++;
      else if (c === quote) quote = null;
    } else if (c === "#") {
      return -1;
    } else if (c === '"' || c === "'") {
      quote = c;
      start = i + 1;
    }
  }
  return quote ? start : -1;
}

export function sparqlCompletion(context) {
  const line = context.state.doc.lineAt(context.pos);
  const before = line.text.slice(0, context.pos - line.from);
  const stringStart = inString(before);
  if (stringStart >= 0) {
    if (!terms.components.length) return null;
    return {
      from: line.from + stringStart,
      options: terms.components.map((label) => ({ label, type: "text", detail: "component" })),
      validFor: /^[^"']*$/,
    };
  }
  const declaring = /PREFIX\s+([\w-]*)$/i.exec(before);
  if (declaring) {
    return {
      from: context.pos - declaring[1].length,
      options: Object.entries(prefixes).map(([name, iri]) => ({
        label: `${name}: <${iri}>`, type: "namespace", detail: "prefix",
      })),
    };
  }
  const variable = /[?$][\w]*$/.exec(before);
  if (variable) {
    const names = new Set([...context.state.doc.toString().matchAll(/[?$]([A-Za-z_]\w*)/g)].map((m) => m[1]));
    return {
      from: context.pos - variable[0].length,
      options: [...names].map((name) => ({ label: `?${name}`, type: "variable" })),
      validFor: /^[?$]\w*$/,
    };
  }
  const prefixed = /([A-Za-z][\w.-]*):([\w-]*)$/.exec(before);
  if (prefixed) {
    const namespace = declared(context.state.doc.toString())[prefixed[1]] || prefixes[prefixed[1]];
    const list = namespace ? byNamespace.get(namespace) : null;
    if (!list) return null;
    return {
      from: context.pos - prefixed[0].length,
      options: list.map((term) => termOption(term, prefixed[1])),
      validFor: /^[A-Za-z][\w.-]*:[\w-]*$/,
    };
  }
  const word = context.matchBefore(/[A-Za-z_][\w-]*/);
  if (!word || (word.from === word.to && !context.explicit)) return null;
  const options = KEYWORDS.map((k) => ({ label: k, type: "keyword", boost: -1 }));
  for (const name of Object.keys(prefixes)) {
    options.push({ label: `${name}:`, type: "namespace", detail: prefixes[name], apply: applyWithPrefix(`${name}:`, name) });
  }
  for (const [namespace, list] of byNamespace) {
    const prefix = prefixOf(namespace);
    if (prefix) for (const term of list) options.push(termOption(term, prefix, prefix === "ck" ? 1 : 0));
  }
  return { from: word.from, options, validFor: /^[\w-]*$/ };
}
