"""Hostile and unusual C and C++: deep and unbalanced nesting, long chains and one-line
files are measured (or cut off by the parse time budget), never crash, never run away.

docs/metrics.md, "Limits", has the rules; benchmarks/pathological.py times these inputs.
"""

from __future__ import annotations

import re
import subprocess
import sys
import textwrap

import pytest
from hypothesis import given
from hypothesis import strategies as st
from tree_sitter import Node, QueryCursor

from archmetrics.facts import FileFacts, Language
from archmetrics.parsers import DEFAULT_LIMITS, LanguageTable, ParseLimits, parse_source, shown
from archmetrics.parsers.c_family import grammar
from archmetrics.parsers.c_family_calls import without_template_arguments
from archmetrics.parsers.c_family_names import in_order
from archmetrics.parsers.c_family_text import compact, compact_slowly, tokens

_TABLE = LanguageTable.default(plugins=False)


def read(source: str, language: str = "cpp", limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    path = "deep.cpp" if language == "cpp" else "deep.c"
    return parse_source(path, source.encode(), language, _TABLE, limits)


def in_function(body: str) -> str:
    return f"int f(int x) {{\n{body}\n}}\n"


# -- deep nesting: what walked up the tree (n² steps in tree-sitter) -------------------------


def _scopes_walking_up(node: Node, data: bytes) -> list[str]:
    """The names around ``node`` as the parser found them before: by walking up."""
    names: list[str] = []
    parent = node.parent
    while parent is not None:
        name = parent.child_by_field_name("name")
        if parent.type in ("namespace_definition", "class_specifier") and name is not None:
            names.append(compact(data[name.start_byte : name.end_byte]))
        parent = parent.parent
    return names[::-1]


def test_classes_nested_in_methods_are_named_as_by_walking_up() -> None:
    source = ("namespace n { class A { void f() {" * 150 + "}" * 450 + ";").encode()
    built = grammar(Language.CPP)
    found = QueryCursor(built.query).captures(built.parser.parse(source).root_node)
    expected = [
        "::".join([*_scopes_walking_up(node, source), "A"]) for node in in_order(found["class"])
    ]
    facts = read(source.decode())
    assert [c.qualified_name for c in facts.classes] == expected
    assert len(expected) > 50


def test_thousands_of_nested_classes_are_named_in_linear_time() -> None:
    # 19 KB of this (1,000 levels) took 32 s: a walk to the parent per enclosing scope,
    # per class, and in tree-sitter each step to a parent descends from the root again
    facts = read("class A { void f() {" * 2_000 + "}" * 2_000 + ";")
    assert facts.parsed
    names = [c.qualified_name for c in facts.classes]
    assert len(names) > 900
    longest = max(names, key=len)
    assert longest == shown.CUT + ("::A" * 1_000)[-shown.LIMIT :] + "::A"  # the inner end kept


def test_an_else_if_chain_of_two_thousand_counts_each_branch() -> None:
    arms = "".join(f"else if (x == {i}) x = {i};\n" for i in range(1, 2_000))
    facts = read(in_function("if (x == 0) x = 0;\n" + arms), "c")
    assert facts.functions[0].complexity == 2_001
    assert [s.kind for s in facts.statements].count("if") == 2_000


def test_three_thousand_nested_blocks_count_each_if() -> None:
    facts = read(in_function("if (x) {\n" * 3_000 + "x++;\n" + "}\n" * 3_000), "c")
    assert facts.functions[0].complexity == 3_001
    assert len(facts.statements) == 3_002


def test_a_specifier_deep_in_blocks_still_stands_alone() -> None:
    facts = read(in_function("{" * 2_000 + "struct S { int a; };" + "}" * 2_000), "c")
    assert "struct" in [s.kind for s in facts.statements]


def test_a_typedef_names_an_anonymous_class_at_any_depth() -> None:
    body = "{" * 2_000 + "typedef struct { int x; } T;" + "}" * 2_000
    facts = read(in_function(body), "c")
    assert [c.qualified_name for c in facts.classes] == ["T"]


@pytest.mark.parametrize(
    "unit",
    ["if (x) { f(", "{ (", "[ { (", "x = (y ? {", "g(x, [&](){", "a<b<", "#if A\n{\n"],
)
def test_unbalanced_nesting_is_read_with_warnings(unit: str) -> None:
    facts = read(in_function(unit * 2_000))
    assert facts.parsed
    assert facts.warnings  # what could not be parsed is reported


# -- long chains and nests of calls -------------------------------------------------------------


def test_a_chain_of_calls_names_every_call_and_cuts_its_long_texts() -> None:
    facts = read(in_function("x" + ".m()" * 5_000 + ";"))
    assert len(facts.call_sites) == 5_000
    assert {site.name for site in facts.call_sites} == {"m"}
    assert max(len(site.callee) for site in facts.call_sites) == shown.LIMIT + len(shown.CUT)
    assert [site.callee for site in facts.call_sites[-2:]] == ["x.m().m", "x.m"]


def test_nested_calls_cut_the_texts_that_hold_long_calls() -> None:
    facts = read(in_function("return " + "g(" * 5_000 + "x" + ")" * 5_000 + ";"))
    texts = [site.arguments[0].text for site in facts.call_sites]
    assert texts[-1] == "x"
    assert texts[-3] == "g(g(x))"
    assert all(len(text) <= shown.LIMIT + len(shown.CUT) for text in texts)


def test_a_tree_deeper_than_max_depth_is_refused_naming_the_limit() -> None:
    facts = read(in_function("x" + ".m()" * 15_000 + ";"))  # two levels a call
    assert not facts.parsed
    assert facts.warnings[0].message == (
        "tree-sitter's tree of this file is more than 20,000 levels deep; the limit is"
        " limits.nesting, ParseLimits.max_depth (raise it to measure the file)"
    )
    assert read(in_function("x" + ".m()" * 9_000 + ";")).parsed


def test_a_tree_deeper_than_tree_sitters_query_goes_is_refused_at_any_limit() -> None:
    # its query cursor counts depth in 16 bits: at 34,000 chained calls it found 32,766
    facts = read(in_function("x" + ".m()" * 34_000 + ";"), limits=ParseLimits(max_depth=10**6))
    assert not facts.parsed
    assert facts.warnings[0].message == (
        "tree-sitter's tree of this file is more than 65,000 levels deep;"
        " tree-sitter's query cannot go deeper"
    )


def test_a_long_argument_whose_calls_are_short_is_whole() -> None:
    table = ", ".join(f"h({i})" for i in range(500))
    facts = read(in_function(f"f({table});"), "c")
    (outer,) = [site for site in facts.call_sites if site.callee == "f"]
    assert len(outer.arguments) == 500
    long = read(in_function(f"f(g({table}));"), "c")
    (call,) = [site for site in long.call_sites if site.callee == "f"]
    assert call.arguments[0].text.endswith(shown.CUT)  # g(...) is long


def test_template_arguments_are_dropped_from_the_callee_at_any_depth() -> None:
    facts = read(in_function("A<" * 3 + "int" + ">" * 3 + "::g();"))
    assert [(call.callee, call.name) for call in facts.call_sites] == [("A::g", "g")]
    deep = read(in_function("A<" * 3_000 + "int" + ">" * 3_000 + "::g();"))
    # tree-sitter reads the deep one as a `::g` after an expression it could not parse
    assert [(call.callee, call.name) for call in deep.call_sites] == [("::g", "g")]


def test_a_long_qualified_function_name_is_read() -> None:
    facts = read("void " + "a::" * 3_000 + "f() {}\n")
    assert facts.functions[0].name == "f"


@given(st.text(alphabet="ab<>()-: ", max_size=30))
def test_template_arguments_go_as_the_regular_expression_takes_them(written: str) -> None:
    expected, previous = written, ""
    while previous != expected and "<" in expected:
        previous, expected = expected, re.sub(r"<[^<>()]*>", "", expected)
    assert without_template_arguments(written) == expected


_PIECES = ["a", "b1", "_", " ", "->", "(", ")", '"x y"', "'c'", "/*c*/", "\n", "é", "\0"]


@given(st.lists(st.sampled_from(_PIECES), max_size=12))
def test_compact_joins_as_the_token_loop_did(pieces: list[str]) -> None:
    data = "".join(pieces).encode()
    found = tokens(data)
    expected = found[0].decode() if len(found) == 1 else compact_slowly(found)
    assert compact(data) == expected


# -- one-line files and the parse budget ---------------------------------------------------------


def test_a_one_line_initializer_of_a_hundred_thousand_is_one_statement() -> None:
    facts = read("int t[] = {" + ",".join(map(str, range(100_000))) + "};\n", "c")
    assert [s.kind for s in facts.statements] == ["declaration"]


def test_long_preprocessor_chains_are_measured() -> None:
    chain = "#if A0\nint a;\n" + "".join(f"#elif A{i}\nint a{i};\n" for i in range(1, 2_000))
    facts = read(chain + "#endif\n", "c")
    assert facts.parsed
    assert len(facts.statements) == 2_000


@pytest.mark.security
def test_a_parse_over_its_time_budget_is_cut_off_and_the_parser_stays_usable() -> None:
    big = "int t[] = {" + ",".join(map(str, range(200_000))) + "};\n"
    facts = read(big, "c", ParseLimits(parse_seconds=1e-6))
    assert not facts.parsed
    assert facts.warnings[0].message == (
        "tree-sitter's parse took longer than 1e-06 s and was cut off"
        " (raise limits.parse-seconds, ParseLimits.parse_seconds, to measure it)"
    )
    small = read(in_function("return x;"), "c")  # not the rest of the cut-off parse
    assert [s.kind for s in small.statements] == ["function", "return"]
    assert small.warnings == ()


@pytest.mark.security
def test_every_pathological_input_completes_under_an_address_space_limit() -> None:
    """As ``ulimit -v 2000000`` would: the child must finish, measured or refused."""
    script = textwrap.dedent(
        """
        import resource
        resource.setrlimit(resource.RLIMIT_AS, (2_000 << 20, 2_000 << 20))
        from archmetrics.parsers import LanguageTable, parse_source
        table = LanguageTable.default()
        f = "int f(int x) {%s}"
        for source in (
            "class A { void f() {" * 2_000 + "}" * 2_000 + ";",
            f % ("if (x) {" * 5_000),
            f % ("x" + ".m()" * 20_000 + ";"),
            f % ("g(" * 20_000 + "x" + ")" * 20_000 + ";"),
            f % ("([{" * 5_000),
            "int t[] = {" + ",".join(map(str, range(300_000))) + "};",
        ):
            facts = parse_source("x.cpp", source.encode(), "cpp", table)
            assert facts.parsed or facts.warnings
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, done.stderr[-2000:]
