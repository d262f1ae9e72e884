"""libcst's per-node validation is skipped while parsing (a quarter of ``parse_module``):
the facts must be the same as with it, and nodes built anywhere else are still checked."""

from __future__ import annotations

import contextlib
from pathlib import Path

import libcst as cst
import pytest

from archmetrics.parsers import python

ROOT = Path(__file__).resolve().parents[2]
SOURCES = sorted(
    path
    for path in [*(ROOT / "fixtures").rglob("*.py"), *(ROOT / "archmetrics").rglob("*.py")]
    if path.stat().st_size > 300  # not the empty __init__.py files
)


def test_the_sample_is_real_code() -> None:
    assert len(SOURCES) > 120


@pytest.mark.parametrize("path", SOURCES[::3], ids=lambda p: str(p.relative_to(ROOT)))
def test_facts_are_the_same_as_with_libcst_validating_every_node(
    path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    source = path.read_text(encoding="utf-8")
    fast = python.parse_with_libcst(str(path), source)
    monkeypatch.setattr(python, "_unvalidated_nodes", contextlib.nullcontext)
    assert python.parse_with_libcst(str(path), source) == fast
    assert fast.parsed and fast.statements


@pytest.mark.parametrize("source", ["x = 1\n", "def f(:\n"], ids=["parsed", "syntax-error"])
def test_nodes_built_by_hand_are_still_validated_after_a_parse(source: str) -> None:
    python.parse_with_libcst("m.py", source)
    with pytest.raises(cst.CSTValidationError):
        cst.Name("")
