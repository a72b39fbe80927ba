"""The component model XML reader: Figure 4's model, older files, children, and located errors."""

from __future__ import annotations

import pytest

from cadkg.errors import IngestError
from cadkg.registry import sniff_kind
from cadkg.usecases.iema.component_model import (
    ChildPlacement,
    ComponentModel,
    Couple,
    Placement,
    looks_like_component_models,
    parse_models_fragment,
    read_component_models,
)
from tests.conftest import ROOT

READERS = ROOT / "tests" / "data" / "readers"
SAMPLE = READERS / "models-sample.xml"
OLD = READERS / "models-old.xml"

ZERO = (0.0, 0.0, 0.0)


@pytest.fixture(scope="module")
def sample() -> dict[str, ComponentModel]:
    return {m.key: m for m in read_component_models(SAMPLE)}


def test_figure_4_model_exact(sample: dict[str, ComponentModel]) -> None:
    model = sample["SIEMENS 5SL4202-8"]
    assert (model.code, model.commercial, model.role, model.line) == (
        "SIEMENS 5SL4202-8",
        "SIEMENS 5SL4202-8",
        "root",
        3,
    )
    assert model.dimensions == (0.0898, 0.0359, 0.07448)
    assert model.couples[0] == Couple(
        name="1",
        screw=Placement(xyz=(0.0085, 0.009, 0.04496), rpy=ZERO, line=5),
        hole=Placement(xyz=ZERO, rpy=ZERO, line=6),
        line=4,
    )
    assert [c.name for c in model.couples] == ["1", "2"]
    assert model.couples[1].hole == Placement(xyz=(0.018, 0.0, 0.0), rpy=ZERO, line=10)


def test_child_placement(sample: dict[str, ComponentModel]) -> None:
    (child,) = sample["SIEMENS 5SL4202-8"].children
    assert child == ChildPlacement(
        name="6503373", relative=Placement(xyz=(0.0898, 0.0, 0.0), rpy=(0.0, 0.0, 1.5708), line=13), line=12
    )
    # The child's own model is in the same file, keyed by its commercial code.
    assert sample[child.name].role == "child"


def test_file_order_roles_and_screw_only_couples(sample: dict[str, ComponentModel]) -> None:
    assert list(sample) == ["SIEMENS 5SL4202-8", "6503373", "6013290"]
    aux = sample["6503373"]
    assert [(c.name, c.screw is not None, c.hole) for c in aux.couples] == [
        ("13", True, None),
        ("14", True, None),
    ]
    assert sample["6013290"].role == "terminal"


def test_numbers_with_white_space_and_line_breaks(sample: dict[str, ComponentModel]) -> None:
    terminal = sample["6013290"]
    assert "\n          0.0031\n" in SAMPLE.read_text(encoding="utf-8")
    a, b = terminal.couples
    assert a.screw == Placement(xyz=(0.0031, 0.0105, 0.0447), rpy=ZERO, line=27)
    assert a.hole is not None and a.hole.xyz == (0.0031, 0.0045, 0.0325)
    assert b.screw is not None and b.screw.xyz == (0.0031, 0.048, 0.0447)


def test_old_file_without_commercial_and_parent() -> None:
    first, second = read_component_models(OLD)
    assert (first.code, first.commercial, first.role, first.key) == ("6503372", None, None, "6503372")
    assert first.dimensions == (0.045, 0.09, 0.07)
    assert first.couples[1].screw == Placement(xyz=(0.0085, 0.0795, 0.0645), rpy=ZERO, line=8)
    assert (second.code, second.dimensions, second.children) == ("6013277", None, ())
    assert second.couples == (
        Couple("1", screw=None, hole=Placement(xyz=(0.003, 0.01, 0.03), rpy=ZERO, line=14), line=13),
    )


def test_fragment_lines_are_shifted_by_the_offset() -> None:
    text = SAMPLE.read_text(encoding="utf-8").split("\n", 1)[1]  # without the XML declaration
    models = parse_models_fragment(text, "list.csv", 100)
    assert [m.line for m in models] == [102, 115, 124]
    assert models[0].couples[0].screw is not None and models[0].couples[0].screw.line == 104


def test_sniff() -> None:
    assert sniff_kind(SAMPLE) == "component-model"
    head = SAMPLE.read_bytes()
    assert looks_like_component_models(head)
    assert looks_like_component_models(b"\xef\xbb\xbf\n  <data><code name='x'/></data>")
    assert not looks_like_component_models(b"Component ID\tXML Data\n-A1\t<pre> <data> <code")


# --- located errors ----------------------------------------------------------------------------------

