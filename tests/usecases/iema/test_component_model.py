"""The component model XML reader: Figure 4's model, older files, children, and located errors."""

from __future__ import annotations

import pytest

from cadkg.errors import IngestError
from cadkg.ingest.placement import Placement
from cadkg.registry import sniff_kind
from cadkg.usecases.iema.component_model import (
    ChildPlacement,
    ComponentModel,
    Couple,
    looks_like_component_models,
    parse_models_fragment,
    read_component_models,
)
from tests.conftest import ROOT

READERS = ROOT / "tests" / "data" / "readers"
SAMPLE = READERS / "models-sample.xml"
OLD = READERS / "models-old.xml"

ZERO = (0.0, 0.0, 0.0)


def _placement(xyz: tuple[float, ...], rpy: tuple[float, ...], line: int) -> Placement:
    # Angles of this format turn about the moving axes (docs/formats/component-model.md).
    return Placement(xyz, rpy, line, moving_axes=True)  # type: ignore[arg-type]


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
        screw=_placement(xyz=(0.0085, 0.009, 0.04496), rpy=ZERO, line=5),
        hole=_placement(xyz=ZERO, rpy=ZERO, line=6),
        line=4,
    )
    assert [c.name for c in model.couples] == ["1", "2"]
    assert model.couples[1].hole == _placement(xyz=(0.018, 0.0, 0.0), rpy=ZERO, line=10)


