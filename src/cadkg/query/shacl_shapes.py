"""The SHACL shapes cadkg checks, read from Turtle into records its SPARQL compiler runs.

Only what the compiler can check is accepted: single-predicate paths; the targets
``sh:targetClass``, ``sh:targetNode``, ``sh:targetSubjectsOf``, ``sh:targetObjectsOf`` and
SHACL-AF SPARQL targets; ``sh:minCount``, ``sh:maxCount``, ``sh:datatype``, ``sh:class``,
``sh:nodeKind``, ``sh:in``, the four value ranges, ``sh:pattern``, ``sh:disjoint``, ``sh:or`` of
such value checks, and SPARQL-based constraints (``sh:sparql`` with ``sh:select``). Any other
``sh:`` term on a shape is an :class:`UnsupportedShapeError` naming the shape and the term,
so a shape the compiler cannot run is never skipped in silence.
"""

from __future__ import annotations

import re
from collections.abc import Iterator
from dataclasses import dataclass, replace
from functools import cache
from pathlib import Path

import pyoxigraph as ox

from cadkg.errors import CadkgError
from cadkg.ontology.terms import ontology_path

__all__ = [
    "SH",
    "AnyOf",
    "ClassOf",
    "Datatype",
    "Disjoint",
    "In",
    "NodeKind",
    "NodeShape",
    "Pattern",
    "PropertyShape",
    "Range",
    "ShapeSet",
    "SparqlConstraint",
    "Targets",
    "UnsupportedShapeError",
    "ValueCheck",
    "cadkg_shapes",
    "read_shapes",
]

SH = "http://www.w3.org/ns/shacl#"
_RDF = "http://www.w3.org/1999/02/22-rdf-syntax-ns#"
_RDFS = "http://www.w3.org/2000/01/rdf-schema#"
_XSD = "http://www.w3.org/2001/XMLSchema#"
_TYPE = ox.NamedNode(_RDF + "type")

Term = ox.NamedNode | ox.BlankNode | ox.Literal


class UnsupportedShapeError(CadkgError):
    """A shape uses a SHACL feature cadkg's SPARQL compiler does not run."""


# -- value checks: one test of each value node ---------------------------------------------
@dataclass(frozen=True)
class Datatype:
    datatype: str
    component = "DatatypeConstraintComponent"


@dataclass(frozen=True)
class ClassOf:
    cls: str
    component = "ClassConstraintComponent"


@dataclass(frozen=True)
class NodeKind:
    kind: str  # local name: IRI, BlankNode, Literal, BlankNodeOrIRI, ...
    component = "NodeKindConstraintComponent"


@dataclass(frozen=True)
class In:
    members: tuple[Term, ...]
    component = "InConstraintComponent"


@dataclass(frozen=True)
class Range:
    operator: str  # the SPARQL comparison the value must pass against the bound
    bound: ox.Literal
    component: str


@dataclass(frozen=True)
class Pattern:
    regex: str
    flags: str
    component = "PatternConstraintComponent"


@dataclass(frozen=True)
class Disjoint:
    predicate: str
    component = "DisjointConstraintComponent"


@dataclass(frozen=True)
class AnyOf:
    """``sh:or``: each alternative a conjunction of value checks."""

    alternatives: tuple[tuple[ValueCheck, ...], ...]
    component = "OrConstraintComponent"


ValueCheck = Datatype | ClassOf | NodeKind | In | Range | Pattern | Disjoint | AnyOf

_RANGES = {
    "minExclusive": (">", "MinExclusiveConstraintComponent"),
    "minInclusive": (">=", "MinInclusiveConstraintComponent"),
    "maxExclusive": ("<", "MaxExclusiveConstraintComponent"),
    "maxInclusive": ("<=", "MaxInclusiveConstraintComponent"),
}
_NODE_KINDS = {"IRI", "BlankNode", "Literal", "BlankNodeOrIRI", "BlankNodeOrLiteral", "IRIOrLiteral"}
# Datatypes whose ill-typed literals the compiler can tell from well-typed ones.
_DATATYPES = frozenset(
    _XSD + name for name in ("string", "boolean", "integer", "decimal", "double", "float", "dateTime", "date")
)


# -- shapes ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class SparqlConstraint:
    """A SPARQL-based constraint: ``select`` (prefixes declared) reports a result per row."""

    node: str
    select: str
    message: str | None
    prologue: str