SUB = (
    '<subitem name="{s}"><pos name="x">0.1</pos><pos name="y">0.2</pos><pos name="z">0.3</pos>'
    '<rot name="R">0</rot><rot name="P">0</rot><rot name="Y">0</rot></subitem>'
)


def _model(body: str, attrs: str = 'xdim="0.1" ydim="0.1" zdim="0.1"') -> str:
    return f'<data>\n<code name="M1" {attrs}>\n<couple name="1">\n{body}\n</couple>\n</code>\n</data>\n'


def _mounting(*models: tuple[str, ...]) -> str:
    """A file of models: each ``(model, child, ...)`` a <code> holding those children, a line each."""
    body = "".join(
        f"<code name='{model}'>\n"
        + "".join(f"<child name='{child}'>{SUB.format(s='relative')}</child>\n" for child in children)
        + "</code>\n"
        for model, *children in models
    )
    return f"<data>\n{body}</data>\n"


@pytest.mark.parametrize(
    ("text", "line", "reason", "found"),
    [
        (
            _model(SUB.format(s="screw").replace('<pos name="y">0.2</pos>', "")),
            4,
            "subitem 'screw' of couple '1' of model 'M1' lacks y",
            None,
        ),
        (
            _model(SUB.format(s="screw").replace('<rot name="P">0</rot><rot name="Y">0</rot>', "")),
            4,
            "subitem 'screw' of couple '1' of model 'M1' lacks P, Y",
            None,
        ),
        (_model(SUB.format(s="nut")), 4, "unknown subitem 'nut' in couple '1' of model 'M1'", "nut"),
        (
            _model(SUB.format(s="screw").replace("0.2", "0,2")),
            4,
            "not a finite number in <pos name='y'> of subitem 'screw' of couple '1' of model 'M1'",
            "0,2",
        ),
        (
            _model(SUB.format(s="hole").replace("0.3", "inf")),
            4,
            "not a finite number in <pos name='z'> of subitem 'hole' of couple '1' of model 'M1'",
            "inf",
        ),
        (
            _model(SUB.format(s="hole").replace("0.3", "1e999")),
            4,
            "not a finite number in <pos name='z'> of subitem 'hole' of couple '1' of model 'M1'",
            "1e999",
        ),
        (
            _model(SUB.format(s="hole").replace('name="z"', 'name="w"')),
            4,
            "unknown <pos> name 'w' in subitem 'hole' of couple '1' of model 'M1'",
            "w",
        ),
        (
            _model(SUB.format(s="screw") + SUB.format(s="screw")),
            4,
            "subitem 'screw' given twice in couple '1' of model 'M1'",
            None,
        ),
        (_model("", 'xdim="0.1" zdim="0.1"'), 2, "model 'M1' gives xdim, zdim but not ydim", None),
        (
            _model("", 'xdim="0.1" ydim="abc" zdim="0.1"'),
            2,
            "not a finite number in ydim of model 'M1'",
            "abc",
        ),
        (
            _model("", 'xdim="-0.1" ydim="0.1" zdim="0.1"'),
            2,
            "negative dimension of model 'M1'",
            "(-0.1, 0.1, 0.1)",
        ),
        (_model("", 'parent="rail"'), 2, "unknown parent role of model 'M1'", "rail"),
        (_model("<screw/>"), 4, "unexpected element <screw> inside <couple>", None),
        (
            _model(SUB.format(s="hole").replace('<rot name="R">0</rot>', '<rot name="P">0</rot>')),
            4,
            "<rot name='P'> of subitem 'hole' of couple '1' of model 'M1' given twice",
            None,
        ),
        (_model('<subitem name="screw"><pos name="x">0.1</subitem>'), 4, "malformed XML: ", None),
        ("<models>\n<code name='M1'/>\n</models>\n", 1, "the root element is not <data>", "<models>"),
        ("<data>\n</data>\n", 1, "no <code> model inside <data>", None),
        (
            "<data>\n<code name='M1'/>\n<code name='M2' commercial='M1'/>\n</data>\n",
            3,
            "model 'M1' given twice (first on line 2)",
            None,
        ),
        (
            "<data>\n<code name='M1'>\n<couple name='1'/>\n<couple name='1'/>\n</code>\n</data>\n",
            4,
            "couple '1' given twice in model 'M1' (first on line 3)",
            None,
        ),
        (
            "<data>\n<code name='M1'>\n<child name='C1'>\n</child>\n</code>\n</data>\n",
            3,
            "child 'C1' of model 'M1' has no relative placement",
            None,
        ),
        ("<data>\n<code commercial='M1'/>\n</data>\n", 2, "<code> without a name attribute", None),
        (_mounting(("M1", "M1")), 3, "model 'M1' is mounted in itself: M1 → M1", None),
        (
            _mounting(("M1", "M2"), ("M2", "M3"), ("M3", "M1")),
            9,
            "model 'M1' is mounted in itself: M1 → M2 → M3 → M1",
            None,
        ),
        (
            _mounting(("M1", "M2"), ("M2", "M3"), ("M3", "M2")),
            9,
            "model 'M2' is mounted in itself: M2 → M3 → M2",
            None,
        ),
    ],
    ids=[
        "missing-y",
        "missing-P-Y",
        "unknown-subitem",
        "decimal-comma",
        "inf",
        "overflow",
        "unknown-axis",
        "duplicate-subitem",
        "partial-dims",
        "bad-dim",
        "negative-dim",
        "bad-parent",
        "unknown-element",
        "duplicate-rot",
        "syntax",
        "wrong-root",
        "no-code",
        "duplicate-code-key",
        "duplicate-couple",
        "child-without-relative",
        "no-name",
        "mounted-in-itself",
        "mounted-in-a-child",
        "cycle-below-a-root",
    ],
)
def test_malformed_is_a_located_error(write, text: str, line: int, reason: str, found: str | None) -> None:
    path = write("bad.xml", text)
    with pytest.raises(IngestError) as info:
        read_component_models(path)
    err = info.value
    assert (err.path, err.line, err.found) == (str(path), line, found)
    assert err.reason.startswith(reason) if reason.endswith(": ") else err.reason == reason
    assert str(err).startswith(f"{path}:{line}: ")


