"""The cabinet's derivation: the inputs gathered from a build's records (``collect``) or read
back from the graph (``extract``), the derived geometry (``cabinet``), its triples (``emit``)
and the copy kept beside an on-disk store (``persist``)."""
