"""The rule packs and router rules the docs show are files archmetrics and robosoa take as
written: docs/metrics.md's rule pack loads and its rule matches its own example, its
``[[scopes]]`` and ``[[configuration]]`` tables load in that pack, and docs/runtime.md's
router rules load. (Configuration files: tests/test_config_examples.py; commands:
tests/test_doc_commands.py; plans: tests/cli/test_estimate_example.py.)"""

from __future__ import annotations

import re
import tomllib
from pathlib import Path
from typing import Any

from archmetrics.coupling import RuleSet
from archmetrics.coupling.validate import parse_pack
from robosoa.router import Router
from tests.coupling.trees import measure

ROOT = Path(__file__).resolve().parent.parent


def _blocks(page: str) -> list[dict[str, Any]]:
    text = (ROOT / page).read_text(encoding="utf-8")
    return [tomllib.loads(b) for b in re.findall(r"^```toml\n(.*?)^```", text, re.S | re.M)]


def test_the_rule_pack_format_loads_and_its_rule_finds_its_example() -> None:
    [pack_block, scopes, configuration] = _blocks("docs/metrics.md")
    pack = parse_pack(pack_block, "docs/metrics.md")
    [rule] = pack.rules
    [(language, snippet)] = rule.examples
    assert language == "python"
    report = measure({"example.py": snippet}, rules=RuleSet((pack,)))
    sites = [s for s in report.of_file("example.py").link_sites if s.rule == rule.qualified_id]
    assert [s.endpoint.key if s.endpoint else None for s in sites] == [rule.example_endpoint]
    with_scopes = parse_pack({**pack_block, **scopes}, "docs/metrics.md")
    assert [s.id for s in with_scopes.scopes] == ["node"]
    with_configuration = parse_pack({**pack_block, **configuration}, "docs/metrics.md")
    assert [c.id for c in with_configuration.configuration] == ["route-service"]


def test_the_router_rules_load() -> None:
    [rules] = _blocks("docs/runtime.md")
    router = Router.from_data(rules)
    assert [r.operation for r in router.rules][:1] == ["set_goal"]
    assert len(router.rules) == len(rules["rules"])