@pytest.mark.parametrize(
    ("text", "line", "what"),
    [
        (
            '<?xml version="1.0"?>\n<!DOCTYPE data [\n<!ENTITY big "x">\n]>\n'
            '<data><code name="&big;"/></data>',
            2,
            "DOCTYPE",
        ),
        ('<?xml version="1.0"?>\n\n<!DOCTYPE data SYSTEM "http://example.org/x.dtd">\n<data/>', 3, "DOCTYPE"),
        ('<data>\n<!ENTITY x SYSTEM "file:///etc/passwd">\n</data>', 2, "ENTITY"),
    ],
    ids=["internal-entity", "external-dtd", "stray-entity"],
)
def test_doctype_and_entities_are_refused(write, text: str, line: int, what: str) -> None:
    with pytest.raises(IngestError) as info:
        read_component_models(write("evil.xml", text))
    assert info.value.line == line
    assert info.value.reason == f"<!{what}> is not allowed in component model XML"


def test_syntax_error_line_is_the_line_of_the_problem(write) -> None:
    text = _model(SUB.format(s="screw")).replace("</couple>", "</coupl>")
    with pytest.raises(IngestError) as info:
        read_component_models(write("bad.xml", text))
    assert info.value.line == 5
    assert "Opening and ending tag mismatch" in info.value.reason


def test_an_xml_declaration_naming_another_encoding_is_read(write) -> None:
    text = '<?xml version="1.0" encoding="ISO-8859-1"?>\n' + _model(SUB.format(s="hole"))
    (model,) = read_component_models(write("latin.xml", text))
    assert model.couples[0].hole is not None and model.couples[0].hole.xyz == (0.1, 0.2, 0.3)


def test_models_sharing_a_child_or_naming_an_unknown_one_are_not_a_cycle(write) -> None:
    text = _mounting(("M1", "M2", "M3"), ("M2", "M4"), ("M3", "M4"), ("M4", "OTHER-FILE"))
    models = {m.key: m for m in read_component_models(write("shared.xml", text))}
    assert [c.name for c in models["M1"].children] == ["M2", "M3"]
    assert [c.name for c in models["M4"].children] == ["OTHER-FILE"]
    assert [c.name for c in models["M2"].children] == ["M4"]


def test_a_long_chain_of_children_is_read_and_a_cycle_at_its_end_found(write) -> None:
    chain = [(f"M{i}", f"M{i + 1}") for i in range(3_000)]
    models = read_component_models(write("chain.xml", _mounting(*chain)))
    assert len(models) == 3_000
    with pytest.raises(IngestError) as info:
        read_component_models(write("loop.xml", _mounting(*chain, ("M3000", "M2990"))))
    assert info.value.reason.startswith("model 'M2990' is mounted in itself: M2990 → M2991 → ")
    assert info.value.line == 3 * 3_001


def test_a_cycle_in_a_fragment_is_located_in_the_whole_file() -> None:
    with pytest.raises(IngestError) as info:
        parse_models_fragment(_mounting(("M1", "M1")), "list.csv", 10)
    assert (info.value.line, info.value.reason) == (13, "model 'M1' is mounted in itself: M1 → M1")