@dataclass(frozen=True)
class Targets:
    classes: tuple[str, ...] = ()
    nodes: tuple[Term, ...] = ()
    subjects_of: tuple[str, ...] = ()
    objects_of: tuple[str, ...] = ()
    selects: tuple[SparqlConstraint, ...] = ()  # SHACL-AF SPARQL targets (their message is None)

    def __bool__(self) -> bool:
        return bool(self.classes or self.nodes or self.subjects_of or self.objects_of or self.selects)


@dataclass(frozen=True)
class PropertyShape:
    node: str  # the shape's IRI, or ``<node shape IRI>/<path IRI>`` for a blank one
    path: str
    severity: str
    message: str | None
    min_count: int | None = None
    max_count: int | None = None
    checks: tuple[ValueCheck, ...] = ()
    sparql: tuple[SparqlConstraint, ...] = ()


@dataclass(frozen=True)
class NodeShape:
    node: str
    targets: Targets
    severity: str
    message: str | None
    properties: tuple[PropertyShape, ...] = ()
    sparql: tuple[SparqlConstraint, ...] = ()


@dataclass(frozen=True)
class ShapeSet:
    """The targeted shapes of a shapes graph (a targeted property shape is a node shape of one property)."""

    shapes: tuple[NodeShape, ...] = ()


# What the reader accepts on each kind of node; rdfs: and other vocabularies are documentation.
_COMMON = {"message", "severity", "deactivated", "name", "description", "order", "group"}
_TARGETS = {"targetClass", "targetNode", "targetSubjectsOf", "targetObjectsOf", "target"}
_VALUE = {"datatype", "class", "nodeKind", "in", "pattern", "flags", "or", *_RANGES}
_NODE_ALLOWED = _COMMON | _TARGETS | {"property", "sparql"}
_PROPERTY_ALLOWED = _COMMON | _TARGETS | _VALUE | {"path", "minCount", "maxCount", "disjoint", "sparql"}
_SPARQL_ALLOWED = {"select", "message", "prefixes", "deactivated"}
_TARGET_ALLOWED = {"select", "prefixes"}
_PROLOGUE_IN_TEXT = re.compile(r"^\s*(PREFIX|BASE)\b", re.IGNORECASE)


