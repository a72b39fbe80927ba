"""Reader of VRML97 scenes (``.wrl``, the classic ``#VRML V2.0 utf8`` encoding).

The parser knows no field types: a field's value is a run of numbers, a string, a boolean,
a node or a ``[ ]`` list of those, which is all VRML97 can write. Prototypes are skipped (their
instances become unknown nodes, skipped with a warning) and routes are ignored. See
docs/formats/scene.md for what is read.
"""

from __future__ import annotations

import re
from pathlib import Path

from cadkg.errors import IngestError
from cadkg.ingest.scene.nodes import MAX_NESTING, Field, Node, ParsedFile
from cadkg.ingest.text import read_text

__all__ = ["looks_like_vrml97", "parse_vrml"]

HEADER = "#VRML V2.0 utf8"
_EXPECTED = f"a VRML97 file starting with {HEADER!r}"
# Each match is the white space and comments before one token, then the token (or the end).
# Possessive quantifiers: nothing is retried, so no input makes the scan slower than linear.
_TOKEN = re.compile(
    r'(?:[\s,]++|\#[^\n]*+)*+(?:(?P<string>"(?:[^"\\]++|\\.)*+")|(?P<punct>[\[\]{}])'
    r'|(?P<word>[^\s,"\#\[\]{}]++)|(?P<unterminated>")|(?P<end>\Z))',
    re.DOTALL,
)
_NUMBER_START = re.compile(r"[+-]?\.?\d")
_ESCAPE = re.compile(r"\\(.)", re.DOTALL)
_INTERFACE = frozenset({"eventIn", "eventOut", "field", "exposedField"})
_CLOSE = {"[": "]", "{": "}"}
_KEYWORDS = frozenset(
    {"DEF", "USE", "PROTO", "EXTERNPROTO", "ROUTE", "TO", "IS", "TRUE", "FALSE", "NULL"}
    | {"eventIn", "eventOut", "field", "exposedField"}
)

Token = tuple[str, str, int]


def parse_vrml(path: Path) -> ParsedFile:
    """Parse one VRML97 file into scene nodes (Inline files are not followed here)."""
    text = read_text(path, expected=_EXPECTED)
    first = text.split("\n", 1)[0].rstrip("\r")
    if not first.startswith(HEADER):
        reason = "VRML 1.0 is not read" if first.startswith("#VRML V1.0") else "not a VRML97 file"
        raise IngestError(path, reason, line=1, found=first[:40], expected=_EXPECTED)
    return _Parser(path, _tokenize(path, text.replace("\r\n", "\n").replace("\r", "\n"))).scene()


def _tokenize(path: Path, text: str) -> list[Token]:
    tokens: list[Token] = []
    line, last = 1, 0
    for match in _TOKEN.finditer(text):
        kind = match.lastgroup
        if kind is None or kind == "end":
            break
        start = match.start(kind)
        line += text.count("\n", last, start)
        last = start
        if kind == "unterminated":
            raise IngestError(
                path, "unterminated string", line=line, found=text[start : start + 30], expected='a closing "'
            )
        tokens.append((kind, match.group(kind), line))
    return tokens


def _is_number(token: Token) -> bool:
    return token[0] == "word" and _NUMBER_START.match(token[1]) is not None


