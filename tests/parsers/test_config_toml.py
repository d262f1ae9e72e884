"""The TOML configuration reader: every table with values, on the line it is written."""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from archmetrics.facts import ConfigTable, Severity
from archmetrics.parsers import LanguageTable, parse_source
from archmetrics.parsers.config_lines import table_lines
from archmetrics.parsers.config_toml import MAX_KEYS, MAX_TABLES, parse

ROOT = Path(__file__).resolve().parents[2]
TABLE = LanguageTable.default(plugins=False)

ROUTES = '''title = """a [[fake]] header
[[rules.to]]
inside a string"""
[[rules]]  # the first rule
name = 'drive'
to = [ {kind = "send", service = "s1"},
       {kind = "send", service = "s2"} ]

[[rules]]
"quoted.key" = 1
[[rules.to]]
kind = "publish"
topic = "t"
[rules.meta]
m.n = 2
inline = { p = { q = true } }
'''


def _tables(source: str) -> list[ConfigTable]:
    facts = parse("rules.toml", source)
    assert facts.parsed, facts.warnings
    return list(facts.tables)


def test_each_table_is_read_with_its_keys_values_and_line() -> None:
    assert _tables(ROUTES) == [
        ConfigTable((), 1, (("title", ("a [[fake]] header\n[[rules.to]]\ninside a string",)),)),
        ConfigTable(("rules",), 4, (("name", ("drive",)),)),
        # tables written inline take the line of the key that holds them
        ConfigTable(("rules", "to"), 6, (("kind", ("send",)), ("service", ("s1",)))),
        ConfigTable(("rules", "to"), 6, (("kind", ("send",)), ("service", ("s2",)))),
        ConfigTable(("rules",), 9, (("quoted.key", ("1",)),)),
        ConfigTable(("rules", "to"), 11, (("kind", ("publish",)), ("topic", ("t",)))),
        ConfigTable(("rules", "meta", "m"), 15, (("n", ("2",)),)),
        ConfigTable(("rules", "meta", "inline", "p"), 16, (("q", ("true",)),)),
    ]


def test_the_router_fixture_gives_each_output_its_header_line() -> None:
    path = ROOT / "fixtures/study/pragmatics/soa/second/pragmatics/rules.toml"
    source = path.read_text(encoding="utf-8")
    outputs = [t for t in _tables(source) if t.keys == ("rules", "to")]
    lines = source.splitlines()
    assert [lines[t.line - 1] for t in outputs] == ["[[rules.to]]"] * 6
    assert [t.get("service") for t in outputs] == [("muri.backend",)] * 3 + [("muri.gui",)] * 3


def test_arrays_of_scalars_are_values_and_nested_arrays_are_flattened() -> None:
    [table] = _tables('drop = ["a", ["b", 3]]\nflag = false\nwhen = 1979-05-27\n')
    assert table.values == (
        ("drop", ("a", "b", "3")),
        ("flag", ("false",)),
        ("when", ("1979-05-27",)),
    )


def test_a_file_that_is_not_toml_is_not_measured_with_its_line() -> None:
    for source, line in (('[[rules]]\nname = "x"\nto = [\n', 3), ("a = 1\nb c\nd = 2\n", 2)):
        facts = parse("rules.toml", source)
        assert not facts.parsed and facts.tables == ()
        [warning] = facts.warnings
        assert (warning.severity, warning.line) == (Severity.ERROR, line)
        assert warning.message.startswith("not valid TOML")


@pytest.mark.security
def test_nesting_tomllib_cannot_follow_is_not_measured() -> None:
    facts = parse("deep.toml", "a = " + "[" * 100_000 + "]" * 100_000)
    assert not facts.parsed
    assert "nested too deeply" in facts.warnings[0].message


def test_tables_deeper_than_the_key_limit_are_left_out_with_a_warning() -> None:
    deep = ".".join(["k"] * (MAX_KEYS + 1))
    facts = parse("deep.toml", f"[{deep}]\nx = 1\n[ok]\ny = 2\n")
    assert facts.parsed and [t.keys for t in facts.tables] == [("ok",)]
    assert "deeper than" in facts.warnings[0].message


@pytest.mark.security
def test_more_tables_than_the_limit_is_not_measured() -> None:
    facts = parse("many.toml", "[[t]]\nx = 1\n" * (MAX_TABLES + 1))
    assert not facts.parsed and "tables" in facts.warnings[0].message


def test_configuration_has_no_statements_and_no_complexity() -> None:
    facts = parse_source("rules.toml", ROUTES.encode(), "toml", TABLE)
    assert (facts.loc, facts.sloc, facts.vg, facts.functions) == (0, 0, 0, ())
    assert TABLE.language_of("rules.toml") is None  # no ending maps to configuration


_TOMLISH = st.text(alphabet='[]{}=."\'#\n \\abk0,', max_size=200)


@settings(max_examples=300, deadline=None)
@given(_TOMLISH)
def test_the_line_scan_ends_on_any_text_and_places_only_real_lines(text: str) -> None:
    lines = table_lines(text)
    assert all(1 <= line <= text.count("\n") + 1 for line in lines.values())


@settings(max_examples=200, deadline=None)
@given(st.lists(st.sampled_from(["a", "b", "to"]), min_size=1, max_size=4), st.integers(1, 4))
def test_every_array_of_tables_header_is_placed(keys: list[str], count: int) -> None:
    header = ".".join(keys)
    source = "".join(f"[[{header}]]\nx = {i}\n" for i in range(count))
    tables = _tables(source)
    assert [t.line for t in tables if t.keys == tuple(keys)] == [1 + 2 * i for i in range(count)]
    assert tomllib.loads(source)  # the documents are TOML
