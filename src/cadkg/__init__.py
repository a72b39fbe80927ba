"""cadkg: the CAD platform interface of a robotic wiring cell, as an RDF knowledge graph.

>>> import cadkg
>>> kg = cadkg.build("examples/iema-switchgear/manifest.toml")   # doctest: +SKIP
>>> kg.named_query("wires-of-component", label="F1500.1").to_dataframe()   # doctest: +SKIP
"""

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
from cadkg.graph import KnowledgeGraph, build, open_store
from cadkg.ontology.terms import CK
from cadkg.query.validate import Finding, validate
from cadkg.store import QueryResult

open = open_store

__version__ = "0.1.0"

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