class _Parser:
    def __init__(self, path: Path, tokens: list[Token]) -> None:
        self.path = path
        self.source = str(path)
        self.tokens = tokens
        self.pos = 0
        self.defs: dict[str, Node] = {}

    # -- tokens --

    def peek(self) -> Token | None:
        return self.tokens[self.pos] if self.pos < len(self.tokens) else None

    def take(self, expected: str, opened: Token | None = None) -> Token:
        token = self.peek()
        if token is None:
            raise self.eof(expected, opened)
        self.pos += 1
        return token

    def eof(self, expected: str, opened: Token | None) -> IngestError:
        if opened is not None:
            reason = f"unexpected end of file: {opened[1]!r} on line {opened[2]} is never closed"
            return IngestError(self.path, reason, line=opened[2], expected=expected)
        last = self.tokens[-1][2] if self.tokens else 1
        return IngestError(self.path, "unexpected end of file", line=last, expected=expected)

    def unexpected(self, token: Token, expected: str) -> IngestError:
        found = token[1][:40]
        return IngestError(self.path, "unexpected token", line=token[2], found=found, expected=expected)

    def word(self, expected: str) -> Token:
        token = self.take(expected)
        if token[0] != "word":
            raise self.unexpected(token, expected)
        return token

    def name(self, expected: str) -> Token:
        # VRML97 names cannot start with a digit or sign, nor be a keyword.
        token = self.word(expected)
        if _is_number(token) or token[1] in _KEYWORDS:
            raise self.unexpected(token, expected)
        return token

    def skip_block(self, expected_open: str) -> None:
        opened = self.take(f"'{expected_open}'")
        if opened[1] != expected_open:
            raise self.unexpected(opened, f"'{expected_open}'")
        stack = [opened]
        while stack:
            token = self.take(f"{_CLOSE[stack[-1][1]]!r}", stack[-1])
            if token[1] in _CLOSE and token[0] == "punct":
                stack.append(token)
            elif token[0] == "punct":
                if token[1] != _CLOSE[stack[-1][1]]:
                    raise self.unexpected(token, f"{_CLOSE[stack[-1][1]]!r} for line {stack[-1][2]}")
                stack.pop()

    # -- statements --

    def scene(self) -> ParsedFile:
        roots: list[Node] = []
        while self.peek() is not None:
            node = self.statement(0)
            if node is not None:
                roots.append(node)
        return ParsedFile(roots, {name: node.line for name, node in self.defs.items()})

    def statement(self, depth: int) -> Node | None:
        token = self.peek()
        if token is not None and token[0] == "word":
            if token[1] == "PROTO":
                self.pos += 1
                self.word("a prototype name")
                self.skip_block("[")
                self.skip_block("{")
                return None
            if token[1] == "EXTERNPROTO":
                self.pos += 1
                self.word("a prototype name")
                self.skip_block("[")
                url = self.peek()
                if url is not None and url[1] == "[":
                    self.skip_block("[")
                elif self.take("the prototype's url")[0] != "string":
                    raise self.unexpected(self.tokens[self.pos - 1], "the prototype's url")
                return None
            if token[1] == "ROUTE":
                self.route()
                return None
        return self.node_statement(depth)

    def route(self) -> None:
        self.pos += 1
        self.word("node.eventOut")
        to = self.word("TO")
        if to[1] != "TO":
            raise self.unexpected(to, "TO")
        self.word("node.eventIn")

    def node_statement(self, depth: int) -> Node:
        token = self.word("a node, DEF or USE")
        if token[1] == "USE":
            name = self.name("a DEF name")
            target = self.defs.get(name[1])
            if target is None:
                raise IngestError(
                    self.path,
                    "USE of an undefined name",
                    line=name[2],
                    found=name[1],
                    expected="the DEF name of an earlier node",
                )
            return Node(target.type, self.source, token[2], use_of=target)
        if token[1] == "DEF":
            name = self.name("a DEF name")
            node = self.node(self.name("a node type"), depth, token[2])
            first = self.defs.get(name[1])
            if first is not None:
                raise IngestError(
                    self.path,
                    f"DEF name {name[1]} given twice (first on line {first.line})",
                    line=token[2],
                    found=name[1],
                    expected="each DEF name once",
                )
            node.def_name = name[1]
            self.defs[name[1]] = node
            return node
        if _is_number(token) or token[1] in _KEYWORDS:
            raise self.unexpected(token, "a node type")
        return self.node(token, depth, token[2])

    def node(self, kind: Token, depth: int, line: int) -> Node:
        if depth > MAX_NESTING:
            raise IngestError(self.path, f"nodes nest deeper than {MAX_NESTING} levels", line=kind[2])
        opened = self.take("'{'")
        if opened[1] != "{" or opened[0] != "punct":
            raise self.unexpected(opened, f"'{{' after {kind[1]}")
        node = Node(kind[1], self.source, line)
        while True:
            token = self.take("a field name or '}'", opened)
            if token[0] == "punct" and token[1] == "}":
                return node
            if token[0] != "word" or _is_number(token):
                raise self.unexpected(token, f"a field name or '}}' closing {kind[1]} of line {opened[2]}")
            if token[1] in ("ROUTE", "PROTO", "EXTERNPROTO"):
                self.pos -= 1
                self.statement(depth)
            elif token[1] in _INTERFACE:
                # Script and prototype interfaces: "field SFFloat name value".
                self.word("a field type")
                name = self.word("a field name")
                if token[1] in ("field", "exposedField"):
                    self.value(node, name[1], depth)
            else:
                self.value(node, token[1], depth)

    def value(self, node: Node, name: str, depth: int) -> None:
        token = self.take(f"a value for {name!r}")
        scalars: list[str] = []
        nodes: list[Node] = []
        if token[0] == "punct" and token[1] == "[":
            while True:
                item = self.peek()
                if item is None:
                    raise self.eof("']'", token)
                if item[0] == "punct":
                    if item[1] != "]":
                        raise self.unexpected(item, f"']' closing the list of line {token[2]}")
                    self.pos += 1
                    break
                if item[0] == "string" or _is_number(item) or item[1] in ("TRUE", "FALSE"):
                    self.pos += 1
                    scalars.append(self.scalar(item))
                else:
                    nodes.append(self.node_statement(depth + 1))
        elif token[0] == "string" or token[1] in ("TRUE", "FALSE"):
            scalars.append(self.scalar(token))
        elif _is_number(token):
            scalars.append(token[1])
            while (following := self.peek()) is not None and _is_number(following):
                scalars.append(following[1])
                self.pos += 1
        elif token[0] == "word" and token[1] != "NULL":
            self.pos -= 1
            nodes.append(self.node_statement(depth + 1))
        elif token[0] == "punct":
            raise self.unexpected(token, f"a value for {name!r}")
        node.fields[name] = Field(token[2], scalars)
        node.nodes[name] = nodes

    def scalar(self, token: Token) -> str:
        return _ESCAPE.sub(r"\1", token[1][1:-1]) if token[0] == "string" else token[1]


def looks_like_vrml97(head: bytes) -> bool:
    """Whether a file starts with the VRML97 header."""
    return head.removeprefix(b"\xef\xbb\xbf").startswith(b"#VRML V2.0")
