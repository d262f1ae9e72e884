"""Configuration links (p. 110): a router's rules file read by the real reader, its routes
counted and resolved by the shipped packs' [[configuration]] rules."""

from __future__ import annotations

from pathlib import Path

import pytest

from archmetrics.coupling import LinkKind, Role, RulePackError, RuleSet, load_rule_pack
from archmetrics.coupling.config_links import config_link_sites
from archmetrics.coupling.measure import measure_coupling
from archmetrics.coupling.model import LinkStatus
from archmetrics.facts import FileFacts
from archmetrics.parsers import LanguageTable, parse_source
from archmetrics.parsers.config_toml import parse
from tests.coupling.trees import BUILTIN, tree_facts

ROUTES = """
[[rules]]
name = "drive"
operation = "drive"
[[rules.to]]
service = "muri.backend"
operation = "translate"
[[rules.to]]
kind = "publish"
topic = "status"

[[rules]]
topic = "pose"
to = [{ kind = "emit", topic = "moved" }, { kind = "send", service = "log" }]
"""
BACKEND = """import robosoa


def serve(bus, handler):
    bus.provide("muri.backend", handler)
"""


def _config(path: str, source: str) -> FileFacts:
    facts = parse(path, source)
    assert facts.parsed, facts.warnings
    return facts


def test_every_route_is_one_site_on_its_line_with_its_rule() -> None:
    sites = config_link_sites(_config("rules.toml", ROUTES), BUILTIN.configuration)
    assert [(s.line, s.rule, s.role, s.endpoint.key if s.endpoint else None) for s in sites] == [
        (5, "robosoa/route-service", Role.INITIATE, "service:muri.backend"),  # kind left out
        (8, "robosoa/route-publish", Role.INITIATE, "topic:status"),
        (12, "robosoa/route-topic", Role.RECEIVE, "topic:pose"),
        (14, "robosoa/route-emit", Role.INITIATE, "event:moved"),
        (14, "robosoa/route-service", Role.INITIATE, "service:log"),
    ]
    assert {(s.kind, s.callee, s.endpoint.via) for s in sites if s.endpoint} == {
        (LinkKind.MESSAGING, "rules.to", "configuration"),
        (LinkKind.MESSAGING, "rules", "configuration"),
    }


def test_a_route_links_into_the_element_that_provides_its_service() -> None:
    files = [*tree_facts({"backend_app.py": BACKEND}), _config("pragmatics/rules.toml", ROUTES)]
    report = measure_coupling(files, rules=BUILTIN)
    rules, backend = report.element("pragmatics/rules.toml"), report.element("backend_app.py")
    assert rules.d_e == 5
    [route] = [s for s in rules.link_sites if s.endpoint and s.endpoint.key.endswith("backend")]
    assert (route.status, route.targets) == (LinkStatus.RESOLVED, ("backend_app.py",))
    assert backend.d_a == 1 and backend.incoming_sites == (route,)


def test_tables_that_are_no_route_make_no_site() -> None:
    source = """
[[rules]]
operation = "stop"
[[rules.to]]
kind = "send"            # names no service: the router refuses it, so no link
operation = "halt"
[[other.to]]
service = "not-a-router-table"
"""
    assert config_link_sites(_config("rules.toml", source), BUILTIN.configuration) == ()


def test_source_files_and_other_formats_are_left_to_their_own_rules() -> None:
    [code] = tree_facts({"rules.py": "to = {'service': 'x'}\n"})
    assert config_link_sites(code, BUILTIN.configuration) == ()


_EXAMPLES = [(rule.qualified_id, rule) for rule in BUILTIN.configuration]
_TABLE = LanguageTable.default(plugins=False)


@pytest.mark.parametrize(("name", "rule"), _EXAMPLES, ids=[name for name, _ in _EXAMPLES])
def test_each_configuration_rule_finds_its_example(name: str, rule: object) -> None:
    from archmetrics.coupling.rules import ConfigRule

    assert isinstance(rule, ConfigRule) and rule.example and rule.description
    path = "example/" + rule.files[0].replace("**/", "").replace("*", "example")
    facts = parse_source(path, rule.example.encode(), rule.format, _TABLE)
    assert facts.parsed, facts.warnings
    sites = [s for s in config_link_sites(facts, BUILTIN.configuration) if s.rule == name]
    if rule.example_endpoint is None:  # the tree's configuration, read by rosgraph.py: no site
        assert sites == []
        return
    assert [s.endpoint.key if s.endpoint else None for s in sites] == [rule.example_endpoint]


def _pack(tmp_path: Path, body: str) -> Path:
    path = tmp_path / "mine.toml"
    path.write_text('[pack]\nname = "mine"\n' + body, encoding="utf-8")
    return path


GOOD = """
[[configuration]]
id = "route"
files = ["router/*.toml"]
format = "toml"
table = "routes"
kind = "messaging"
role = "initiate"
endpoint = { type = "service", key = "to", pattern = '^svc:(.*)$' }
"""


def test_another_router_is_added_as_data(tmp_path: Path) -> None:
    pack = load_rule_pack(_pack(tmp_path, GOOD))
    assert pack.rules == () and [r.qualified_id for r in pack.configuration] == ["mine/route"]
    source = '[[routes]]\nto = ["svc:a", "svc:b", "other"]\n'
    sites = config_link_sites(_config("router/r.toml", source), RuleSet((pack,)).configuration)
    # one site per value; a value the pattern does not find is a site with no endpoint
    assert [s.endpoint.key if s.endpoint else None for s in sites] == [
        "service:a",
        "service:b",
        None,
    ]


@pytest.mark.parametrize(
    ("change", "key"),
    [
        (("format", '"toml"', '"json"'), "format"),
        (("table", '"routes"', '"routes[].to"'), "table"),
        (("files", '["router/*.toml"]', '["!x"]'), "files"),
        (("endpoint", "key = \"to\", ", ""), "endpoint.key"),
        (("pattern", "'^svc:(.*)$'", "'(unclosed'"), "endpoint.pattern"),
        (("role", '"initiate"', '"listen"'), "role"),
        (("when", 'kind = "messaging"', 'kind = "messaging"\nwhen = { kind = 3 }'), "when.kind"),
    ],
    ids=lambda v: v if isinstance(v, str) else v[0],
)
def test_a_bad_configuration_rule_names_the_file_rule_and_key(
    tmp_path: Path, change: tuple[str, str, str], key: str
) -> None:
    _, old, new = change
    assert old in GOOD
    path = _pack(tmp_path, GOOD.replace(old, new, 1))
    with pytest.raises(RulePackError) as raised:
        load_rule_pack(path)
    assert (raised.value.source, raised.value.rule, raised.value.key) == (str(path), "route", key)


def test_a_pack_with_neither_rules_nor_configuration_is_refused(tmp_path: Path) -> None:
    with pytest.raises(RulePackError, match=r"\[\[rules\]\] or \[\[configuration\]\]"):
        load_rule_pack(_pack(tmp_path, ""))
