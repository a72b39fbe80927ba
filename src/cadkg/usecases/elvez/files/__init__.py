"""Readers of the ELVEZ cell's own files: platform scenes, WRI tables and meshes, element
definitions, wiring harnesses, components and the assembly sequence."""
