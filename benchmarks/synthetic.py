"""A synthetic switchgear cabinet of any size, in the real IEMA export formats.

``write_cell(directory, wires)`` writes three files, shaped like
``examples/iema-switchgear``:

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

Usage: ``python benchmarks/synthetic.py OUTDIR --wires 10000 [--seed 0]``
"""

from __future__ import annotations

import argparse
import random
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path

__all__ = ["CellFiles", "Component", "build_components", "write_cell"]

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


def _chain(*parts: Iterator[str]) -> Iterator[str]:
    for part in parts:
        yield from part


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description="Write a synthetic IEMA cabinet cell.")
    parser.add_argument("outdir", type=Path, help="directory to write the cell into")
    parser.add_argument("--wires", type=int, default=10000, help="number of wires (default 10000)")
    parser.add_argument("--seed", type=int, default=0, help="random seed (default 0)")
    args = parser.parse_args(argv)
    print(write_cell(args.outdir, args.wires, args.seed))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
