"""EPLAN exports: device tags and pin references (``labels``), connection lists."""
