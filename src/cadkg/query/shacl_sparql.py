"""SHACL shapes compiled to SPARQL and run by pyoxigraph on the store itself.

The data graph is the merge of some named graphs of the store (for ``cadkg validate``, every
graph but the derived one). Each node shape with property shapes becomes one query: its focus
nodes, then per property shape a ``LATERAL`` subquery that counts the values of the focus node
and flags each value that fails a value check, so the store visits each focus node and each of
its values once and returns only the focus nodes that break something. Each SPARQL-based
constraint becomes one query too: its focus nodes joined ``LATERAL`` with its ``SELECT``, which
sees the focus node as ``$this`` the way SHACL pre-binds it.

The patterns of the compiled queries name the graph of each triple (``GRAPH ?g``) and leave the
other graphs out by a filter: on pyoxigraph a default graph made of several graphs looks each
pattern up once per graph, five times slower here than one lookup over all graphs. The SPARQL
text of the shapes themselves (targets, constraints) runs on that merged default graph, as the
SHACL specification has it.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from functools import partial
from typing import TYPE_CHECKING, Any

import pyoxigraph as ox

from cadkg.errors import QueryError
from cadkg.query.shacl_shapes import (
    AnyOf,
    ClassOf,
    Datatype,
    Disjoint,
    In,
    NodeKind,
    NodeShape,
    Pattern,
    PropertyShape,
    Range,
    ShapeSet,
    SparqlConstraint,
    Targets,
    ValueCheck,
)

if TYPE_CHECKING:
    from cadkg.store import GraphStore

__all__ = ["ShapeResult", "check_shapes"]

_XSD = "http://www.w3.org/2001/XMLSchema#"
_RDFS = "http://www.w3.org/2000/01/rdf-schema#"
_NUMERIC = {_XSD + name for name in ("integer", "decimal", "double", "float")}
_DATES = {_XSD + "dateTime", _XSD + "date"}


@dataclass(frozen=True)
class ShapeResult:
    """One SHACL validation result: the focus node (an IRI, or ``_:id``), the path, the
    constraint component's local name, the shape, the severity IRI and the message."""

    focus: str
    path: str | None
    component: str
    shape: str
    severity: str
    message: str

    def order(self) -> tuple[str, ...]:
        return (self.focus, self.path or "", self.component, self.shape, self.severity, self.message)


class _Dataset:
    """The named graphs a validation reads, and how a compiled pattern keeps to them."""

    def __init__(self, kg: GraphStore, graphs: Sequence[str]) -> None:
        self.kg = kg
        self.graphs = list(graphs)
        self.excluded = sorted(set(kg.named_graphs()) - set(self.graphs))

    def only(self, var: str) -> str:
        """A filter keeping ``GRAPH ?var`` to the dataset's graphs."""
        if not self.excluded:
            return ""
        return f"FILTER(?{var} NOT IN ({', '.join(f'<{g}>' for g in self.excluded)}))"

    def select_union(self, sparql: str) -> Iterable[Any]:
        return self._solutions(self.kg.execute(sparql))

    def select_merged(self, sparql: str) -> Iterable[Any]:
        """A query on the merge of the graphs as its default graph (the SHACL data graph)."""
        return self._solutions(self.kg.execute(sparql, default_graphs=self.graphs, named_graphs=()))

    @staticmethod
    def _solutions(result: Any) -> Iterable[Any]:
        if not isinstance(result, ox.QuerySolutions):
            raise QueryError("a SHACL query must be a SELECT")
        return result


def _term(node: ox.NamedNode | ox.BlankNode | ox.Literal) -> str:
    return str(node)  # pyoxigraph writes terms as N-Triples, which SPARQL reads


def _values(var: str, terms: Iterable[str]) -> str:
    return f"VALUES ?{var} {{ {' '.join(terms)} }}"


def _name(term: Any) -> str:
    return term.value if isinstance(term, ox.NamedNode) else str(term)


def _text(term: Any) -> str:
    """A term in a message as pySHACL writes it: an IRI or a literal's lexical form, a double
    as Python writes the number."""
    if isinstance(term, ox.Literal) and term.datatype.value in (_XSD + "double", _XSD + "float"):
        try:
            return str(float(term.value))
        except ValueError:
            return term.value
    return term.value if isinstance(term, ox.NamedNode | ox.Literal) else str(term)


