"""reports/json_report.py's text: json's own indent=2 rendering, byte for byte, whoever writes
it (orjson in C where it can, json where orjson would spell a value otherwise)."""

from __future__ import annotations

import json
import re
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from archmetrics.cli import main
from archmetrics.reports.json_report import _indented, dumps, short_exponent
from tests.gitrepo import GitRepo


def _reference(document: Any) -> str:
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


@pytest.mark.parametrize(
    "document",
    [
        {"text": 'x\x00\x1f\x7f\x85\u2028 é \t\n"\\/', "empty": [], "none": {}, "n": [1, None]},
        {"floats": [0.1, 2.5, 1 / 3, 1e16, 1e22, 5e-324, 123456789.123, -0.0]},
        {"small": [1e-05, 1e-07, 2.5e-09]},  # json spells 1e-07, orjson 1e-7: json writes it
        {"lone surrogate": "\ud800"},  # not UTF-8: json writes it, escaped afterwards
        {"big": 2**70, "bools": [True, False]},  # past 64 bits: json writes it
        {"nested": [{"a": [{"b": {"c": []}}]}], "unicode": "Γ' ΔVg' → ✓"},
    ],
)
def test_the_text_is_jsons_indent_2(document: dict[str, Any]) -> None:
    assert _indented(document) == _reference(document)


def test_a_lone_surrogate_and_c1_controls_come_out_escaped() -> None:
    text = dumps({"name": "a\ud800b\x85c"})
    assert text == '{\n  "name": "a\\ud800b\\u0085c"\n}\n'
    text.encode("utf-8")  # printable and valid UTF-8


def test_a_real_diff_report_is_written_as_json_would(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    repo.commit("one", tag="v1", files={"a.py": "x = 1\n", "b.c": "int f(void) { return 0; }\n"})
    repo.commit(
        "two",
        tag="v2",
        files={"a.py": "x = 2\nif x:\n    x = 3\n", "b.c": "int f(int a) { return a ? 1 : 0; }\n"},
    )
    out = tmp_path / "diff.json"
    argv = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2", "-q", "--no-cache"]
    assert main([*argv, "-o", str(out)]) == 0
    written = out.read_text(encoding="utf-8")
    assert written == _reference(json.loads(written))


@given(st.text(alphabet="01e-9 x٣", max_size=40))
def test_a_short_exponent_is_found_as_the_regular_expression_finds_it(text: str) -> None:
    """The look for orjson's one-digit exponents (``1e-7``) agrees with the pattern it
    replaced, ASCII digits only (``٣`` is a digit to ``str.isdigit``, not to ``[0-9]``)."""
    assert short_exponent(text) == bool(re.search(r"[0-9]e-[0-9](?![0-9])", text))


def test_ascii_text_with_del_is_still_escaped() -> None:
    assert dumps({"name": "a\x7fb"}) == '{\n  "name": "a\\u007fb"\n}\n'
