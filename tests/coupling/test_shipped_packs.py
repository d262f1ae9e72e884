"""Every shipped rule pack loads, and every rule finds its own examples through the real parsers."""

from __future__ import annotations

from importlib.resources.abc import Traversable

import pytest

from archmetrics.coupling import LinkKind, Role, Rule, RuleSet, load_rule_pack
from archmetrics.coupling.loader import builtin_pack_files
from tests.coupling.trees import BUILTIN, measure

EXPECTED_PACKS = {
    "posix-sockets", "dynamic-loading", "cpp-rtti", "zeroc-ice", "zeromq", "player", "robosoa",
    "ros1", "ros2",
}  # fmt: skip
_PATHS = {"python": "example.py", "c": "example.c", "cpp": "example.cpp"}
_CASES = [
    (rule, language, snippet) for rule in BUILTIN.rules for language, snippet in rule.examples
]


def test_the_expected_packs_ship_and_every_rule_has_an_example() -> None:
    assert {p.name for p in BUILTIN.packs} == EXPECTED_PACKS
    assert [r.qualified_id for r in BUILTIN.rules if not r.examples] == []


@pytest.mark.parametrize("source", builtin_pack_files(), ids=lambda f: f.name)
def test_each_shipped_pack_loads_on_its_own(source: Traversable) -> None:
    pack = load_rule_pack(source)
    assert pack.rules and pack.description
    assert pack.source.endswith(f"{pack.name}.toml")


@pytest.mark.parametrize(
    ("rule", "language", "snippet"),
    _CASES,
    ids=[f"{rule.qualified_id}-{language}" for rule, language, _ in _CASES],
)
def test_each_rule_matches_its_example(rule: Rule, language: str, snippet: str) -> None:
    path = _PATHS[language]
    sites = [
        s for s in measure({path: snippet}).of_file(path).link_sites if s.rule == rule.qualified_id
    ]
    assert sites, f"{rule.qualified_id} does not match its {language} example"
    if rule.example_endpoint is not None:
        assert [s.endpoint.key if s.endpoint else None for s in sites] == [rule.example_endpoint]


@pytest.mark.parametrize("pack", BUILTIN.packs, ids=lambda p: p.name)
def test_a_pack_alone_still_finds_its_examples(pack: object) -> None:
    """Rules do not lean on other packs (and other packs do not shadow them)."""
    alone = RuleSet((pack,))  # type: ignore[arg-type]
    for rule in alone.rules:
        for language, snippet in rule.examples:
            report = measure({_PATHS[language]: snippet}, rules=alone)
            assert rule.qualified_id in {s.rule for s in report.elements[0].link_sites}


def test_every_link_kind_and_role_has_shipped_rules() -> None:
    assert {r.kind for r in BUILTIN.rules} == set(LinkKind)
    assert {r.role for r in BUILTIN.rules} == set(Role)