class _Compiler:
    def __init__(self, dataset: _Dataset, closure: dict[str, list[str]]) -> None:
        self.dataset = dataset
        self.closure = closure  # each class → itself and its subclasses in the data
        self.fresh = 0

    def var(self, stem: str) -> str:
        self.fresh += 1
        return f"{stem}{self.fresh}"

    def classes(self, cls: str) -> str:
        return " ".join(f"<{c}>" for c in self.closure.get(cls, [cls]))

    def ok(self, check: ValueCheck, value: str) -> str:
        """A SPARQL expression, true when the value ``?value`` of ``?this`` passes ``check``."""
        v = f"?{value}"
        if isinstance(check, Datatype):
            test = f"isLiteral({v}) && DATATYPE({v}) = <{check.datatype}>"
            if check.datatype in _NUMERIC:
                test += f" && isNumeric({v})"
            elif check.datatype in _DATES:
                test += f" && isNumeric(YEAR({v}))"  # an ill-typed date has no year
            elif check.datatype == _XSD + "boolean":
                test += f" && ({v} = true || {v} = false)"
            return f"COALESCE({test}, false)"
        if isinstance(check, ClassOf):
            g, k = self.var("h"), self.var("k")
            return (
                f"EXISTS {{ {_values(k, self.classes(check.cls).split())} "
                f"GRAPH ?{g} {{ {v} a ?{k} }} {self.dataset.only(g)} }}"
            )
        if isinstance(check, NodeKind):
            kinds = {"IRI": f"isIRI({v})", "BlankNode": f"isBlank({v})", "Literal": f"isLiteral({v})"}
            return "(" + " || ".join(kinds[k] for k in kinds if k in check.kind) + ")"
        if isinstance(check, In):
            return "(" + " || ".join([f"sameTerm({v}, {_term(m)})" for m in check.members] or ["false"]) + ")"
        if isinstance(check, Range):
            return f"COALESCE({v} {check.operator} {_term(check.bound)}, false)"
        if isinstance(check, Pattern):
            regex, flags = _term(ox.Literal(check.regex)), _term(ox.Literal(check.flags))
            return f"COALESCE(!isBlank({v}) && REGEX(STR({v}), {regex}, {flags}), false)"
        if isinstance(check, Disjoint):
            g = self.var("h")
            return f"NOT EXISTS {{ GRAPH ?{g} {{ ?this <{check.predicate}> {v} }} {self.dataset.only(g)} }}"
        alternatives = [
            "(" + " && ".join([self.ok(c, value) for c in alternative] or ["true"]) + ")"
            for alternative in check.alternatives
        ]
        return "(" + " || ".join(alternatives or ["false"]) + ")"

    def focus(self, targets: Targets, found: Sequence[str], *, by_graph: bool) -> str:
        """A subquery of the focus nodes of ``targets`` (``found``: those of its SPARQL targets),
        looked up graph by graph or (``by_graph=False``) in the merged default graph."""
        patterns = []  # (what goes before the pattern, the pattern)
        if targets.classes:
            classes = " ".join(c for cls in targets.classes for c in self.classes(cls).split())
            patterns.append((_values("tc", classes.split()), "?this a ?tc"))
        patterns += [("", f"?this <{p}> ?to") for p in targets.subjects_of]
        patterns += [("", f"?ts <{p}> ?this") for p in targets.objects_of]
        if by_graph:
            graphs = self.dataset.graphs
            branches = [
                f"{before} GRAPH <{g}> {{ {pattern} }}" for g in graphs for before, pattern in patterns
            ]
        else:
            branches = [f"{before} {pattern}" for before, pattern in patterns]
        nodes = [_term(n) for n in targets.nodes] + list(found)
        if nodes:
            branches.append(_values("this", nodes))
        return "{ SELECT DISTINCT ?this WHERE { " + " UNION ".join(f"{{ {b} }}" for b in branches) + " } }"

    def properties(self, focus: str, properties: Sequence[PropertyShape]) -> str:
        """One query returning each focus node that breaks a property shape, with per shape
        ``?c<i>`` its number of values and ``?f<i>_<j>`` 1 when a value fails check ``j``."""
        laterals, broken = [], []
        for i, prop in enumerate(properties):
            g, binds, flags = f"g{i}", [], []
            for j, check in enumerate(prop.checks):
                binds.append(f"BIND(IF({self.ok(check, f'v{i}')}, 0, 1) AS ?x{i}_{j})")
                flags.append(f"(MAX(?x{i}_{j}) AS ?f{i}_{j})")
                broken.append(f"COALESCE(?f{i}_{j}, 0) > 0")
            if prop.min_count is not None:
                broken.append(f"?c{i} < {prop.min_count}")
            if prop.max_count is not None:
                broken.append(f"?c{i} > {prop.max_count}")
            laterals.append(
                f"LATERAL {{ SELECT ?this (COUNT(DISTINCT ?v{i}) AS ?c{i}) {' '.join(flags)} WHERE {{ "
                f"OPTIONAL {{ GRAPH ?{g} {{ ?this <{prop.path}> ?v{i} }} {self.dataset.only(g)} "
                f"{' '.join(binds)} }} }} GROUP BY ?this }}"
            )
        return f"SELECT * WHERE {{ {focus}\n" + "\n".join(laterals) + f"\nFILTER({' || '.join(broken)}) }}"


