"""The legend and the glossary say what each number means: every term the reports' legend and
the SARIF help draw on (reports/glossary.py) is explained on docs/glossary.md, which ships
(`archmetrics docs glossary`), and every gate field has a meaning in plain words."""

from __future__ import annotations

from pathlib import Path

import pytest

from archmetrics.changeset.gates import NUMERIC_FIELDS
from archmetrics.cli import main
from archmetrics.complexity.thresholds import FIELDS
from archmetrics.reports.glossary import TERMS, meaning

PAGE = (Path(__file__).resolve().parents[2] / "docs" / "glossary.md").read_text("utf-8")


@pytest.mark.parametrize("term", TERMS, ids=lambda t: t.field)
def test_every_term_is_on_the_page(term: object) -> None:
    field, symbol = term.field, term.symbol
    assert f"`{field}`" in PAGE
    assert all(part.strip() in PAGE for part in symbol.split(","))


def test_every_gate_field_has_a_meaning_in_plain_words() -> None:
    fields = set(NUMERIC_FIELDS) | {f for unit in FIELDS.values() for f in unit}
    for field in fields:
        assert meaning(field) != field, field  # not the bare name
        assert f"`{field}`" in PAGE, field


def test_the_page_is_installed_and_printed(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["docs", "glossary"]) == 0
    assert capsys.readouterr().out == PAGE