class _Reader:
    def __init__(self, store: ox.Store, source: str) -> None:
        self.store = store
        self.source = source

    def objects(self, node: Term, local: str, namespace: str = SH) -> list[Term]:
        if isinstance(node, ox.Literal):
            return []
        quads = self.store.quads_for_pattern(node, ox.NamedNode(namespace + local), None)
        return [o for q in quads if not isinstance(o := q.object, ox.Triple)]

    def one(self, node: Term, local: str) -> Term | None:
        values = self.objects(node, local)
        if len(values) > 1:
            raise self.unsupported(node, f"sh:{local} given {len(values)} times")
        return values[0] if values else None

    def unsupported(self, node: Term | str, what: str) -> UnsupportedShapeError:
        name = node if isinstance(node, str) else _name(node)
        return UnsupportedShapeError(
            f"{self.source}: shape {name}: {what}; cadkg's SHACL engine does not run it"
        )

    def sh_predicates(self, node: Term) -> set[str]:
        if isinstance(node, ox.Literal):
            return set()
        return {
            q.predicate.value[len(SH) :]
            for q in self.store.quads_for_pattern(node, None, None)
            if q.predicate.value.startswith(SH)
        }

    def refuse_others(self, node: Term, allowed: set[str]) -> None:
        extra = sorted(self.sh_predicates(node) - allowed)
        if extra:
            raise self.unsupported(node, ", ".join(f"sh:{name}" for name in extra))

    def items(self, head: Term) -> Iterator[Term]:
        seen = 0
        while head != ox.NamedNode(_RDF + "nil"):
            first, rest = self.objects(head, "first", _RDF), self.objects(head, "rest", _RDF)
            if len(first) != 1 or len(rest) != 1 or seen > 10_000:
                raise self.unsupported(head, "a malformed RDF list")
            yield first[0]
            head = rest[0]
            seen += 1

    def flag(self, node: Term, local: str) -> bool:
        value = self.one(node, local)
        return isinstance(value, ox.Literal) and value.value in ("true", "1")

    def severity(self, node: Term) -> str:
        value = self.one(node, "severity")
        if value is None:
            return SH + "Violation"
        if not isinstance(value, ox.NamedNode):
            raise self.unsupported(node, "a sh:severity that is not an IRI")
        return value.value

    def message(self, node: Term) -> str | None:
        messages = self.objects(node, "message")
        if len(messages) > 1:
            # pySHACL reports every message and a finding shows one: which would be chance.
            raise self.unsupported(node, f"{len(messages)} sh:message values (cadkg shows one per finding)")
        return messages[0].value if messages else None

    def iri(self, node: Term, local: str) -> str | None:
        value = self.one(node, local)
        if value is not None and not isinstance(value, ox.NamedNode):
            raise self.unsupported(node, f"sh:{local} {value} is not an IRI")
        return value.value if value is not None else None

    def count(self, node: Term, local: str) -> int | None:
        value = self.one(node, local)
        if value is None:
            return None
        if not isinstance(value, ox.Literal) or not value.value.isdigit():
            raise self.unsupported(node, f"sh:{local} {value} is not a non-negative integer")
        return int(value.value)

    # -- the parts of a shape ----------------------------------------------------------------
    def prologue(self, node: Term) -> str:
        lines = []
        for holder in self.objects(node, "prefixes"):
            for declaration in self.objects(holder, "declare"):
                prefix, namespace = self.one(declaration, "prefix"), self.one(declaration, "namespace")
                if prefix is None or namespace is None:
                    raise self.unsupported(node, "a sh:declare without sh:prefix and sh:namespace")
                lines.append(f"PREFIX {prefix.value}: <{namespace.value}>")
        return "\n".join(sorted(set(lines)))

    def sparql(self, node: Term, allowed: set[str]) -> SparqlConstraint:
        self.refuse_others(node, allowed)
        select = self.one(node, "select")
        if select is None:
            raise self.unsupported(node, "a SPARQL constraint or target without sh:select")
        if _PROLOGUE_IN_TEXT.match(select.value):
            raise self.unsupported(node, "PREFIX or BASE in sh:select (declare prefixes with sh:prefixes)")
        if re.search(r"\$(shapesGraph|currentShape)\b", select.value):
            raise self.unsupported(node, "$shapesGraph or $currentShape in sh:select")
        return SparqlConstraint(_name(node), select.value, self.message(node), self.prologue(node))

    def constraints(self, node: Term) -> tuple[SparqlConstraint, ...]:
        """The shape's SPARQL constraints; one without a message takes the shape's."""
        shape_message = self.message(node)
        found = []
        for c in self.objects(node, "sparql"):
            if self.flag(c, "deactivated"):
                continue
            constraint = self.sparql(c, _SPARQL_ALLOWED)
            if shape_message is not None and constraint.message is not None:
                raise self.unsupported(node, "a sh:message on the shape and on its SPARQL constraint")
            found.append(replace(constraint, message=constraint.message or shape_message))
        return tuple(found)

    def targets(self, node: Term) -> Targets:
        def iris(local: str) -> tuple[str, ...]:
            values = self.objects(node, local)
            if any(not isinstance(v, ox.NamedNode) for v in values):
                raise self.unsupported(node, f"a sh:{local} that is not an IRI")
            return tuple(sorted(v.value for v in values))

        classes = iris("targetClass")
        if ox.Quad(node, _TYPE, ox.NamedNode(_RDFS + "Class")) in self.store:  # type: ignore[arg-type]
            classes = (*classes, _name(node))  # an implicit class target
        selects = []
        for target in self.objects(node, "target"):
            if ox.Quad(target, _TYPE, ox.NamedNode(SH + "SPARQLTarget")) not in self.store:  # type: ignore[arg-type]
                raise self.unsupported(node, "a sh:target that is not a sh:SPARQLTarget")
            selects.append(self.sparql(target, _TARGET_ALLOWED))
        return Targets(
            classes=classes,
            nodes=tuple(self.objects(node, "targetNode")),
            subjects_of=iris("targetSubjectsOf"),
            objects_of=iris("targetObjectsOf"),
            selects=tuple(selects),
        )

    def value_checks(self, node: Term, *, nested: bool = False) -> tuple[ValueCheck, ...]:
        if nested:
            self.refuse_others(node, _VALUE - {"or"} | {"message"})
        checks: list[ValueCheck] = []
        datatype = self.iri(node, "datatype")
        if datatype is not None:
            if datatype not in _DATATYPES:
                raise self.unsupported(node, f"sh:datatype <{datatype}>")
            checks.append(Datatype(datatype))
        for cls in self.objects(node, "class"):
            if not isinstance(cls, ox.NamedNode):
                raise self.unsupported(node, "a sh:class that is not an IRI")
            checks.append(ClassOf(cls.value))
        kind = self.iri(node, "nodeKind")
        if kind is not None:
            if not kind.startswith(SH) or kind[len(SH) :] not in _NODE_KINDS:
                raise self.unsupported(node, f"sh:nodeKind <{kind}>")
            checks.append(NodeKind(kind[len(SH) :]))
        members = self.one(node, "in")
        if members is not None:
            checks.append(In(tuple(self.items(members))))
        for local, (operator, component) in _RANGES.items():
            for bound in self.objects(node, local):
                if not isinstance(bound, ox.Literal):
                    raise self.unsupported(node, f"sh:{local} that is not a literal")
                checks.append(Range(operator, bound, component))
        pattern = self.one(node, "pattern")
        if pattern is not None:
            flags = self.one(node, "flags")
            checks.append(Pattern(pattern.value, flags.value if flags is not None else ""))
        alternatives = self.one(node, "or")
        if alternatives is not None:
            checks.append(AnyOf(tuple(self.value_checks(a, nested=True) for a in self.items(alternatives))))
        return tuple(checks)

    def property_shape(self, node: Term, owner: str) -> PropertyShape:
        self.refuse_others(node, _PROPERTY_ALLOWED)
        path = self.one(node, "path")
        if not isinstance(path, ox.NamedNode):
            raise self.unsupported(owner if isinstance(node, ox.BlankNode) else node, f"sh:path {path}")
        disjoint = tuple(
            Disjoint(v.value) for v in self.objects(node, "disjoint") if isinstance(v, ox.NamedNode)
        )
        if len(disjoint) != len(self.objects(node, "disjoint")):
            raise self.unsupported(node, "a sh:disjoint that is not an IRI")
        return PropertyShape(
            node=f"{owner}/{path.value}" if isinstance(node, ox.BlankNode) else _name(node),
            path=path.value,
            severity=self.severity(node),
            message=self.message(node),
            min_count=self.count(node, "minCount"),
            max_count=self.count(node, "maxCount"),
            checks=self.value_checks(node) + disjoint,
            sparql=self.constraints(node),
        )

    def node_shape(self, node: Term) -> NodeShape:
        if self.one(node, "path") is not None:  # a targeted property shape: a shape of one property
            prop = self.property_shape(node, _name(node))
            return NodeShape(prop.node, self.targets(node), prop.severity, prop.message, (prop,))
        self.refuse_others(node, _NODE_ALLOWED)
        properties = [
            self.property_shape(p, _name(node))
            for p in self.objects(node, "property")
            if not self.flag(p, "deactivated")
        ]
        return NodeShape(
            node=_name(node),
            targets=self.targets(node),
            severity=self.severity(node),
            message=self.message(node),
            properties=tuple(sorted(properties, key=lambda p: p.node)),
            sparql=self.constraints(node),
        )


