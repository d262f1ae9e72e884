"""The two Python readers give the same facts on real code, and the one-regex lexer the same
tokens as ``tokenize``.

The ``ast`` reader (python_ast.py) reads every file the running interpreter parses; libcst's
(python_walk.py) reads the rest, so a file's facts must not depend on which one read it. The
corpus is real code: this project's own, and installed packages nobody here wrote (a fixed,
sorted selection, as in test_python_oracle.py).
"""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

from archmetrics.parsers import python, python_ast, python_lex
from tests.parsers.test_python_oracle import SITE_PACKAGES

ROOT = Path(__file__).resolve().parents[2]
PACKAGES = (("rich", 50), ("git", 30), ("libcst", 60), ("pandas/core", 50), ("hypothesis", 30))


def corpus() -> list[Path]:
    files = sorted(
        path
        for folder in ("archmetrics", "robosoa", "fixtures", "tests")
        for path in (ROOT / folder).rglob("*.py")
    )
    for package, limit in PACKAGES:
        found = sorted((SITE_PACKAGES / package).rglob("*.py"))
        files.extend(found[: limit * 2 : 2])
    return files


def read(path: Path) -> str:
    source = path.read_bytes().decode("utf-8-sig", "replace")
    return source.replace("\r\n", "\n").replace("\r", "\n")


@pytest.mark.slow
def test_both_readers_give_the_same_facts_on_real_code() -> None:
    files = corpus()
    assert len(files) > 400, f"corpus too small ({len(files)} files): packages missing?"
    compared, differing = 0, []
    for path in files:
        source = read(path)
        tree = python._standard_tree(source)
        through_libcst = python.parse_with_libcst(str(path), source)
        if tree is None or not through_libcst.parsed:
            continue
        compared += 1
        if python_ast.read(str(path), source, tree) != through_libcst:
            differing.append(str(path))
    assert compared > 400
    assert differing == []


@pytest.mark.skipif(sys.version_info >= (3, 12), reason="the one-regex lexer is for 3.11")
def test_the_one_regex_lexer_finds_the_tokens_tokenize_finds() -> None:
    files = corpus()
    for path in files:
        source = read(path)
        regex, standard = (python_lex.Tokens.__new__(python_lex.Tokens) for _ in range(2))
        for tokens in (regex, standard):
            tokens.closing, tokens.multiline = {}, []
            tokens.text, tokens.starts, tokens.ends, tokens.offsets = [], [], [], []
        try:
            python_lex._read_tokenize(standard, source, 1)
        except python_lex.Unreadable:
            continue  # not Python tokenize reads; nor does the regex, below
        assert python_lex._scan(regex, source, 1), path
        python_lex._finish(regex)
        python_lex._finish(standard)
        for name in ("text", "starts", "ends", "offsets", "multiline", "closing"):
            assert getattr(regex, name) == getattr(standard, name), (path, name)


def test_a_file_the_ast_reader_cannot_line_up_is_read_by_libcst() -> None:
    # a variation selector in a name: Python accepts it, its tokenizer does not
    facts = python.parse("odd.py", "x\U000e0100 = 1\nprint(x\U000e0100)\n")
    assert facts.parsed and facts.loc == 2
    assert [c.callee for c in facts.call_sites] == ["print"]


@pytest.mark.skipif(sys.version_info >= (3, 12), reason="needs an interpreter without PEP 695")
def test_syntax_newer_than_the_interpreter_is_read_by_libcst() -> None:
    facts = python.parse("new.py", "def first[T](items: list[T]) -> T:\n    return items[0]\n")
    assert facts.parsed
    assert [(s.kind, s.text) for s in facts.statements] == [
        ("def", "def first [ T ] ( items : list [ T ] ) -> T :"),
        ("return", "return items [ 0 ]"),
    ]


def test_names_are_kept_as_written() -> None:
    # Python reads the full-width name as "www"; the facts keep what the author wrote
    facts = python.parse("wide.py", "def ｗｗｗ():\n    return ｇ(1)\n")
    assert [f.name for f in facts.functions] == ["ｗｗｗ"]
    assert [c.callee for c in facts.call_sites] == ["ｇ"]


@pytest.mark.skipif(sys.version_info < (3, 12), reason="PEP 701 f-strings need Python 3.12")
def test_both_readers_agree_on_pep_701_fstrings() -> None:
    source = (
        "def f(d, items):\n"
        '    a = f"{d["key"]}"\n'
        "    b = f\"{'\\n'.join(x for x in items if x)}\"\n"
        '    c = f"{  # a comment\n'
        "        g(1,\n"
        '          2) if d else h(d["k"] or 3)\n'
        '    }"\n'
        "    e = (\n"
        '        f"{f"{d[\'x\']}"}"\n'
        "    )\n"
        '    return f"{a!r:>{width(1)}} {b=}" + c + e\n'
    )
    tree = python._standard_tree(source)
    assert tree is not None
    facts = python_ast.read("pep701.py", source, tree)
    assert facts == python.parse_with_libcst("pep701.py", source)
    assert [c.callee for c in facts.call_sites] == ["'\\n' . join", "g", "h", "width"]
    (function,) = facts.functions
    assert [(d.kind, d.line) for d in function.decisions] == [
        ("comp_for", 3),
        ("comp_if", 3),
        ("ifexp", 5),
        ("or", 6),
    ]
