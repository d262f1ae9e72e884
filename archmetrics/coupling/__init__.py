"""Coupling: static (s_a, s_e) and dynamic (d_a, d_e) coupling of elements, from facts (pure).

Entry points for the application layer:

- :func:`group_elements` -- paths to elements (also used by the change-set engine);
- :func:`load_rule_packs` -- the dynamic-coupling rule packs in force (the only file reading);
- :func:`measure_coupling` -- facts, options and rules to a :class:`CouplingReport`;
- :func:`rule_rows` / :func:`rules_markdown` -- the rule table for ``archmetrics rules``.

See docs/metrics.md for the definitions and rules.
"""

from __future__ import annotations

from archmetrics.coupling.elements import Element, group_elements
from archmetrics.coupling.loader import ENTRY_POINT_GROUP, load_rule_pack, load_rule_packs
from archmetrics.coupling.measure import measure_coupling
from archmetrics.coupling.model import (
    CouplingOptions,
    CouplingReport,
    EdgeKind,
    ElementCoupling,
    ElementGraph,
    Endpoint,
    GraphEdge,
    LinkSite,
    LinkStatus,
    Resolution,
    SourceRef,
    StaticDependency,
)
from archmetrics.coupling.rules import LinkKind, Role, Rule, RulePack, RulePackError, RuleSet
from archmetrics.coupling.ruletable import RuleRow, rule_rows, rules_markdown

__all__ = [
    "ENTRY_POINT_GROUP",
    "CouplingOptions",
    "CouplingReport",
    "EdgeKind",
    "Element",
    "ElementCoupling",
    "ElementGraph",
    "Endpoint",
    "GraphEdge",
    "LinkKind",
    "LinkSite",
    "LinkStatus",
    "Resolution",
    "Role",
    "Rule",
    "RulePack",
    "RulePackError",
    "RuleRow",
    "RuleSet",
    "SourceRef",
    "StaticDependency",
    "group_elements",
    "load_rule_pack",
    "load_rule_packs",
    "measure_coupling",
    "rule_rows",
    "rules_markdown",
]
