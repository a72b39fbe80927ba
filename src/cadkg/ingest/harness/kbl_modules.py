"""Modules and variants of a modular (150 %) KBL harness.

A KBL harness may hold the parts of many variants: each ``Module`` controls (through its
``Module_configuration/Controlled_components``) the occurrences and connections it brings;
modules of one ``Module_families`` entry exclude each other. A harness-level
``Module_configuration`` of type ``module list`` controls completion parts, which a variant
holds when it chooses at least one of the listed modules (their ids, as text); one of type
``option code`` controls parts by a PR code alone, and is offered as a module of its own. A
``Harness_configuration`` names a set of modules (a derivative). See docs/formats/kbl.md.
"""

from __future__ import annotations

from collections import defaultdict
from typing import Any

from cadkg.ingest.harness.kbl_document import KblDocument, child_elements, child_text, first_child
from cadkg.ingest.harness.records import HarnessConfiguration, HarnessModule

__all__ = ["KblModules"]


class KblModules:
    """The modules of one ``<Harness>`` and what each controls."""

    def __init__(self, document: KblDocument, harness: Any, harness_ident: str) -> None:
        self.document = document
        self.harness = harness_ident
        self.records: list[HarnessModule] = []
        self.controlled: dict[str, set[str]] = defaultdict(set)
        families = {f.get("id"): f for f in child_elements(harness, "Module_families")}
        modules = child_elements(harness, "Module")
        by_name = {m.get("id"): m.get("id") for m in modules}
        for module in modules:
            by_name.setdefault(child_text(module, "Part_number") or "", module.get("id"))
            self._module(module, families)
        for configuration in child_elements(harness, "Module_configuration"):
            kind = child_text(configuration, "Configuration_type") or "option code"
            if kind == "module list":
                listed = self._listed(configuration, by_name)
            else:
                ident = configuration.get("id")
                label = child_text(configuration, "Logistic_control_information") or ident
                self.records.append(
                    HarnessModule(
                        self.harness,
                        ident,
                        label,
                        kind,
                        None,
                        label,
                        None,
                        None,
                        None,
                        configuration.sourceline,
                    )
                )
                listed = {ident}
            for token in (child_text(configuration, "Controlled_components") or "").split():
                self.controlled[token] |= listed
        self.configurations = [
            HarnessConfiguration(
                self.harness,
                c.get("id"),
                child_text(c, "Car_classification_level_4")
                or child_text(c, "Car_classification_level_3")
                or child_text(c, "Part_number")
                or c.get("id"),
                tuple(
                    m.get("id")
                    for m in (
                        document.ref(c, "Modules", {m.get("id"): m for m in modules}, "a <Module>", many=True)
                        if (child_text(c, "Modules") or "")
                        else []
                    )
                ),
                c.sourceline,
            )
            for c in child_elements(harness, "Harness_configuration")
        ]

    def _module(self, module: Any, families: dict[str, Any]) -> None:
        ident = module.get("id")
        configuration = first_child(module, "Module_configuration")
        family = (
            self.document.ref(module, "Of_family", families, "a <Module_families>")[0]
            if child_text(module, "Of_family")
            else None
        )
        self.records.append(
            HarnessModule(
                self.harness,
                ident,
                child_text(module, "Part_number") or ident,
                child_text(module, "Content") or "module",
                child_text(module, "Description"),
                child_text(configuration, "Logistic_control_information")
                if configuration is not None
                else None,
                family.get("id") if family is not None else None,
                child_text(family, "Id") if family is not None else None,
                child_text(family, "Description") if family is not None else None,
                module.sourceline,
            )
        )
        if configuration is not None:
            for token in (child_text(configuration, "Controlled_components") or "").split():
                self.controlled[token].add(ident)

    def _listed(self, configuration: Any, by_name: dict[str, str]) -> set[str]:
        listed = set()
        for token in (child_text(configuration, "Logistic_control_information") or "").split():
            if token not in by_name:
                self.document.error(
                    "a module list names no module",
                    first_child(configuration, "Logistic_control_information"),
                    found=token,
                    expected="the ids (or part numbers) of <Module>s of the harness",
                )
            listed.add(by_name[token])
        return listed

    def control(self, element: Any) -> frozenset[str] | None:
        """The modules controlling ``element``, directly or through its assembly (a specified
        occurrence follows its ``Related_assembly``); None when nothing controls it."""
        found = set(self.controlled.get(element.get("id"), ()))
        assembly = child_text(element, "Related_assembly")
        if assembly is not None:
            found |= self.controlled.get(assembly, set())
        return frozenset(found) if found else None