def _generic(component: str, prop: PropertyShape, check: ValueCheck | None) -> str:
    """The message of a result whose shape gives none."""
    if check is None:
        fewer = component.startswith("Min")
        return f"{'fewer' if fewer else 'more'} than {prop.min_count if fewer else prop.max_count} values"
    return _GENERIC[type(check)](check)


# The message of each kind of check, where its shape gives none.
_GENERIC: dict[type, Callable[[Any], str]] = {
    Datatype: lambda check: f"a value is not a well-formed <{check.datatype}> literal",
    ClassOf: lambda check: f"a value is not an instance of <{check.cls}>",
    NodeKind: lambda check: f"a value is not of node kind sh:{check.kind}",
    Range: lambda check: f"a value is not {check.operator} {check.bound.value}",
    Pattern: lambda check: f"a value does not match {check.regex!r}",
    Disjoint: lambda check: f"a value is also a value of <{check.predicate}>",
    In: lambda check: "a value is not one of those allowed",
    AnyOf: lambda check: "a value fits no alternative",
}


def _property_results(row: Any, properties: Sequence[PropertyShape]) -> list[ShapeResult]:
    focus = _name(row["this"])
    results = []
    for i, prop in enumerate(properties):
        count = int(row[f"c{i}"].value)
        broken: list[tuple[str, ValueCheck | None]] = []
        if prop.min_count is not None and count < prop.min_count:
            broken.append(("MinCountConstraintComponent", None))
        if prop.max_count is not None and count > prop.max_count:
            broken.append(("MaxCountConstraintComponent", None))
        for j, failed in enumerate(prop.checks):
            flag = row[f"f{i}_{j}"]
            if flag is not None and flag.value == "1":
                broken.append((failed.component, failed))
        for component, check in broken:
            message = prop.message or _generic(component, prop, check)
            results.append(ShapeResult(focus, prop.path, component, prop.node, prop.severity, message))
    return results


def _sparql_results(
    rows: Iterable[dict[str, Any]],
    constraint: SparqlConstraint,
    shape: str,
    severity: str,
    prop: PropertyShape | None,
) -> list[ShapeResult]:
    """A result per row of a SPARQL constraint; ``{?var}`` in its message is the row's ``?var``."""
    results = []
    for bound in rows:
        if "failure" in bound and bound["failure"].value in ("true", "1"):
            raise QueryError(f"SPARQL constraint {constraint.node} failed on {_name(bound.get('this'))}")
        focus = bound["this"]
        path = bound.get("path")
        # The value of a node shape's result is the focus node unless the row gives one.
        value = bound.get("value", focus if prop is None else None)
        fields = {**bound, "this": focus, **({"value": value} if value is not None else {})}
        message = constraint.message or f"violates the SPARQL constraint {constraint.node}"
        for var, term in fields.items():
            message = message.replace(f"{{?{var}}}", _text(term)).replace(f"{{${var}}}", _text(term))
        results.append(
            ShapeResult(
                _name(focus),
                _name(path) if path is not None else (prop.path if prop is not None else None),
                "SPARQLConstraintComponent",
                shape,
                severity,
                message,
            )
        )
    return results


def _closure(dataset: _Dataset, shapes: ShapeSet) -> dict[str, list[str]]:
    """Each class a shape names, with its subclasses (``rdfs:subClassOf+`` in the data)."""
    named: set[str] = set()

    def visit(checks: Iterable[ValueCheck]) -> None:
        for check in checks:
            if isinstance(check, ClassOf):
                named.add(check.cls)
            elif isinstance(check, AnyOf):
                for alternative in check.alternatives:
                    visit(alternative)

    for shape in shapes.shapes:
        named.update(shape.targets.classes)
        for prop in shape.properties:
            visit(prop.checks)
    closure: dict[str, list[str]] = {cls: [cls] for cls in named}
    if named:
        query = (
            f"SELECT DISTINCT ?c ?sub WHERE {{ {_values('c', (f'<{c}>' for c in sorted(named)))} "
            f"?sub <{_RDFS}subClassOf>+ ?c FILTER(isIRI(?sub)) }}"
        )
        for row in dataset.select_merged(query):
            closure[row["c"].value].append(row["sub"].value)
    return {cls: sorted(set(subs)) for cls, subs in closure.items()}