def test_child_placement(sample: dict[str, ComponentModel]) -> None:
    (child,) = sample["SIEMENS 5SL4202-8"].children
    assert child == ChildPlacement(
        name="6503373", relative=_placement(xyz=(0.0898, 0.0, 0.0), rpy=(0.0, 0.0, 1.5708), line=13), line=12
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
    assert a.screw == _placement(xyz=(0.0031, 0.0105, 0.0447), rpy=ZERO, line=27)
    assert a.hole is not None and a.hole.xyz == (0.0031, 0.0045, 0.0325)
    assert b.screw is not None and b.screw.xyz == (0.0031, 0.048, 0.0447)


def test_old_file_without_commercial_and_parent() -> None:
    first, second = read_component_models(OLD)
    assert (first.code, first.commercial, first.role, first.key) == ("6503372", None, None, "6503372")
    assert first.dimensions == (0.045, 0.09, 0.07)
    assert first.couples[1].screw == _placement(xyz=(0.0085, 0.0795, 0.0645), rpy=ZERO, line=8)
    assert (second.code, second.dimensions, second.children) == ("6013277", None, ())
    assert second.couples == (
        Couple("1", screw=None, hole=_placement(xyz=(0.003, 0.01, 0.03), rpy=ZERO, line=14), line=13),
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
        "decimal-comma",
        "inf",
        "overflow",
        "unknown-axis",
        "duplicate-subitem",
        "partial-dims",
        "bad-dim",
        "negative-dim",
        "duplicate-rot",
        "syntax",
        "wrong-root",
        "no-code",
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


# --- the shapes of the cell's real Component_tf.xml files -------------------------------------------


def _frame(tag: str, name: str, xyz: str, rpy: str = "0 0 0", end: str = "") -> str:
    x, y, z = xyz.split()
    r, p, w = rpy.split()
    return (
        f'<{tag} name="{name}">\n<pos name="x">{x}{end}</pos>\n<pos name="y">{y}</pos>\n'
        f'<pos name="z">{z}</pos>\n<rot name="R">{r}</rot>\n<rot name="P">{p}</rot>\n'
        f'<rot name="Y">{w}</rot>\n</{tag}>\n'
    )


# Commercial-keyed form: a breaker given twice (another size the second time), its auxiliary
# contact mounted with <child name="1">, and a terminal.
REAL = (
    "<data>\n"
    '<code name="ACME BREAKER" commercial="6100002" xdim="0.045" ydim="0.09" zdim="0.07">\n'
    + '<couple name="1">\n'
    + _frame("subitem", "screw", "0.005 0.08 0.07")
    + "</couple>\n"
    + "</code>\n"
    '<code name="ACME AUX-11" commercial="6100001" xdim="0.009" ydim="0.09" zdim="0.06" parent="child">\n'
    + '<child name="1">\n'
    + _frame("subitem", "relative", "0.045 0 0")
    + "</child>\n"
    + '<couple name="13">\n'
    + _frame("subitem", "screw", "0.0045 0.08 0.06")
    + _frame("subitem", "hole", "0.0045 0.075 0.05", "1.57 0 3.14")
    + "</couple>\n"
    + "</code>\n"
    '<code name="ACME BREAKER" commercial="6100002" xdim="0.045" ydim="0.0974" zdim="0.0969" parent="root">\n'
    + '<couple name="2">\n'
    + _frame("subitem", "screw", "0.005 0.01 0.07")
    + "</couple>\n"
    + _frame("item", "marker", "0.02 0.05 0.0969")
    + _frame("item", "visual", "0.02 0.05 0.1969")
    + _frame("item", "corner", "0 0 0.0969", "0 0 1.5708")
    + "<drawing/>\n<drawing/>\n"
    + "</code>\n</data>\n"
)


def test_items_duplicates_and_child_mounting_as_real_files_write_them(write) -> None:
    path = write("Component_tf.xml", REAL)
    with pytest.warns() as caught:
        models = {m.key: m for m in read_component_models(path)}
    messages = [str(w.message) for w in caught]
    # The later model counts, whole; the warning names both lines.
    assert (
        f"{path}:44: model '6100002' given twice, on lines 2 and 44; the later one (line 44) is read"
        in messages
    )
    # Unknown elements are skipped, one warning per name.
    assert [m for m in messages if "<drawing>" in m] == [
        f"{path}:79: unknown element <drawing> inside <code> skipped"
    ]
    assert list(models) == ["6100001", "6100002"]
    breaker = models["6100002"]
    assert breaker.dimensions == (0.045, 0.0974, 0.0969) and breaker.role == "root"
    assert [c.name for c in breaker.couples] == ["2"]
    assert [(i.name, i.placement.xyz) for i in breaker.items] == [
        ("marker", (0.02, 0.05, 0.0969)),
        ("visual", (0.02, 0.05, 0.1969)),
        ("corner", (0.0, 0.0, 0.0969)),
    ]
    aux = models["6100001"]
    # <child name="1"> of a child model is where it sits on its label's root item.
    assert aux.children == () and aux.mounting == _placement((0.045, 0.0, 0.0), ZERO, 16)


def test_rotations_turn_about_the_moving_axes(write, recwarn: pytest.WarningsRecorder) -> None:
    hole_frame = _frame("subitem", "hole", "0 0 0", "1.5707963267948966 0 1.5707963267948966")
    text = f'<data>\n<code name="M">\n<couple name="1">\n{hole_frame}</couple>\n</code>\n</data>\n'
    (model,) = read_component_models(write("m.xml", text))
    assert not recwarn.list
    hole = model.couples[0].hole
    assert hole is not None
    # Rx(π/2)·Rz(π/2): (0.5, -0.5, 0.5, 0.5); REP 103's Rz·Ry·Rx would give (0.5, 0.5, 0.5, 0.5).
    assert [round(v, 9) for v in hole.quaternion()] == [0.5, -0.5, 0.5, 0.5]


# Older name-keyed form: no commercial, no parent, numbers with line breaks, couple names with a
# line feed written as a character reference, items after the couples.
OLDER = (
    "<data>\n"
    '    <code name="3XY2011-1AB20">\n'
    '        <couple name="T1_H1">\n'
    + _frame("subitem", "hole", "0.004 0.01 0.05", end="\n\n")
    + _frame("subitem", "screw", "0.004 0.012 0.06")
    + "        </couple>\n"
    '        <couple name="15mm_hole1&#10;">\n'
    + _frame("subitem", "hole", "0.01 0.02 0.03")
    + "</couple>\n"
    + _frame("item", "marker", "0.035 0.05 0.08", "1.570796 3.141593 0", end="\n")
    + "    </code>\n</data>\n"
)


def test_older_name_keyed_form_with_items(write) -> None:
    (model,) = read_component_models(write("Component_tf.xml", OLDER))
    assert (model.key, model.commercial, model.role) == ("3XY2011-1AB20", None, None)
    assert [c.name for c in model.couples] == ["T1_H1", "15mm_hole1"]
    assert model.couples[0].hole is not None and model.couples[0].hole.xyz == (0.004, 0.01, 0.05)
    assert [(i.name, i.placement.rpy) for i in model.items] == [("marker", (1.570796, 3.141593, 0.0))]


def test_an_unknown_subitem_of_a_couple_is_its_screw(write) -> None:
    with pytest.warns(match="subitem 'nut' of a couple read as its screw"):
        (model,) = read_component_models(write("m.xml", _model(SUB.format(s="nut"))))
    assert model.couples[0].screw is not None and model.couples[0].screw.xyz == (0.1, 0.2, 0.3)


def test_a_couple_given_twice_keeps_the_later(write) -> None:
    text = _model(SUB.format(s="hole")).replace(
        "</code>", f'<couple name="1">{SUB.format(s="screw")}</couple>\n</code>'
    )
    with pytest.warns(match="couple '1' given twice in model 'M1', on lines 3 and 6; the later one is read"):
        (model,) = read_component_models(write("m.xml", text))
    assert [(c.screw is not None, c.hole is not None) for c in model.couples] == [(True, False)]
