"""The workbench page and what only it asks for: the page itself (``page``), completion terms
(``terms``), the 3D scene of the cell and its use cases' extras (``scene``, ``scene_extras``,
``harness_layout``) and their routes (``routes``)."""
