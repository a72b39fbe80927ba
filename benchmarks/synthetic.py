"""A synthetic switchgear cabinet of any size, in the real IEMA export formats.

``write_cell(directory, wires)`` writes three files, shaped like
``examples/iema-switchgear`` before it took the real exports' shapes
(``tests/data/iema-old-forms``):

* ``ids.wri``: the WRI ID table (tab separated, no header, CRLF), 1-3 CAD items
  per component plus the wiring ducts ``U1``..``U20``;
* ``lista-cablaggio.csv``: the EPLAN "Lista cablaggio" (4 preamble rows, the
  15-column header, tab separated, CRLF, decimal commas and units, duct paths);
* ``manifest.toml``: the cell manifest listing both, with one static frame.

The cabinet has about ``wires / 4`` components (fuses ``F``, contactors ``Q``,
relays ``K`` and terminal blocks ``X``) of 8 pins each, so every pin carries about
one wire end. Terminal block pins are ``:TERMINAL:LEVEL`` (``=-X0123.4:2:a``).
Wires go from the first four pins of a component to the last four pins of a
component a few positions further on, the way a feeder runs from one sheet to
the next; when those pins are taken the wire shares one (a daisy chain, as the
real ``0V`` wires do). Wire numbers are ``PAGE.NN`` and unique.

The output depends only on ``wires`` and ``seed``. A million wires take a few seconds.

``write_cabinet(directory, wires)`` writes a complete cabinet instead, with every
file kind of ``tests/data/cells/mini``: the WRI table, component models XML,
a terminal schema CSV, an X3D scene (DIN rails as DEF'd Transforms with the
components nested in them, wiring ducts), the connection list with duct paths,
an assignments CSV and a manifest with ``[derive]`` settings. It has about
``wires / 3`` components sending 3 wires each, 20 to a rail (see
``write_cabinet_files`` for what the generator knows of the result).

Usage: ``python benchmarks/synthetic.py OUTDIR --wires 10000 [--seed 0] [--cabinet]``
"""

from __future__ import annotations

import argparse
import random
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

__all__ = [
    "CabinetFiles",
    "CellFiles",
    "Component",
    "build_components",
    "write_cabinet",
    "write_cabinet_files",
    "write_cell",
]

EOL = "\r\n"
COLUMNS = 15
DUCTS = 20
COMPONENTS_PER_PAGE = 6
WIRES_PER_COMPONENT = 4  # wires leaving a component; as many arrive: 8 pin ends
MAX_HOP = 40  # how many components further on a wire may end
HEADER = (
    "N. Pagina",
    "Zona",
    "Componente:pin",
    "N. Pagina",
    "Zona",
    "Componente:pin",
    "Numero filo",
    "Sezione",
    "Colore",
    "Tipo pot.",
    "Nome pot.",
    "L filo (m)",
    "Traccia collegamenti",
    "Terminazione Origine",
    "Terminazione Destinazione",
)
# Kind of component → (share of the cabinet, its 8 pins: 4 outgoing then 4 incoming).
KINDS: dict[str, tuple[int, tuple[str, ...]]] = {
    "F": (15, ("2", "4", "6", "14", "1", "3", "5", "13")),
    "Q": (20, ("2", "4", "6", "A2", "1", "3", "5", "A1")),
    "K": (35, ("11", "14", "21", "24", "A1", "A2", "12", "22")),
    "X": (30, ("1:a", "2:a", "3:a", "4:a", "1:b", "2:b", "3:b", "4:b")),
}
TERMINATION = {"X": "ELETTROSALDATO_molla", "F": "PUNTALINO_vite", "K": "PUNTALINO_vite"}
# (section, colour, potential type, potential name): weighted the way a cabinet is.
CIRCUITS: tuple[tuple[str, str, str, str, int], ...] = (
    ("0,75 mm²", "BU", "+", "24V", 30),
    ("0,75 mm²", "BU", "-", "0V", 12),
    ("0,75 mm²", "WH", "+", "24V", 8),
    ("0,75 mm²", "GY", "+", "24V", 4),
    ("0,75 mm²", "BN", "+", "24V", 4),
    ("1 mm²", "BU", "-", "0V", 6),
    ("1,5 mm²", "BK", "L", "L1", 6),
    ("1,5 mm²", "BK", "L", "L2", 6),
    ("1,5 mm²", "BK", "L", "L3", 6),
    ("1,5 mm²", "BU", "N", "N", 4),
    ("1,5 mm²", "GNYE", "PE", "PE", 4),
    ("2,5 mm²", "BK", "L", "L1", 3),
    ("2,5 mm²", "RD", "L", "L1", 1),
    ("2,5 mm²", "GNYE", "PE", "PE", 2),
)
COMMERCIAL_CODES: dict[str, tuple[str, ...]] = {
    "F": ("6503372", "6503373", "6503110", "6503050"),
    "Q": ("SIE.3RT2015-1BB41", "6503531", "6100231", "6100240"),
    "K": ("PILZ.750104", "6402292", "6158742", "6153805"),
    "X": ("6013280", "6013281", "6013285", "6013290", "6013298"),
}


