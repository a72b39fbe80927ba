"""CAD scenes: the records (``records``), the scene graph both encodings parse into and the walk
that turns it into items (``graph``), and the X3D and VRML97 parsers."""
