"""The change set as RDF, in the ontology's terms: the statements each change removes and adds.

Every quad that one revision holds and the other does not is a removed or an added statement,
reified (``rdf:subject``, ``rdf:predicate``, ``rdf:object``, ``ck:inGraph``) and grouped by its
subject into a ``ck:Change``; a subject that is a thing of the diff carries its kind and
identity. Applied to the old graph (:func:`apply_changes`), it gives the new one, so a remote
store can be patched with it. The ontology's own graph is left out: it is cadkg's vocabulary,
not the cell, and its blank nodes differ in every store.
"""

from __future__ import annotations

import uuid
from collections import defaultdict
from collections.abc import Iterable, Iterator
from typing import Any

import pyoxigraph as ox

from cadkg.changes.changeset import ChangeSet
from cadkg.errors import StoreError
from cadkg.ontology.terms import CK, CK_NS, ONTOLOGY_IRI, RDF_TYPE

__all__ = ["apply_changes", "cell_quads", "changes_turtle", "read_changes", "statement_changes"]

_RDF = "http://www.w3.org/1999/02/22-rdf-syntax-ns#"
_STATEMENT = ox.NamedNode(_RDF + "Statement")
_SUBJECT, _PREDICATE, _OBJECT = (ox.NamedNode(_RDF + n) for n in ("subject", "predicate", "object"))
_ONTOLOGY = ox.NamedNode(ONTOLOGY_IRI)
_TYPE = RDF_TYPE


def cell_quads(graph: Any) -> Iterator[ox.Quad]:
    """Every quad of ``graph`` but the ontology's."""
    return (q for q in graph.quads() if q.graph_name != _ONTOLOGY)


def statement_changes(old: Any, new: Any) -> tuple[set[ox.Quad], set[ox.Quad]]:
    """The quads only ``old`` holds (removed) and those only ``new`` holds (added)."""
    before = set(cell_quads(old))
    after = set(cell_quads(new))
    return before - after, after - before


def changes_turtle(
    removed: Iterable[ox.Quad], added: Iterable[ox.Quad], changes: ChangeSet | None = None
) -> bytes:
    """The change set as Turtle: a ``ck:ChangeSet`` with one ``ck:Change`` per subject."""
    things = {}
    if changes is not None:
        for change in changes:
            for iri in (change.old_iri, change.new_iri):
                if iri is not None:
                    things[iri] = change
    by_subject: dict[Any, tuple[list[ox.Quad], list[ox.Quad]]] = defaultdict(lambda: ([], []))
    for quad in removed:
        by_subject[quad.subject][0].append(quad)
    for quad in added:
        by_subject[quad.subject][1].append(quad)
    root = ox.NamedNode(f"urn:uuid:{uuid.uuid4()}")
    triples = [ox.Triple(root, _TYPE, CK.ChangeSet)]
    if changes is not None:
        triples += [
            ox.Triple(root, CK.fromRevision, ox.Literal(changes.old)),
            ox.Triple(root, CK.toRevision, ox.Literal(changes.new)),
        ]
    for number, subject in enumerate(sorted(by_subject, key=str), start=1):
        gone, came = by_subject[subject]
        node = ox.NamedNode(f"{root.value}#change-{number}")
        kind = "changed" if gone and came else "removed" if gone else "added"
        triples += [
            ox.Triple(root, CK.hasChange, node),
            ox.Triple(node, _TYPE, CK.Change),
            ox.Triple(node, CK.changeOf, subject),
        ]
        thing = things.get(subject.value) if isinstance(subject, ox.NamedNode) else None
        if thing is not None:
            kind = thing.change
            triples += [
                ox.Triple(node, CK.thingKind, ox.Literal(thing.kind)),
                ox.Triple(node, CK.thingId, ox.Literal(thing.id)),
            ]
            triples += [ox.Triple(node, CK.changedAttribute, ox.Literal(a)) for a in thing.attributes]
        triples.append(ox.Triple(node, CK.changeKind, ox.Literal(kind)))
        for label, quads in (("removed", gone), ("added", came)):
            link = CK.removedStatement if label == "removed" else CK.addedStatement
            for index, quad in enumerate(sorted(quads, key=str), start=1):
                statement = ox.NamedNode(f"{node.value}-{label}-{index}")
                triples += [
                    ox.Triple(node, link, statement),
                    ox.Triple(statement, _TYPE, _STATEMENT),
                    ox.Triple(statement, _SUBJECT, quad.subject),
                    ox.Triple(statement, _PREDICATE, quad.predicate),
                    ox.Triple(statement, _OBJECT, quad.object),
                ]
                if isinstance(quad.graph_name, ox.NamedNode):
                    triples.append(ox.Triple(statement, CK.inGraph, quad.graph_name))
    return bytes(
        ox.serialize(
            triples,
            format=ox.RdfFormat.TURTLE,
            prefixes={"ck": CK_NS, "rdf": _RDF},
        )
        or b""
    )


def read_changes(data: bytes) -> tuple[list[ox.Quad], list[ox.Quad]]:
    """The removed and added quads of a change set in Turtle.

    Raises
    ------
    StoreError
        When ``data`` is not Turtle or a statement lacks a part.
    """
    try:
        triples = list(ox.parse(data, format=ox.RdfFormat.TURTLE))
    except SyntaxError as err:
        raise StoreError(f"the change set is not Turtle: {err}") from None
    parts: dict[Any, dict[Any, Any]] = defaultdict(dict)
    links: list[tuple[bool, Any]] = []
    for t in triples:
        if t.predicate in (_SUBJECT, _PREDICATE, _OBJECT, CK.inGraph):
            parts[t.subject][t.predicate] = t.object
        elif t.predicate in (CK.removedStatement, CK.addedStatement):
            links.append((t.predicate == CK.addedStatement, t.object))
    removed: list[ox.Quad] = []
    added: list[ox.Quad] = []
    for is_added, statement in links:
        part = parts.get(statement, {})
        if not all(p in part for p in (_SUBJECT, _PREDICATE, _OBJECT)):
            raise StoreError(f"the change set's statement {statement} lacks its subject, predicate or object")
        graph = part.get(CK.inGraph, ox.DefaultGraph())
        (added if is_added else removed).append(
            ox.Quad(part[_SUBJECT], part[_PREDICATE], part[_OBJECT], graph)
        )
    return removed, added


def apply_changes(store: ox.Store, data: bytes) -> tuple[int, int]:
    """Patch ``store`` with a change set in Turtle; give how many statements went and came.

    Raises
    ------
    StoreError
        As :func:`read_changes`.
    """
    removed, added = read_changes(data)
    for quad in removed:
        store.remove(quad)
    store.extend(added)
    return len(removed), len(added)