@dataclass(frozen=True, slots=True)
class Component:
    """One device or terminal block of the synthetic cabinet."""

    kind: str
    page: int
    label: str  # bare device tag, e.g. K0123.4
    wri_label: str  # as the WRI table writes it: =-K0123.4, -K0123.4 or K0123.4


@dataclass(frozen=True, slots=True)
class CellFiles:
    """The files of a synthetic cell."""

    manifest: Path
    wri: Path
    connection_list: Path


def _pick_kinds(rng: random.Random, count: int) -> list[str]:
    names = list(KINDS)
    return rng.choices(names, weights=[KINDS[k][0] for k in names], k=count)


def build_components(count: int, rng: random.Random) -> list[Component]:
    """``count`` components, 6 to a drawing page, labelled ``KIND PAGE . POSITION``."""
    prefixes = ("=-", "-", "")
    components = []
    for index, kind in enumerate(_pick_kinds(rng, count)):
        page = 10 + index // COMPONENTS_PER_PAGE
        label = f"{kind}{page:04d}.{index % COMPONENTS_PER_PAGE + 1}"
        components.append(Component(kind, page, label, prefixes[index % 3] + label))
    return components


def _wri_lines(components: Sequence[Component], rng: random.Random) -> Iterator[str]:
    item = 0
    for component, items in zip(components, rng.choices((1, 2, 3), k=len(components)), strict=True):
        codes = COMMERCIAL_CODES[component.kind]
        for _ in range(items):
            item += 1
            code = codes[rng.randrange(len(codes))] if item % 29 else ""
            yield f"ID{item:06d}\t{component.wri_label}\t{code}{EOL}"
    for duct in range(1, DUCTS + 1):
        item += 1
        yield f"ID{item:06d}\t=-U{duct}\t{'6300425' if duct % 2 else '6300440'}{EOL}"


def _duct_paths(rng: random.Random, count: int = 400) -> list[str]:
    """A pool of routes through 1-3 distinct ducts, written ``=-U2;=-U5;=-U3``."""
    paths = []
    for _ in range(count):
        ducts = rng.sample(range(1, DUCTS + 1), rng.choice((1, 1, 2, 3)))
        paths.append(";".join(f"=-U{d}" for d in ducts))
    return paths


def _lengths(rng: random.Random, count: int = 2000) -> list[str]:
    """A pool of wire lengths between 0,150 m and 2,500 m, written ``0,746 m``."""
    mm = (rng.randint(150, 2500) for _ in range(count))
    return [f"{v // 1000},{v % 1000:03d} m" for v in mm]


def _preamble() -> Iterator[str]:
    pad = "\t" * (COLUMNS - 2)
    yield f"Nome Progetto:\tSYNTH_QE{pad}{EOL}"
    yield f"commessa:\t99-0001{pad}{EOL}"
    yield "\t" * (COLUMNS - 1) + EOL
    yield "ORIGINE\t\t\tDESTINAZIONE" + "\t" * (COLUMNS - 4) + EOL
    yield "\t".join(HEADER) + EOL


def _wire_lines(components: Sequence[Component], wires: int, rng: random.Random) -> Iterator[str]:
    count = len(components)
    incoming = [0] * count  # incoming pins taken per component
    hops = [rng.randint(1, MAX_HOP) for _ in range(1024)]
    circuits = rng.choices(range(len(CIRCUITS)), weights=[c[4] for c in CIRCUITS], k=wires)
    paths, lengths = _duct_paths(rng), _lengths(rng)
    choose = rng.getrandbits
    for number in range(wires):
        a = number // WIRES_PER_COMPONENT
        src = components[a]
        b = (a + hops[choose(10)]) % count
        dst = components[b]
        slot = incoming[b]
        if slot < 4:
            incoming[b] = slot + 1
        else:
            slot = choose(2)  # all taken: share one, a daisy chain
        src_pin = KINDS[src.kind][1][number % WIRES_PER_COMPONENT]
        dst_pin = KINDS[dst.kind][1][4 + slot]
        section, colour, ptype, pname, _ = CIRCUITS[circuits[number]]
        yield (
            f"+{src.page:04d}/1.{number % 3 + 1}\tQ\t=-{src.label}:{src_pin}\t"
            f"+{dst.page:04d}/1.{slot % 3 + 1}\tQ\t=-{dst.label}:{dst_pin}\t"
            f"{src.page:04d}.{number % (WIRES_PER_COMPONENT * COMPONENTS_PER_PAGE) + 1:02d}\t"
            f"{section}\t{colour}\t{ptype}\t{pname}\t{lengths[choose(11) % len(lengths)]}\t"
            f"{paths[choose(16) % len(paths)]}\t"
            f"{TERMINATION.get(src.kind, 'CAPICORDA_vite')}\t"
            f"{TERMINATION.get(dst.kind, 'PUNTALINO_vite')}{EOL}"
        )


