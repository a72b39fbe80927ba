"""Wire harness descriptions: the records every harness format reads into (``records``), KBL and VEC."""
