"""Fixtures for the parser tests."""

from __future__ import annotations

import ast
import warnings

import pytest

from archmetrics.parsers import python
from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits


@pytest.fixture(params=["ast", "libcst"])
def python_reader(request: pytest.FixtureRequest, monkeypatch: pytest.MonkeyPatch) -> str:
    """Runs a test once per Python reader: the standard library's (``ast``), which reads
    what the running interpreter parses, and libcst's, which reads the rest. Both must
    give the same facts. Under ``ast``, a fall-back to libcst on source the interpreter
    parses fails the test: the ``ast`` reader gave up where it should not have."""
    if request.param == "libcst":
        monkeypatch.setattr(python, "_standard_tree", lambda source, depth=0: None)
        return "libcst"
    through_libcst = python.parse_with_libcst

    def strict(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> object:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                ast.parse(source)
            except (SyntaxError, ValueError, RecursionError, MemoryError):
                return through_libcst(path, source, limits)
        raise AssertionError(f"the ast reader fell back to libcst on {path}")

    monkeypatch.setattr(python, "parse_with_libcst", strict)
    return "ast"
