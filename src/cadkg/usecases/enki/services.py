"""The ENKI service of D3.1 section 4.5 (profile ``enki``): the parameters of a hose product.

The cell needs the diameter of the hose it handles, and later more product parameters;
``hose_info(product)`` answers them from the hoses in the graph (read from a hose
product table, docs/formats/hose.md). Measures are metres; a measure the table leaves
out is ``None`` (0 on ROS).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from cadkg.services.service import Effect, Service, on_model
from cadkg.services.session import Session
from cadkg.usecase import Answer

__all__ = ["SERVICES", "HoseInfoResult", "HoseRecord", "hose_info", "hose_model"]


@dataclass(frozen=True)
class HoseRecord:
    product: str
    diameter: float
    length: float | None
    material: str | None
    bend_radius: float | None


@dataclass(frozen=True)
class HoseInfoResult(Answer):
    product: str = ""
    diameter: float = 0.0
    length: float | None = None
    material: str = ""
    bend_radius: float | None = None


def hose_model(kg: Any) -> dict[str, HoseRecord]:
    """The hose products of a graph by product name.

    Raises
    ------
    QueryError
        When the graph cannot be queried.
    """
    hoses: dict[str, HoseRecord] = {}
    for row in kg.query(
        """SELECT DISTINCT ?product ?diameter ?length ?material ?bend WHERE {
             ?hose a ck:Hose ; ck:label ?product ; ck:diameterM ?diameter .
             OPTIONAL { ?hose ck:lengthM ?length } OPTIONAL { ?hose ck:material ?material }
             OPTIONAL { ?hose ck:bendRadiusM ?bend } }
           ORDER BY ?product"""
    ):
        product = str(row["product"])
        hoses.setdefault(
            product,
            HoseRecord(
                product=product,
                diameter=float(row["diameter"]),
                length=None if row["length"] is None else float(row["length"]),
                material=None if row["material"] is None else str(row["material"]),
                bend_radius=None if row["bend"] is None else float(row["bend"]),
            ),
        )
    return hoses


def hose_info(hoses: dict[str, HoseRecord], product: str) -> HoseInfoResult:
    """Diameter, length, material and bend radius of a hose product (metres).

    The product is matched as written, else ignoring case when that leaves one product.
    """
    wanted = product.strip()
    hose = hoses.get(wanted)
    if hose is None:
        folded = [h for name, h in hoses.items() if name.casefold() == wanted.casefold()]
        hose = folded[0] if len(folded) == 1 else None
    if hose is None:
        known = ", ".join(hoses) or "none"
        return HoseInfoResult(False, f"no hose product {product!r}; products: {known}")
    missing = [
        name for name, value in (("length", hose.length), ("bend radius", hose.bend_radius)) if value is None
    ]
    note = f"not given: {', '.join(missing)}" if missing else "ok"
    return HoseInfoResult(
        True, note, hose.product, hose.diameter, hose.length, hose.material or "", hose.bend_radius
    )


def _hoses(session: Session) -> dict[str, HoseRecord]:
    return session.profile_model("enki", hose_model)


SERVICES: tuple[Service, ...] = (
    Service(
        "hose_info",
        "diameter, length, material and bend radius of a hose product",
        {"product": str},
        on_model(hose_info, _hoses),
        effect=Effect.READS,
    ),
)