def _name(node: Term) -> str:
    return node.value if isinstance(node, ox.NamedNode) else str(node)


def read_shapes(turtle: bytes | str, source: str = "shapes") -> ShapeSet:
    """The targeted shapes of a Turtle shapes graph.

    Raises
    ------
    UnsupportedShapeError
        When a shape uses a SHACL feature the compiler does not run.
    """
    store = ox.Store()
    store.load(turtle, ox.RdfFormat.TURTLE)
    reader = _Reader(store, source)
    patterns: list[tuple[ox.NamedNode, ox.NamedNode | None]]
    patterns = [(_TYPE, ox.NamedNode(SH + "NodeShape")), (_TYPE, ox.NamedNode(SH + "PropertyShape"))]
    patterns += [(ox.NamedNode(SH + local), None) for local in _TARGETS]
    candidates: set[Term] = {
        s
        for predicate, obj in patterns
        for q in store.quads_for_pattern(None, predicate, obj)
        if not isinstance(s := q.subject, ox.Triple)
    }
    # A shape is run where its targets are; every shape a targeted one uses is read with it, so a
    # declared shape without targets that nothing uses is checked for what it says all the same.
    for node in candidates:
        if reader.flag(node, "deactivated"):
            continue
        if reader.one(node, "path") is None:
            reader.refuse_others(node, _NODE_ALLOWED)
        else:
            reader.refuse_others(node, _PROPERTY_ALLOWED)
    shapes = [
        reader.node_shape(node)
        for node in candidates
        if not reader.flag(node, "deactivated") and reader.targets(node)
    ]
    return ShapeSet(tuple(sorted(shapes, key=lambda s: s.node)))


@cache
def cadkg_shapes() -> ShapeSet:
    """cadkg's own shapes (``ontology/shapes.ttl``), read once."""
    return read_shapes(Path(ontology_path("shapes.ttl")).read_bytes(), "shapes.ttl")
