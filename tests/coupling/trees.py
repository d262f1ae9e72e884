"""Helpers for coupling tests: a tree of real source snippets, parsed by the real parsers."""

from __future__ import annotations

from collections.abc import Mapping

from archmetrics.coupling import (
    CouplingOptions,
    CouplingReport,
    RuleSet,
    load_rule_packs,
    measure_coupling,
)
from archmetrics.facts import FileFacts
from archmetrics.parsers import LanguageTable
from tests.harness import facts_of

_TABLE = LanguageTable.default(plugins=False)
BUILTIN = load_rule_packs(plugins=False)


def tree_facts(files: Mapping[str, str]) -> list[FileFacts]:
    """Facts of every snippet, keyed by its tree-relative path, through the real parsers."""
    facts = []
    for path, source in files.items():
        language = _TABLE.language_of(path)
        assert language is not None, path
        facts.append(facts_of(source, language, path))
    return facts


def measure(
    files: Mapping[str, str], rules: RuleSet | None = BUILTIN, **options: object
) -> CouplingReport:
    """Coupling of a tree of snippets with the built-in packs (or ``rules``)."""
    return measure_coupling(tree_facts(files), CouplingOptions(**options), rules)  # type: ignore[arg-type]
