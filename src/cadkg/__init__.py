"""cadkg: the CAD platform interface of a robotic wiring cell, as an RDF knowledge graph.

>>> import cadkg
>>> kg = cadkg.build("examples/iema-switchgear/manifest.toml")   # doctest: +SKIP
>>> kg.named_query("wires-of-component", label="F1500.1").to_dataframe()   # doctest: +SKIP
"""

import importlib
from typing import TYPE_CHECKING, Any

from cadkg.errors import (
    CadkgError,
    IngestError,
    IngestWarning,
    ManifestError,
    NotFound,
    QueryError,
    RegistryError,
    StoreError,
    UnknownTermError,
)

if TYPE_CHECKING:
    from cadkg.graph import KnowledgeGraph, build, open_store
    from cadkg.ontology.terms import CK
    from cadkg.query.validate import Finding, validate
    from cadkg.store import QueryResult

    open = open_store

__version__ = "0.1.0"

# The public names beyond the errors, imported when first used: a command that needs only one
# of them (or a child process that imports cadkg for its errors) does not pay for the store,
# the mapping and the checks at start-up.
_LAZY = {
    "KnowledgeGraph": ("cadkg.graph", "KnowledgeGraph"),
    "build": ("cadkg.graph", "build"),
    "open_store": ("cadkg.graph", "open_store"),
    "open": ("cadkg.graph", "open_store"),
    "CK": ("cadkg.ontology.terms", "CK"),
    "Finding": ("cadkg.query.validate", "Finding"),
    "validate": ("cadkg.query.validate", "validate"),
    "QueryResult": ("cadkg.store", "QueryResult"),
}


def __getattr__(name: str) -> Any:
    found = _LAZY.get(name)
    if found is None:
        raise AttributeError(f"module 'cadkg' has no attribute {name!r}")
    value = getattr(importlib.import_module(found[0]), found[1])
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted({*globals(), *_LAZY})


__all__ = [
    "CK",
    "CadkgError",
    "Finding",
    "IngestError",
    "IngestWarning",
    "KnowledgeGraph",
    "ManifestError",
    "NotFound",
    "QueryError",
    "QueryResult",
    "RegistryError",
    "StoreError",
    "UnknownTermError",
    "__version__",
    "build",
    "open",
    "open_store",
    "validate",
]
