"""Records → triples, in the terms of the cadkg ontology.

``writer``: N-Triples of one named graph; ``dispatch``: the mapping of each record type;
``nodes``: the nodes mappings share; ``cell`` and ``harness``: the mappings of the formats no
use case owns (each use case maps its own records in its ``mapping`` module).
"""
