"""Variants of a VEC harness description: variant configurations and modules.

A ``VariantConfiguration`` constrains the elements whose ``ConfigInfo`` names it (directly, in
a nested ``ConfigurationConstraint`` of 2.0, or in the ``ConstrainedElements`` of a 2.1
``ConfigurationConstraintSpecification``). A module is a part occurrence with a
``PartWithSubComponentsRole`` (of a part structure of content ``Module``, or named by a module
family or list): it holds its ``SubComponent``s; a ``ModuleList``'s ``CompletionComponents``
are in when one of its modules is; modules of one ``ModuleFamily`` exclude each other. Both
become :class:`HarnessModule` records, chosen alike.
"""

from __future__ import annotations

from collections import defaultdict
from typing import Any

from cadkg.ingest.harness.records import HarnessModule
from cadkg.ingest.harness.variants import Modules
from cadkg.ingest.harness.vec_document import VecDocument
from cadkg.ingest.harness.xml_tree import child_elements, child_text, element_name, kind_of

__all__ = ["VecVariants"]


class VecVariants:
    """The modules of one harness description and what each holds."""

    def __init__(self, document: VecDocument, harness: str, element: Any, occurrences: list[Any]) -> None:
        self.document = document
        self.harness = harness
        self.records: list[HarnessModule] = []
        self.held: dict[str, set[str]] = defaultdict(set)
        specifications = child_elements(element, "Specification")
        for specification in specifications:
            if kind_of(specification) == "VariantConfigurationSpecification":
                for configuration in child_elements(specification, "VariantConfiguration"):
                    self._configuration(configuration)
        for constrained in element.iter():
            if isinstance(constrained.tag, str) and child_text(constrained, "ConfigInfo") is not None:
                self._constraint(constrained)
        self._modules(specifications, occurrences)

    def _configuration(self, configuration: Any) -> None:
        ident = configuration.get("id")
        control = child_text(configuration, "LogisticControlExpression") or child_text(
            configuration, "LogisticControlString"
        )
        self.records.append(
            HarnessModule(
                self.harness,
                ident,
                child_text(configuration, "Identification") or ident,
                "variant configuration",
                None,
                control,
                None,
                None,
                None,
                configuration.sourceline,
            )
        )

    def _constraint(self, element: Any) -> None:
        configuration = self.document.ref(element, "ConfigInfo", ("VariantConfiguration",))
        if kind_of(element) != "ConfigurationConstraint":
            targets = [element]
        elif element_name(element.getparent()) == "Specification":
            # 2.1: a constraint of its own, naming the elements it constrains.
            targets = self.document.refs(element, "ConstrainedElements", None, required=False)
        else:
            # 2.0: a constraint nested in the element it constrains.
            targets = [element.getparent()]
        for target in targets:
            self.held[target.get("id")].add(configuration.get("id"))

    def _modules(self, specifications: list[Any], occurrences: list[Any]) -> None:
        doc = self.document
        families: dict[str, Any] = {}
        lists: list[Any] = []
        for specification in specifications:
            if kind_of(specification) == "ModuleFamilySpecification":
                for family in child_elements(specification, "ModuleFamily"):
                    for role in doc.refs(family, "ModuleInFamily", None):
                        families[role.get("id")] = family
            elif kind_of(specification) == "ModuleListSpecification":
                lists.extend(child_elements(specification, "ModuleListConfiguration"))
        listed = {r.get("id") for m in lists for r in doc.refs(m, "ModuleInList", None)}
        module_of: dict[str, str] = {}
        for occurrence in occurrences:
            for role in child_elements(occurrence, "Role"):
                if kind_of(role) != "PartWithSubComponentsRole":
                    continue
                structure = doc.ref(role, "PartStructureSpecification", ("PartStructureSpecification",))
                content = (child_text(structure, "Content") or "").lower()
                ident = occurrence.get("id")
                if content != "module" and role.get("id") not in families | dict.fromkeys(listed):
                    continue
                module_of[role.get("id")] = module_of[ident] = ident
                family = families.get(role.get("id"), families.get(ident))
                self.records.append(
                    HarnessModule(
                        self.harness,
                        ident,
                        child_text(occurrence, "Identification") or ident,
                        "module",
                        None,
                        None,
                        family.get("id") if family is not None else None,
                        child_text(family, "Identification") if family is not None else None,
                        None,
                        occurrence.sourceline,
                    )
                )
                for member in doc.refs(role, "SubComponent", None, required=False):
                    self.held[member.get("id")].add(ident)
        for module_list in lists:
            chosen = {
                module_of.get(r.get("id"), r.get("id")) for r in doc.refs(module_list, "ModuleInList", None)
            }
            for part in doc.refs(module_list, "CompletionComponents", None):
                self.held[part.get("id")] |= chosen

    def modules(self, *elements: Any) -> Modules:
        """The modules holding any of ``elements``; None when none does (in every variant)."""
        found: set[str] = set()
        for element in elements:
            found |= self.held.get(element.get("id"), set())
        return frozenset(found) if found else None
