"""The use cases cadkg ships, one folder each (D3.1 section 4): ``iema`` (switchgear cabinets),
``elimco`` (aeronautic harnesses on a pin bench), ``elvez`` (harness assembly on guides),
``vw`` (harness state for a detection system), ``enki`` (hose handling).

Each folder holds its own readers, the mapping of their records to triples, its derivation,
its services and its named queries, and declares them in its ``__init__`` as one
:class:`cadkg.usecase.UseCase`; see :mod:`cadkg.usecase` for adding one.
"""