def check_shapes(
    kg: GraphStore,
    graphs: Sequence[str],
    shapes: ShapeSet,
    *,
    on_query: Callable[[int, int], None] | None = None,
) -> list[ShapeResult]:
    """Every SHACL result of ``shapes`` on the merge of ``graphs`` (named graphs of ``kg``), sorted.

    ``on_query(done, total)`` is called after each query.

    Raises
    ------
    QueryError
        When a shape's SPARQL does not parse or run, or a SPARQL constraint reports a failure.
    """
    dataset = _Dataset(kg, graphs)
    found: dict[str, list[str]] = {}  # each shape's focus nodes from its SPARQL targets
    jobs: list[Callable[[_Compiler], list[ShapeResult]]] = []
    for shape in shapes.shapes:
        if any(p.checks or p.min_count is not None or p.max_count is not None for p in shape.properties):
            jobs.append(partial(_run_properties, shape, found))
        jobs += [partial(_run_sparql, shape, found, c, None) for c in shape.sparql]
        jobs += [partial(_run_sparql, shape, found, c, p) for p in shape.properties for c in p.sparql]
    total = 1 + sum(len(s.targets.selects) for s in shapes.shapes) + len(jobs)
    done = 0

    def tick() -> None:
        nonlocal done
        done += 1
        if on_query is not None:
            on_query(done, total)

    compiler = _Compiler(dataset, _closure(dataset, shapes))
    tick()
    for shape in shapes.shapes:
        nodes: set[str] = set()
        for target in shape.targets.selects:
            select = f"{target.prologue}\nSELECT DISTINCT ?this WHERE {{ {{ {target.select} }} }}"
            for row in dataset.select_merged(select):
                if isinstance(row["this"], ox.BlankNode):
                    # A query can name an IRI or a literal it was given, not a blank node.
                    raise QueryError(f"SPARQL target {target.node} finds a blank node; cadkg needs IRIs")
                nodes.add(_term(row["this"]))
            tick()
        found[shape.node] = sorted(nodes)
    results: set[ShapeResult] = set()
    for job in jobs:
        results.update(job(compiler))
        tick()
    return sorted(results, key=ShapeResult.order)


def _targets_known_empty(shape: NodeShape, found: Sequence[str]) -> bool:
    """Whether the shape has no focus node: only SPARQL targets, and they found nothing."""
    t = shape.targets
    return not (t.classes or t.nodes or t.subjects_of or t.objects_of or found)


def _run_properties(
    shape: NodeShape, found: Mapping[str, Sequence[str]], compiler: _Compiler
) -> list[ShapeResult]:
    nodes = found[shape.node]
    checked = [p for p in shape.properties if p.checks or p.min_count is not None or p.max_count is not None]
    if _targets_known_empty(shape, nodes):
        return []
    query = compiler.properties(compiler.focus(shape.targets, nodes, by_graph=True), checked)
    results = []
    for row in compiler.dataset.select_union(query):
        results += _property_results(row, checked)
    return results


def _run_sparql(
    shape: NodeShape,
    found: Mapping[str, Sequence[str]],
    constraint: SparqlConstraint,
    prop: PropertyShape | None,
    compiler: _Compiler,
) -> list[ShapeResult]:
    nodes = found[shape.node]
    if _targets_known_empty(shape, nodes):
        return []
    select = constraint.select
    if prop is not None:
        select = re.sub(r"\$PATH\b", f"<{prop.path}>", select)
    query = (
        f"{constraint.prologue}\nSELECT * WHERE {{ {compiler.focus(shape.targets, nodes, by_graph=False)}\n"
        f"LATERAL {{ {select} }} }}"
    )
    solutions = compiler.dataset.select_merged(query)
    variables = [v.value for v in solutions.variables]  # type: ignore[attr-defined]
    rows = [{name: s[name] for name in variables if s[name] is not None} for s in solutions]
    severity = prop.severity if prop is not None else shape.severity
    return _sparql_results(rows, constraint, prop.node if prop is not None else shape.node, severity, prop)
