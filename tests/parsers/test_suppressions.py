"""The reviewed-function comment `archmetrics: ignore[FIELDS]`: read by the parser layer
into each function's `suppressed` fact, for C, C++ and Python, on the definition's first line
or the comment lines right above it (Python: its decorators too), and nowhere else."""

from __future__ import annotations

import pytest

from archmetrics.facts import FileFacts
from archmetrics.parsers.registry import LanguageTable, parse_source
from archmetrics.sources.codec import decode, encode

TABLE = LanguageTable.default({})


def _suppressed(path: str, source: str, language: str) -> dict[str, tuple[str, ...]]:
    facts = parse_source(path, source.encode(), language, TABLE)
    return {f.qualified_name: f.suppressed for f in facts.functions}


PYTHON = """\
# reviewed: a dispatch table
# archmetrics: ignore[vg]
@cache
def above(a):
    return a


def inline(b):  # archmetrics: ignore
    return b


def body(c):
    # archmetrics: ignore[vg]  (inside the body: not on or above the definition)
    return c


def text():
    return "# archmetrics: ignore[vg]"


x = 1  # archmetrics: ignore[vg]
def after_code(d):
    return d
"""

C = """\
int inline_c(int a) { return a; }  // archmetrics: ignore[vg, loc]

/* reviewed:
 * archmetrics: ignore[vg]
 */
static int
block(int b)
{
    return b;
}

int plain(int c) { return c; }
"""

CPP = """\
// archmetrics: ignore[loc]
int Motor::drive(int a)
{
    return a;
}
const char *s = "// archmetrics: ignore";
int Motor::stop() { return 0; }
"""


def test_python() -> None:
    assert _suppressed("m.py", PYTHON, "python") == {
        "above": ("vg",),  # above its decorator
        "inline": ("*",),  # `ignore` alone: every field
        "body": (),
        "text": (),
        "after_code": (),  # the line above is code, not a comment
    }


def test_c_and_cpp() -> None:
    assert _suppressed("m.c", C, "c") == {
        "inline_c": ("vg", "loc"),
        "block": ("vg",),  # a block comment's continuation line, above `static int`
        "plain": (),
    }
    assert _suppressed("m.cpp", CPP, "cpp") == {"Motor::drive": ("loc",), "Motor::stop": ()}


@pytest.mark.parametrize(("path", "source", "language"), [("m.py", PYTHON, "python"),
                                                          ("m.c", C, "c")])  # fmt: skip
def test_the_fact_survives_the_cache(path: str, source: str, language: str) -> None:
    facts: FileFacts = parse_source(path, source.encode(), language, TABLE)
    assert decode(encode(facts), path).functions == facts.functions
