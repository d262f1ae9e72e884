"""`archmetrics docs [TOPIC]`: the pages installed with archmetrics (tests/test_packaging.py
checks them in an installed wheel; here, in the checkout)."""

from __future__ import annotations

from pathlib import Path

import pytest

from archmetrics.cli import main

DOCS = Path(__file__).resolve().parents[2] / "docs"


def test_the_list_names_every_page(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["docs"]) == 0
    out = capsys.readouterr().out
    assert f"installed in {DOCS}:" in out
    for page in DOCS.rglob("*.md"):
        topic = page.relative_to(DOCS).with_suffix("").as_posix()
        assert f"  {topic} " in out, topic
    assert "JSON Schemas of the reports:" in out


def test_a_page_prints_whole_and_by_path(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["docs", "ci.md"]) == 0
    assert capsys.readouterr().out == (DOCS / "ci.md").read_text(encoding="utf-8")
    assert main(["docs", "subjects/wdb", "--path"]) == 0
    assert capsys.readouterr().out == f"{DOCS / 'subjects' / 'wdb.md'}\n"


def test_an_unknown_page_is_one_line_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["docs", "../README"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "no page '../README' (pages: api, architecture, ci," in err
