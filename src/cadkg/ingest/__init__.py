"""Reading the cell's input files: the manifest, the build pipeline, and one module (or package)
per format that no single use case owns.

- ``manifest``: the cell manifest (TOML); ``pipeline``: read a file, map its records, report;
- ``reader``: what a reader declares; ``formats``: the readers of the formats below;
- ``text``, ``sheet``, ``xml_input``: encodings and CSV sniffing, workbooks, untrusted XML;
- ``wri``: WRI ID tables; ``assignments``: the robot/human overlay; ``placement``: poses as files state them;
- ``eplan/``: EPLAN device tags and connection lists; ``scene/``: the X3D/VRML scene graph;
  ``harness/``: harness records, KBL and VEC.

Every reader returns typed records (frozen dataclasses) and knows nothing of triples.
"""