def _write_lines(path: Path, lines: Iterator[str], chunk: int = 20000) -> None:
    with path.open("w", encoding="utf-8", newline="") as handle:
        buffer: list[str] = []
        for line in lines:
            buffer.append(line)
            if len(buffer) >= chunk:
                handle.write("".join(buffer))
                buffer.clear()
        handle.write("".join(buffer))


def _manifest_text(wires: int, seed: int) -> str:
    return (
        "[cell]\n"
        f'name = "Synthetic cabinet, {wires} wires (seed {seed})"\n'
        'profile = "iema"\n'
        'base_iri = "https://example.org/cell/synthetic/"\n\n'
        '[[source]]\npath = "ids.wri"\nkind = "wri"\n\n'
        '[[source]]\npath = "lista-cablaggio.csv"\nkind = "connection-list"\n\n'
        '[[frame]]\nparent = "world"\nchild = "cabinet"\n'
        "xyz = [1.2, 0.0, 0.0]\nrpy = [0.0, 0.0, 1.5707963267948966]\n"
    )


def write_cell_files(directory: str | Path, wires: int, seed: int = 0) -> CellFiles:
    """Write the synthetic cell of ``wires`` wires into ``directory`` (see the module doc)."""
    if wires < 1:
        raise ValueError("a cell needs at least one wire")
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    rng = random.Random(seed)
    components = build_components(-(-wires // WIRES_PER_COMPONENT), rng)
    files = CellFiles(
        manifest=directory / "manifest.toml",
        wri=directory / "ids.wri",
        connection_list=directory / "lista-cablaggio.csv",
    )
    _write_lines(files.wri, _wri_lines(components, rng))
    rows = _wire_lines(components, wires, rng)
    _write_lines(files.connection_list, _chain(_preamble(), rows))
    files.manifest.write_text(_manifest_text(wires, seed), encoding="utf-8")
    return files


def write_cell(directory: str | Path, wires: int, seed: int = 0) -> Path:
    """Write a synthetic cell of ``wires`` wires; returns the path of its manifest."""
    return write_cell_files(directory, wires, seed).manifest


# -- a complete cabinet: models, terminal schema, scene, connection list, assignments ---------

CABINET_WIRES_PER_COMPONENT = 3  # wires leaving each component, one from each of its "out" pins
COMPONENTS_PER_RAIL = 20
RAILS_PER_ROW = 4
RAIL_LENGTH = 1.25  # m; 20 of the widest components with their spacing fit on it
RAIL_PITCH = 1.45  # m from the start of a rail to the start of the next one in its row
ROW_PITCH = 0.3  # m between two rows of rails
RAIL_FRONT = 0.0075  # z of the rail's front face, where the components sit
SPACING = 0.006  # m left free between two components on a rail
TERMINALS_PER_BLOCK = 4  # terminals 1..4 with levels a and b, then an end plate
EXTERNAL_EVERY = 499  # wires 7, 506, 1005 ... end on a motor that no cabinet file describes
EXTERNAL_OFFSET = 7
EXTERNAL_PINS = ("U1", "V1", "W1")
RAIL_MODEL = "DIN35"
DUCT_MODEL = "DUCT40x60"
# Kind → (the 3 pins its wires leave from, the 3 pins wires arrive at; more arrivals share one).
CABINET_PINS: dict[str, tuple[tuple[str, ...], tuple[str, ...]]] = {
    "F": (("2", "4", "6"), ("1", "3", "5")),
    "Q": (("2", "4", "14"), ("1", "A1", "13")),
    "K": (("14", "24", "12"), ("A1", "11", "21")),
    "X": (("1:b", "2:b", "3:b"), ("1:a", "2:a", "3:a")),
}


@dataclass(frozen=True, slots=True)
class PartModel:
    """One ``<code>`` of the component models: size, role, pins and the model mounted beside it."""

    code: str
    role: str | None  # root, child, terminal; None for rails and ducts
    size: tuple[float, float, float]
    pins: tuple[tuple[str, float, float], ...] = ()  # (couple, x, y of the screw)
    child: str | None = None


@dataclass(frozen=True, slots=True)
class CabinetFiles:
    """The files of a synthetic cabinet and what the generator put in them."""

    manifest: Path
    files: tuple[Path, ...]
    components: int  # devices and terminal blocks, without rails and ducts
    rails: dict[str, tuple[str, ...]]  # rail label → the labels on it, left to right
    terminal_blocks: tuple[str, ...]
    ducts: tuple[str, ...]
    missing_ends: frozenset[str]  # wire ends on devices no file describes: LABEL:PIN
    human_components: tuple[str, ...]
    human_wires: tuple[str, ...]  # wire numbers assigned to a person
    human_operations: tuple[int, ...]  # list positions assigned to a person


def _pin_rows(width: float, *rows: tuple[float, tuple[str, ...]]) -> tuple[tuple[str, float, float], ...]:
    """Pins spread evenly across the width, one row per (height, names)."""
    return tuple(
        (name, width * (k + 0.5) / len(names), y) for y, names in rows for k, name in enumerate(names)
    )


def cabinet_models() -> dict[str, PartModel]:
    """The 30 commercial models of the cabinet, by code."""
    models: list[PartModel] = []
    fuses = [(0.027, 0.08, 0.065), (0.027, 0.085, 0.068), (0.03, 0.08, 0.07)]
    fuses += [(0.032, 0.09, 0.07), (0.036, 0.09, 0.075), (0.036, 0.085, 0.072)]
    for n, (w, h, d) in enumerate(fuses, 1):
        pins = _pin_rows(w, (h - 0.01, ("1", "3", "5")), (0.01, ("2", "4", "6")))
        models.append(PartModel(f"FUSE3P-{n:02d}", "root", (w, h, d), pins))
    for n, (w, h, d) in enumerate(((0.009, 0.08, 0.06), (0.01, 0.085, 0.065)), 1):
        models.append(
            PartModel(f"AUX-{n:02d}", "child", (w, h, d), _pin_rows(w, (h - 0.01, ("13",)), (0.01, ("14",))))
        )
    contactors = [(0.036, 0.08, 0.06), (0.036, 0.085, 0.065), (0.04, 0.085, 0.065)]
    contactors += [(0.04, 0.09, 0.07), (0.045, 0.09, 0.07), (0.045, 0.095, 0.075)]
    for n, (w, h, d) in enumerate(contactors, 1):
        pins = _pin_rows(w, (h - 0.01, ("1", "3", "5", "A1")), (0.01, ("2", "4", "6", "A2")))
        models.append(PartModel(f"CONT-{n:02d}", "root", (w, h, d), pins, f"AUX-{(n - 1) % 2 + 1:02d}"))
    for n, w in enumerate((0.0125, 0.0125, 0.015, 0.0155, 0.0175, 0.018, 0.0225, 0.0225), 1):
        h, d = 0.08 + 0.005 * (n % 3), 0.06 + 0.005 * (n % 2)
        pins = _pin_rows(w, (h - 0.01, ("A1", "11", "21")), (h / 2, ("12", "22")), (0.01, ("A2", "14", "24")))
        models.append(PartModel(f"RELAY-{n:02d}", "root", (w, h, d), pins))
    for n, (w, h, d) in enumerate(((0.0051, 0.05, 0.04), (0.0052, 0.055, 0.042)), 1):
        models.append(
            PartModel(
                f"TERM-{n:02d}", "terminal", (w, h, d), _pin_rows(w, (h - 0.01, ("a",)), (0.01, ("b",)))
            )
        )
    for n, (w, h, d) in enumerate(((0.0061, 0.06, 0.045), (0.0062, 0.058, 0.044)), 3):
        models.append(
            PartModel(
                f"TERM-{n:02d}", "terminal", (w, h, d), _pin_rows(w, (h - 0.01, ("a",)), (0.01, ("b",)))
            )
        )
    models.append(PartModel("ENDPLATE-01", "terminal", (0.0015, 0.05, 0.04)))
    models.append(PartModel("ENDPLATE-02", "terminal", (0.002, 0.06, 0.045)))
    models.append(PartModel(RAIL_MODEL, None, (RAIL_LENGTH, 0.035, 0.0075)))
    models.append(PartModel(DUCT_MODEL, None, (1.0, 0.04, 0.06)))
    return {m.code: m for m in models}


def _num(value: float) -> str:
    return f"{value:.6g}"


def _subitem(name: str, x: float, y: float, z: float) -> str:
    return (
        f'<subitem name="{name}"><pos name="x">{_num(x)}</pos><pos name="y">{_num(y)}</pos>'
        f'<pos name="z">{_num(z)}</pos><rot name="R">0</rot><rot name="P">0</rot><rot name="Y">0</rot>'
        "</subitem>"
    )


def _models_xml(models: dict[str, PartModel]) -> Iterator[str]:
    yield '<?xml version="1.0" encoding="UTF-8"?>\n<data>\n'
    for m in models.values():
        w, h, d = m.size
        role = f' parent="{m.role}"' if m.role else ""
        dims = f'xdim="{_num(w)}" ydim="{_num(h)}" zdim="{_num(d)}"'
        head = f'  <code name="{m.code}" commercial="{m.code}" {dims}{role}'
        if not m.pins and m.child is None:
            yield head + "/>\n"
            continue
        yield head + ">\n"
        for name, x, y in m.pins:
            # The screw faces the front; the hole is 1 cm deeper, 5 mm towards the nearer edge.
            hole_y = y + 0.005 if y > h / 2 else y - 0.005
            yield (
                f'    <couple name="{name}">{_subitem("screw", x, y, d)}'
                f"{_subitem('hole', x, hole_y, d - 0.01)}</couple>\n"
            )
        if m.child is not None:
            yield f'    <child name="{m.child}">{_subitem("relative", w, 0.0, 0.0)}</child>\n'
        yield "  </code>\n"
    yield "</data>\n"


def _shape(size: tuple[float, float, float], centre_y: float | None = None) -> str:
    """A box of ``size`` from the item's origin (centred on it in y when ``centre_y`` is 0)."""
    w, h, d = size
    y = h / 2 if centre_y is None else centre_y
    return (
        f'<Transform translation="{_num(w / 2)} {_num(y)} {_num(d / 2)}"><Shape>'
        f'<Box size="{_num(w)} {_num(h)} {_num(d)}"/></Shape></Transform>'
    )


@dataclass
class _Layout:
    """Where everything goes: CAD items, models, rails and ducts of the cabinet."""

    items: list[tuple[str, ...]]  # per component, its CAD IDs: root first, or in block order
    codes: list[tuple[str, ...]]  # per component, the model of each item
    x: list[float]  # per component, where it starts along its rail
    rails: int
    rows: int
    columns: int
    first_rail_item: int  # number of the CAD ID of the first rail; ducts follow the rails

    def rail_id(self, rail: int) -> str:
        return f"ID{self.first_rail_item + rail:06d}"

    def duct_id(self, duct: int) -> str:
        return f"ID{self.first_rail_item + self.rails + duct:06d}"

    @property
    def ducts(self) -> int:
        return self.rows + self.columns


def _layout(components: Sequence[Component], models: dict[str, PartModel], rng: random.Random) -> _Layout:
    by_kind: dict[str, list[str]] = {"F": [], "Q": [], "K": [], "X": []}
    for code in models:
        kind = {"FUSE3P": "F", "CONT": "Q", "RELAY": "K", "TERM": "X"}.get(code.split("-")[0])
        if kind is not None:
            by_kind[kind].append(code)
    plates = [c for c in models if c.startswith("ENDPLATE")]
    items: list[tuple[str, ...]] = []
    codes: list[tuple[str, ...]] = []
    xs: list[float] = []
    number = 0
    cursor = 0.0
    for index, component in enumerate(components):
        choices = by_kind[component.kind]
        code = choices[rng.randrange(len(choices))]
        if component.kind == "X":
            chosen = (code,) * TERMINALS_PER_BLOCK + (plates[rng.randrange(len(plates))],)
        elif component.kind == "Q":
            chosen = (code, models[code].child or "")
        else:
            chosen = (code,)
        if index % COMPONENTS_PER_RAIL == 0:
            cursor = 0.03
        xs.append(cursor)
        cursor += sum(models[c].size[0] for c in chosen) + SPACING
        items.append(tuple(f"ID{number + k + 1:06d}" for k in range(len(chosen))))
        codes.append(chosen)
        number += len(chosen)
    rails = max(1, -(-len(components) // COMPONENTS_PER_RAIL))
    return _Layout(items, codes, xs, rails, -(-rails // RAILS_PER_ROW), min(RAILS_PER_ROW, rails), number + 1)


def _cabinet_wri_lines(components: Sequence[Component], layout: _Layout) -> Iterator[str]:
    for component, ids, codes in zip(components, layout.items, layout.codes, strict=True):
        for cad_id, code in zip(ids, codes, strict=True):
            yield f"{cad_id}\t{component.wri_label}\t{code}{EOL}"
    for rail in range(layout.rails):
        yield f"{layout.rail_id(rail)}\t=-RAIL{rail + 1:04d}\t{RAIL_MODEL}{EOL}"
    for duct in range(layout.ducts):
        yield f"{layout.duct_id(duct)}\t=-U{duct + 1}\t{DUCT_MODEL}{EOL}"


def _terminal_schema_lines(components: Sequence[Component], layout: _Layout) -> Iterator[str]:
    yield "Terminal block,Position,Terminal,Cad ID,Commercial,Levels\n"
    for component, ids, codes in zip(components, layout.items, layout.codes, strict=True):
        if component.kind != "X":
            continue
        for position, (cad_id, code) in enumerate(zip(ids, codes, strict=True), 1):
            if position <= TERMINALS_PER_BLOCK:
                yield f"{component.label},{position},{position},{cad_id},{code},a;b\n"
            else:
                yield f"{component.label},{position},,{cad_id},{code},\n"


def _rail_origin(rail: int) -> tuple[float, float]:
    return 0.1 + (rail % RAILS_PER_ROW) * RAIL_PITCH, -(rail // RAILS_PER_ROW) * ROW_PITCH


def _scene_lines(
    components: Sequence[Component], layout: _Layout, models: dict[str, PartModel], turned_every: int = 0
) -> Iterator[str]:
    yield (
        '<?xml version="1.0" encoding="UTF-8"?>\n'
        '<!DOCTYPE X3D PUBLIC "ISO//Web3D//DTD X3D 3.3//EN" '
        '"http://www.web3d.org/specifications/x3d-3.3.dtd">\n'
        '<X3D profile="Interchange" version="3.3">\n  <Scene>\n'
    )
    rail_box = _shape(models[RAIL_MODEL].size, centre_y=0.0)
    for index, component in enumerate(components):
        rail = index // COMPONENTS_PER_RAIL
        if index % COMPONENTS_PER_RAIL == 0:
            if index:
                yield "    </Transform>\n"
            x0, y0 = _rail_origin(rail)
            yield (
                f'    <Transform DEF="{layout.rail_id(rail)}" translation="{_num(x0)} {_num(y0)} 0">'
                f"{rail_box}\n"
            )
        ids, codes, x = layout.items[index], layout.codes[index], layout.x[index]
        if component.kind == "X":
            for cad_id, code in zip(ids, codes, strict=True):
                size = models[code].size
                yield (
                    f'      <Transform DEF="{cad_id}" translation="{_num(x)} 0 {RAIL_FRONT}">'
                    f"{_shape(size)}</Transform>\n"
                )
                x += size[0]
            continue
        root = models[codes[0]].size
        place = f'translation="{_num(x)} 0 {RAIL_FRONT}"'
        if turned_every and component.kind == "K" and index % turned_every == 0:
            # Mounted upside down: turned half a turn about the plate's normal, same footprint.
            place = (
                f'translation="{_num(x + root[0])} {_num(root[1])} {RAIL_FRONT}" rotation="0 0 1 3.14159265"'
            )
        line = f'      <Transform DEF="{ids[0]}" {place}>{_shape(root)}'
        if component.kind == "Q" and index % 2 == 0:
            # Every other contactor has its auxiliary contact in the scene; the others get it
            # from the model's <child> placement.
            aux = models[codes[1]].size
            line += f'<Transform DEF="{ids[1]}" translation="{_num(root[0])} 0 0">{_shape(aux)}</Transform>'
        yield line + "</Transform>\n"
    if components:
        yield "    </Transform>\n"
    width = RAILS_PER_ROW * RAIL_PITCH
    for row in range(layout.rows):  # a horizontal duct above each row of rails
        y = -row * ROW_PITCH + 0.14
        yield (
            f'    <Transform DEF="{layout.duct_id(row)}" translation="0.05 {_num(y)} 0">'
            f"{_shape((width, 0.04, 0.06))}</Transform>\n"
        )
    height = layout.rows * ROW_PITCH + 0.1
    for column in range(layout.columns):  # a vertical duct left of each column of rails
        x = 0.1 + column * RAIL_PITCH - 0.05
        yield (
            f'    <Transform DEF="{layout.duct_id(layout.rows + column)}" '
            f'translation="{_num(x)} {_num(0.18 - height)} 0">{_shape((0.04, height, 0.06))}</Transform>\n'
        )
    yield "  </Scene>\n</X3D>\n"


def _wire_number(components: Sequence[Component], number: int) -> str:
    page = components[number // CABINET_WIRES_PER_COMPONENT].page
    return f"{page:04d}.{number % (CABINET_WIRES_PER_COMPONENT * COMPONENTS_PER_PAGE) + 1:02d}"


def _external_end(number: int) -> str | None:
    """``M0001.1:U1`` for the wires that leave the cabinet, else None."""
    if number % EXTERNAL_EVERY != EXTERNAL_OFFSET:
        return None
    index = number // EXTERNAL_EVERY
    return f"M{index + 1:04d}.1:{EXTERNAL_PINS[index % len(EXTERNAL_PINS)]}"


def _duct_path(a: int, b: int, layout: _Layout) -> str:
    """Through the duct above the rail row of ``a``, down the column duct, along the row of ``b``."""
    rail_a, rail_b = a // COMPONENTS_PER_RAIL, b // COMPONENTS_PER_RAIL
    row_a, row_b = rail_a // RAILS_PER_ROW, rail_b // RAILS_PER_ROW
    if rail_a == rail_b and abs(b - a) <= 2:
        return ""  # a short jumper between neighbours
    if row_a == row_b:
        return f"=-U{row_a + 1}"
    return f"=-U{row_a + 1};=-U{layout.rows + rail_a % RAILS_PER_ROW + 1};=-U{row_b + 1}"


def _cabinet_wire_lines(
    components: Sequence[Component], layout: _Layout, wires: int, rng: random.Random
) -> Iterator[str]:
    count = len(components)
    incoming = [0] * count  # arrival pins taken per component
    hops = [rng.randint(1, MAX_HOP) for _ in range(1024)]
    circuits = rng.choices(range(len(CIRCUITS)), weights=[c[4] for c in CIRCUITS], k=wires)
    lengths = _lengths(rng)
    choose = rng.getrandbits
    for number in range(wires):
        a = number // CABINET_WIRES_PER_COMPONENT
        src = components[a]
        src_pin = CABINET_PINS[src.kind][0][number % CABINET_WIRES_PER_COMPONENT]
        external = _external_end(number)
        if external is not None:
            dst_page, slot, dst_ref, dst_term = src.page, 0, f"=-{external}", "CAPICORDA_vite"
            path = f"=-U{a // COMPONENTS_PER_RAIL // RAILS_PER_ROW + 1}"
        else:
            b = (a + hops[choose(10)]) % count
            dst = components[b]
            slot = incoming[b]
            if slot < 3:
                incoming[b] = slot + 1
            else:
                slot = choose(16) % 3  # all taken: share one, a daisy chain
            dst_page, dst_term = dst.page, TERMINATION.get(dst.kind, "PUNTALINO_vite")
            dst_ref = f"=-{dst.label}:{CABINET_PINS[dst.kind][1][slot]}"
            path = _duct_path(a, b, layout)
        section, colour, ptype, pname, _ = CIRCUITS[circuits[number]]
        yield (
            f"+{src.page:04d}/1.{number % 3 + 1}\tQ\t=-{src.label}:{src_pin}\t"
            f"+{dst_page:04d}/1.{slot % 3 + 1}\tQ\t{dst_ref}\t"
            f"{_wire_number(components, number)}\t"
            f"{section}\t{colour}\t{ptype}\t{pname}\t{lengths[choose(11) % len(lengths)]}\t{path}\t"
            f"{TERMINATION.get(src.kind, 'PUNTALINO_vite')}\t{dst_term}{EOL}"
        )


def _cabinet_manifest_text(wires: int, seed: int) -> str:
    sources = (
        ("ids.wri", "wri"),
        ("models.xml", "component-model"),
        ("terminals.csv", "terminal-schema"),
        ("scene.x3d", None),
        ("lista-cablaggio.csv", "connection-list"),
        ("assignments.csv", "assignments"),
    )
    text = (
        "[cell]\n"
        f'name = "Synthetic cabinet, {wires} wires (seed {seed})"\n'
        'profile = "iema"\n'
        'base_iri = "https://example.org/cell/synthetic-cabinet/"\n'
    )
    for path, kind in sources:
        text += f'\n[[source]]\npath = "{path}"\n'
        text += f'kind = "{kind}"\n' if kind else 'frame = "cabinet"\n'
    return text + (
        "\n[derive]\napproach_distance = 0.12\n"
        'rail_pattern = "^RAIL"\ncluster_tolerance = 0.003\n\n'
        '[[frame]]\nparent = "world"\nchild = "cabinet"\n'
        "xyz = [1.2, 0.0, 0.0]\nrpy = [0.0, 0.0, 1.5707963267948966]\n"
    )


def write_cabinet_files(
    directory: str | Path, wires: int, seed: int = 0, turned_every: int = 0
) -> CabinetFiles:
    """Write a complete synthetic cabinet of ``wires`` wires into ``directory``.

    About ``wires / 3`` components (the kinds and labels of :func:`build_components`),
    each sending 3 wires from its "out" pins to the "in" pins of a component 1-40
    positions further on (a daisy chain once those are taken), 20 components to a
    DIN rail, 4 rails to a row, a horizontal duct above each row and a vertical duct
    beside each column. Every 499th wire (from the 8th) ends on a motor outside the
    cabinet that no file describes: those ends, and only those, lack pin data. With
    ``turned_every`` N, every relay whose index is a multiple of N is mounted upside down.
    """
    if wires < 1:
        raise ValueError("a cabinet needs at least one wire")
    directory = Path(directory)
    directory.mkdir(parents=True, exist_ok=True)
    rng = random.Random(seed)
    components = build_components(-(-wires // CABINET_WIRES_PER_COMPONENT), rng)
    models = cabinet_models()
    layout = _layout(components, models, rng)
    paths = {name: directory / name for name in ("ids.wri", "models.xml", "terminals.csv", "scene.x3d")}
    paths["lista-cablaggio.csv"] = directory / "lista-cablaggio.csv"
    paths["assignments.csv"] = directory / "assignments.csv"
    _write_lines(paths["ids.wri"], _cabinet_wri_lines(components, layout))
    _write_lines(paths["models.xml"], _models_xml(models))
    _write_lines(paths["terminals.csv"], _terminal_schema_lines(components, layout))
    _write_lines(paths["scene.x3d"], _scene_lines(components, layout, models, turned_every))
    rows = _cabinet_wire_lines(components, layout, wires, rng)
    _write_lines(paths["lista-cablaggio.csv"], _chain(_preamble(), rows))

    relays = [c.label for c in components if c.kind == "K"]
    human_components = (relays[0] if relays else components[0].label,)
    human_wires = tuple(dict.fromkeys(_wire_number(components, n) for n in {1 % wires, wires // 2}))
    human_operations = (min(4, wires),)
    assignments = ["kind,id,performer"]
    assignments += [f"wire,{number},human" for number in human_wires]
    assignments += [f"component,{label},human" for label in human_components]
    assignments += [f"operation,{position},human" for position in human_operations]
    paths["assignments.csv"].write_text("\n".join(assignments) + "\n", encoding="utf-8")
    manifest = directory / "manifest.toml"
    manifest.write_text(_cabinet_manifest_text(wires, seed), encoding="utf-8")

    rails: dict[str, list[str]] = {}
    for index, component in enumerate(components):
        rails.setdefault(f"RAIL{index // COMPONENTS_PER_RAIL + 1:04d}", []).append(component.label)
    missing = {end for n in range(EXTERNAL_OFFSET, wires, EXTERNAL_EVERY) if (end := _external_end(n))}
    return CabinetFiles(
        manifest=manifest,
        files=tuple(paths.values()),
        components=len(components),
        rails={label: tuple(labels) for label, labels in rails.items()},
        terminal_blocks=tuple(c.label for c in components if c.kind == "X"),
        ducts=tuple(f"U{d + 1}" for d in range(layout.ducts)),
        missing_ends=frozenset(missing),
        human_components=human_components,
        human_wires=human_wires,
        human_operations=human_operations,
    )


def write_cabinet(directory: str | Path, wires: int, seed: int = 0, turned_every: int = 0) -> Path:
    """Write a complete synthetic cabinet of ``wires`` wires; returns the path of its manifest."""
    return write_cabinet_files(directory, wires, seed, turned_every).manifest


def _chain(*parts: Iterator[str]) -> Iterator[str]:
    for part in parts:
        yield from part


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Write a synthetic IEMA cabinet cell.")
    parser.add_argument("outdir", type=Path, help="directory to write the cell into")
    parser.add_argument("--wires", type=int, default=10000, help="number of wires (default 10000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    parser.add_argument(
        "--cabinet",
        action="store_true",
        help="write a complete cabinet (models, terminal schema, scene, assignments) too",
    )
    args = parser.parse_args(argv)
    write = write_cabinet if args.cabinet else write_cell
    print(write(args.outdir, args.wires, args.seed))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
