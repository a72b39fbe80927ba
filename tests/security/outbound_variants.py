"""Generated SPARQL texts that ask, or only seem to ask, for an outbound request: the variants the
tests of ``SERVICE`` and ``LOAD`` draw from.

Each text carries what pyoxigraph would reach when it parses: keywords in any case, with
whitespace, comments ended by ``\\r``, ``\\n`` or ``\\r\\n``, or nothing between the keyword, an
optional ``SILENT`` and the target (``SERVICEex:x``, ``SERVICE:x``, ``SERVICESILENT<iri>``),
targets written as IRIs, prefixed names, relative IRIs under ``BASE`` or variables, patterns
nested in groups, and decoys in strings and comments that reach nothing.
"""

from __future__ import annotations

from dataclasses import dataclass

from hypothesis import strategies as st

SEPARATORS = ["", " ", "\t", "\n", "\r", "\r\n", " # SERVICE <x>\r", "#c\n", "#c\r\n", "\r\n\t "]
LINE_ENDS = ["\r", "\n", "\r\n"]
PROLOGUE_SEPARATORS = [" ", "\n", "\r", "#c\r", "#c\r\n"]


@dataclass(frozen=True)
class Variant:
    """A SPARQL text; ``reaches`` are the paths under the listener's address it asks for
    (empty for a decoy), ``reaches_unknown`` whether it asks for an endpoint named by a variable."""

    text: str
    reaches: tuple[str, ...]
    reaches_unknown: bool = False


@st.composite
def keyword(draw: st.DrawFn, word: str) -> str:
    """``word`` with each letter in either case."""
    flips = draw(st.lists(st.booleans(), min_size=len(word), max_size=len(word)))
    return "".join(c.lower() if flip else c for c, flip in zip(word, flips, strict=True))


@st.composite
def _target(draw: st.DrawFn, base: str, path: str) -> tuple[str, str]:
    """(prologue, how the target is written) for ``base + path``."""
    form = draw(st.sampled_from(["iri", "prefixed", "empty-prefix", "relative"]))
    sep = draw(st.sampled_from(PROLOGUE_SEPARATORS))
    if form == "iri":
        return "", f"<{base}{path}>"
    if form == "relative":
        return f"{draw(keyword('BASE'))}{sep}<{base}>{sep}", f"<{path}>"
    name = "" if form == "empty-prefix" else draw(st.sampled_from(["ex", "e2", "remote"]))
    declare = draw(keyword("PREFIX")) + draw(st.sampled_from([" ", "\r", "#c\r", ""] if name else [" ", ""]))
    return f"{declare}{name}:{sep}<{base}>{sep}", f"{name}:{path}"


@st.composite
def outbound_pattern(draw: st.DrawFn, word: str, base: str, index: int) -> tuple[str, str, str | None]:
    """(prologue, pattern, path reached or None for a variable) of one ``SERVICE`` or ``LOAD``."""
    path = f"t{index}"
    parts = [draw(keyword(word))]
    parts.append(draw(st.sampled_from(SEPARATORS)))
    if draw(st.booleans()):
        parts += [draw(keyword("SILENT")), draw(st.sampled_from(SEPARATORS))]
    if word == "SERVICE" and draw(st.integers(0, 5)) == 0:
        parts.append("?endpoint")
        prologue, reached = "", None
    else:
        prologue, written = draw(_target(base, path))
        parts.append(written)
        reached = path
    if word == "SERVICE":
        parts += [draw(st.sampled_from(SEPARATORS)), "{ ?s ?p ?o }"]
    return prologue, "".join(parts), reached


@st.composite
def decoy(draw: st.DrawFn, base: str) -> str:
    """A pattern that mentions ``SERVICE`` but asks for nothing."""
    target = f"<{base}decoy>"
    mention = f"{draw(keyword('SERVICE'))} {target} {{ }}"
    form = draw(st.sampled_from(["string", "long-string", "comment", "name"]))
    if form == "string":
        quote = draw(st.sampled_from(["'", '"']))
        return f"?s ?p {quote}{mention}{quote}"
    if form == "long-string":
        quote = draw(st.sampled_from(["'''", '"""']))
        return f"?s ?p {quote}a\r{mention}\n{quote}"
    if form == "comment":
        end = draw(st.sampled_from(LINE_ENDS))
        return f"# {mention}{end} ?s ?p ?o"
    return "?service <urn:x:service> <urn:x:load>"


def _nest(draw: st.DrawFn, pattern: str) -> str:
    for _ in range(draw(st.integers(0, 3))):
        wrap = draw(st.sampled_from(["{ %s }", "OPTIONAL { %s }", "{ %s } UNION { ?s ?p ?o }", "{{ %s }}"]))
        pattern = wrap % pattern
    return pattern


@st.composite
def service_query(draw: st.DrawFn, base: str) -> Variant:
    """A SELECT with zero to three ``SERVICE`` patterns (each maybe nested) and decoys."""
    prologues: list[str] = []
    patterns: list[str] = []
    reaches: list[str] = []
    unknown = False
    for index in range(draw(st.integers(0, 3))):
        prologue, pattern, reached = draw(outbound_pattern("SERVICE", base, index))
        prologues.append(prologue)
        patterns.append(_nest(draw, pattern))
        if reached is None:
            unknown = True
        else:
            reaches.append(reached)
    for _ in range(draw(st.integers(0 if patterns else 1, 2))):
        # OPTIONAL: a decoy matching nothing must not keep pyoxigraph from calling the services.
        optional = f"OPTIONAL {{ {_nest(draw, draw(decoy(base)))} }}"
        patterns.insert(draw(st.integers(0, len(patterns))), optional)
    joints = [" "] + [draw(st.sampled_from([" ", " . ", "\r", "\n"])) for _ in patterns[1:]]
    body = "".join(f"{joint}{pattern}" for joint, pattern in zip(joints, patterns, strict=True))
    select = draw(keyword("SELECT"))
    return Variant(f"{''.join(prologues)}{select} * WHERE {{ {body} }}", tuple(reaches), unknown)


@st.composite
def load_update(draw: st.DrawFn, base: str) -> Variant:
    """An update of one to three ``LOAD`` operations, or one decoy that loads nothing."""
    if draw(st.integers(0, 4)) == 0:
        return Variant(f"INSERT DATA {{ GRAPH <urn:g> {{ <urn:s> <urn:p> 'LOAD <{base}decoy>' }} }}", ())
    prologues, operations, reaches = [], [], []
    for index in range(draw(st.integers(1, 3))):
        prologue, pattern, reached = draw(outbound_pattern("LOAD", base, index))
        into = draw(
            st.sampled_from(["", " INTO GRAPH <urn:g>", f" {draw(keyword('INTO'))} GRAPH <urn:g{index}>"])
        )
        # pyoxigraph takes PREFIX and BASE only before the first operation.
        prologues.append(prologue)
        operations.append(f"{pattern}{into}")
        assert reached is not None
        reaches.append(reached)
    return Variant("".join(prologues) + " ;\n".join(operations), tuple(reaches))
