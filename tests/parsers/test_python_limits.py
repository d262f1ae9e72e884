"""Hostile and unusual Python: no reader crashes, recurses without bound or runs away, and
generated code (long chains, deep conditional expressions, long `elif` chains) is measured.

Inputs that crashed the process before (libcst's native parser overflowing its stack) run
in a child process, so that a regression fails one test instead of ending the session.
docs/metrics.md, "Limits", has the rules; benchmarks/pathological.py times these inputs.
"""

from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from archmetrics.facts import FileFacts
from archmetrics.parsers import (
    DEFAULT_LIMITS,
    LanguageTable,
    ParseLimits,
    parse_source,
    python,
    python_limits,
    python_shown,
    shown,
)
from archmetrics.parsers import limits as limits_module
from archmetrics.parsers.python_depth import nesting
from tests.untrusted import run_main

_TABLE = LanguageTable.default(plugins=False)
NEWER = "type Alias = int\n"  # Python 3.12 syntax: under 3.11 only libcst reads the file


def read(source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    return parse_source("deep.py", source.encode(), "python", _TABLE, limits)


def in_child(source: str, *, memory: int | None = None) -> dict[str, object]:
    """Facts of ``source`` read in a child process (optionally under an address-space
    limit, like ``ulimit -v``), as JSON: a crash there is a failed test here."""
    script = textwrap.dedent(
        f"""
        import json, resource, sys
        if {memory!r}:
            resource.setrlimit(resource.RLIMIT_AS, ({memory!r}, {memory!r}))
        from archmetrics.parsers import LanguageTable, parse_source
        source = sys.stdin.read()
        facts = parse_source("deep.py", source.encode(), "python", LanguageTable.default())
        print(json.dumps({{
            "parsed": facts.parsed,
            "warnings": [w.message for w in facts.warnings],
            "statements": len(facts.statements),
            "vg": [f.complexity for f in facts.functions],
        }}))
        """
    )
    done = subprocess.run(
        [sys.executable, "-c", script], input=source, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, (done.returncode, done.stderr[-2000:])
    found: dict[str, object] = json.loads(done.stdout)
    return found


def ifexp_chain(levels: int) -> str:
    chain = "".join(f"{i} if c{i} else " for i in range(levels))
    return f"def f():\n    return {chain}0\n"


def elif_chain(branches: int) -> str:
    arms = "".join(f"    elif x == {i}:\n        return {i}\n" for i in range(1, branches + 1))
    return f"def f(x):\n    if x == 0:\n        return 0\n{arms}"


# -- reproduction 1: nesting that overflowed libcst's stack ---------------------------------


def test_ten_thousand_nested_parentheses_are_refused_with_cpythons_limit() -> None:
    found = in_child("x = " + "(" * 10_000 + "1" + ")" * 10_000 + "\n")
    assert found["parsed"] is False
    assert found["warnings"] == [
        "Python source nested 10,000 brackets deep; the limit is 200"
        " (CPython's own: no Python version runs it)"
    ]


def test_newer_syntax_nested_deeper_than_libcst_takes_is_refused_not_crashed() -> None:
    chain = in_child(NEWER + "x = a" + ".b" * 10_000 + "\n")
    assert chain["parsed"] is False
    warnings = chain["warnings"]
    assert isinstance(warnings, list)
    (message,) = warnings
    assert isinstance(message, str)
    assert message.startswith("Python source nested 10,001 levels deep in one statement;")
    assert "libcst, which reads the rest, takes at most 1,000" in message
    assert "Python syntax error at line 1" in message  # why the interpreter did not read it
    brackets = in_child(NEWER + "x = " + "[" * 300 + "]" * 300 + "\n")
    assert brackets["warnings"] == [
        "Python source nested 300 brackets deep; the limit is 200"
        " (CPython's own: no Python version runs it)"
    ]


def test_libcst_reads_newer_syntax_up_to_its_limit_as_the_other_reader_would() -> None:
    source = "x = a" + ".b" * 900 + "\ny = " + " + ".join(["a"] * 900) + "\n"
    facts = python.parse_with_libcst("deep.py", source)
    assert facts.parsed
    assert facts == read(source)


# -- reproduction 2: a long sum ---------------------------------------------------------------


@pytest.mark.parametrize(
    "source",
    [
        "x = " + " + ".join(["a"] * 10_000) + "\n",
        "x = a" + ".b" * 10_000 + "\n",
        "x = " + " and ".join(["a"] * 10_000) + "\n",
        "x = a" + "[0]" * 10_000 + "\n",
    ],
    ids=["sum", "attributes", "and", "subscripts"],
)
def test_a_chain_of_ten_thousand_operators_is_measured(source: str) -> None:
    facts = read(source)
    assert facts.parsed, facts.warnings
    assert [s.kind for s in facts.statements] == ["assign"]


def test_a_long_boolean_chain_counts_each_operator() -> None:
    facts = read("def f():\n    return " + " or ".join(["a"] * 5_000) + "\n")
    assert facts.functions[0].complexity == 5_000


# -- reproduction 3: generated code that was "nested too deeply to measure" --------------------


def test_three_thousand_nested_conditional_expressions_count_each_branch() -> None:
    facts = read(ifexp_chain(3_000))
    assert facts.parsed, facts.warnings
    assert facts.functions[0].complexity == 3_001
    assert len(facts.statements) == 2


def test_conditional_expressions_beyond_libcst_are_read_by_the_interpreters_reader_only() -> None:
    # libcst's own parser takes quadratic memory here (3,000 levels: 1.5 GB): it reads up to
    # 1,000 levels, and both readers agree there
    refused = python.parse_with_libcst("deep.py", ifexp_chain(3_000))
    assert not refused.parsed
    assert "takes at most 1,000" in refused.warnings[0].message
    source = ifexp_chain(900)
    assert python.parse_with_libcst("deep.py", source) == read(source)


def test_an_elif_chain_of_a_thousand_is_measured_alike_by_both_readers() -> None:
    source = elif_chain(1_000)
    facts = read(source)
    assert facts.parsed, facts.warnings
    assert facts.functions[0].complexity == 1_002  # 1 + the if + 1,000 elifs
    assert [s.kind for s in facts.statements].count("elif") == 1_000
    assert python.parse_with_libcst("deep.py", source) == facts


def test_an_else_holding_an_if_is_still_an_if() -> None:
    source = "def f(x):\n    if a:\n        pass\n    else:\n        if b:\n            pass\n"
    kinds = [s.kind for s in read(source).statements]
    assert kinds == ["def", "if", "pass", "if", "pass"]


# -- the limits -------------------------------------------------------------------------------


def test_a_tree_deeper_than_max_depth_is_refused_naming_the_limit() -> None:
    facts = read("x = 1\ny = " + " + ".join(["a"] * 1_000) + "\n", ParseLimits(max_depth=500))
    assert not facts.parsed
    (warning,) = facts.warnings
    assert warning.line == 2
    assert warning.message == (
        "Python source nested 1,000 levels deep; the limit is 500"
        " (raise limits.nesting, ParseLimits.max_depth, to measure it)"
    )


def test_the_interpreters_own_parser_limit_is_reported_as_such() -> None:
    # CPython's parser stops near 6,000 nested conditional expressions, below max_depth
    facts = read(ifexp_chain(7_000))
    assert not facts.parsed
    message = facts.warnings[0].message
    assert message.startswith("Python source nested 7,001 levels deep: more than the")


def test_a_small_stack_lowers_the_depth_limits(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(limits_module, "stack_bytes", lambda: 1 << 20)  # ulimit -s 1024
    assert python_limits.ast_depth(DEFAULT_LIMITS) == 5_000
    facts = read("x = a" + ".b" * 6_000 + "\n")
    assert facts.warnings[0].message == (
        "Python source nested 6,001 levels deep; the limit is 5,000 on this thread's stack"
        " (ulimit -s)"
    )
    assert read("x = a" + ".b" * 4_000 + "\n").parsed


def test_the_recursion_limit_is_put_back() -> None:
    before = sys.getrecursionlimit()
    read("x = a" + ".b" * 10_000 + "\n")
    read(NEWER + elif_chain(50))
    assert sys.getrecursionlimit() == before


def test_a_file_over_max_bytes_is_not_read() -> None:
    facts = read("x = 1\n" * 100, ParseLimits(max_bytes=500))
    assert not facts.parsed
    assert facts.warnings[0].message == (
        "file is 600 bytes; the limit is 500"
        " (raise limits.file-mb, ParseLimits.max_bytes, to measure it)"
    )


def test_libcst_reads_at_most_a_quarter_of_max_bytes() -> None:
    source = 'print "python 2"\n' * 100  # not Python 3: only libcst could try
    facts = read(source, ParseLimits(max_bytes=4_000))
    assert not facts.parsed
    (warning,) = facts.warnings
    assert warning.line == 1
    assert warning.message.startswith("Python syntax error at line 1: Missing parentheses")
    assert warning.message.endswith(
        "libcst, which reads the rest, reads at most 1,000 characters"
        " (a quarter of ParseLimits.max_bytes) and this file has 1,700"
    )


def test_limits_must_be_positive() -> None:
    with pytest.raises(ValueError, match="max_depth"):
        ParseLimits(max_depth=0)


# -- reproduction 4: call-site texts that grew with the square of a chain ---------------------


def test_a_chain_of_calls_shares_one_cut_text_instead_of_repeating_itself() -> None:
    facts = read("x = a" + ".m(1)" * 5_000 + "\n")
    assert facts.parsed
    assert len(facts.call_sites) == 5_000
    assert {site.name for site in facts.call_sites} == {"m"}
    longest = max(len(site.callee) for site in facts.call_sites)
    assert longest == shown.LIMIT + len(shown.CUT)
    receivers = [site.receiver or "" for site in facts.call_sites]
    cut = [receiver for receiver in receivers if receiver.endswith(shown.CUT)]
    assert len(cut) > 4_000
    assert len({id(receiver) for receiver in cut}) == 1  # one string, shared
    inner = [site.receiver for site in facts.call_sites[-3:]]  # the chain's start: whole
    assert inner == ["a . m ( 1 ) . m ( 1 )", "a . m ( 1 )", "a"]


def test_both_readers_cut_a_chain_alike() -> None:
    source = "x = a" + ".m(1)" * 450 + "\n"  # two levels a call: within libcst's 1,000
    facts = read(source)
    assert any(site.callee.endswith(shown.CUT) for site in facts.call_sites)
    assert python.parse_with_libcst("deep.py", source) == facts


def test_a_long_text_whose_calls_are_short_is_whole() -> None:
    entries = ", ".join(f"dict(a={i})" for i in range(300))
    facts = read(f"f([{entries}])\n")
    (outer,) = [site for site in facts.call_sites if site.callee == "f"]
    assert len(outer.arguments[0].text) > shown.LIMIT
    assert not outer.arguments[0].text.endswith(shown.CUT)


def test_a_cut_decides_as_the_whole_text_would() -> None:
    # h(f(x * 3000), k(1)): f is long, k is short
    tokens = ["h", "(", "f", "(", "x" * 3_000, ")", ",", "k", "(", "1", ")", ")"]
    texts = python_shown.Shown(tokens, precise=True)
    texts.note_call(0, 1, 12)
    texts.note_call(2, 3, 6)
    texts.note_call(7, 8, 11)
    assert texts.text(2, 11) == " ".join(tokens[2:11])[: shown.LIMIT] + shown.CUT
    assert texts.text(4, 11) == " ".join(tokens[4:11])  # long, but its one call is short


# -- the estimate of the nesting ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("source", "depth", "brackets"),
    [
        ("x = 1\n", 1, 0),
        ("x = [1, 2, 3]\n", 2, 1),
        ("f(a, b)\n", 3, 1),
        ("x = a + b + c\n", 3, 0),
        ("x = a + \\\n  b + \\\n  c\n", 3, 0),
        ("x = (((1)))\n", 4, 3),
        ("if a:\n    pass\nelif b:\n    x = 1\nelif c:\n    y = 2\n", 3, 0),
        ("x = f'{a}{b}'\n", 3, 0),
        (")))(((x", 5, 3),  # the first "(" follows a ")": a call
    ],
)
def test_the_nesting_is_counted_on_the_tokens(source: str, depth: int, brackets: int) -> None:
    found = nesting(source)
    assert (found.depth, found.brackets) == (depth, brackets)


@pytest.mark.security
def test_every_pathological_input_completes_under_an_address_space_limit() -> None:
    """As ``ulimit -v 2000000`` would: the child must finish, measured or refused."""
    for source in (
        "x = " + "(" * 10_000 + "1" + ")" * 10_000 + "\n",
        "x = a" + ".b" * 10_000 + "\n",
        "x = " + " + ".join(["a"] * 10_000) + "\n",
        ifexp_chain(3_000),
        elif_chain(1_000),
        NEWER + ifexp_chain(3_000),
        "x = a" + ".m(1)" * 8_000 + "\n",
    ):
        found = in_child(source, memory=2_000 * 1024 * 1024)
        assert found["parsed"] or found["warnings"]


@pytest.mark.security
def test_a_flat_file_too_large_for_the_worker_says_memory_ran_out(tmp_path: Path) -> None:
    """150,000 one-line statements (2.5 million in the report that found it) nest one level
    deep: the interpreter's parser runs out of the worker's memory (80 MiB here), and the
    warning says so, not "nested 1 levels deep"."""
    (tmp_path / "flat.py").write_text("x = 1\n" * 150_000)
    config = "[tool.archmetrics.limits]\nworker-memory-mb = 80\n"
    (tmp_path / "pyproject.toml").write_text(config)
    run = run_main(["scan", "flat.py", "--format", "json", "--no-cache"], tmp_path)
    assert run.code == 0, run.err
    (facts,) = json.loads(run.out)["files"]
    message = facts["warnings"][0]["message"]
    assert not facts["parsed"] and "levels deep" not in message
    assert message.startswith("Python source of 150,000 lines and 900,000 characters: the")
    assert "ran out of memory (MemoryError)" in message and "worker-memory-mb" in message
