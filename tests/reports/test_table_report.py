"""Tables that fit the terminal: names wrap and are never cut, numbers are never cut, and the
columns left out on a narrow terminal are named."""

from __future__ import annotations

import pytest

from archmetrics.reports.table_report import rows_table, to_text

HEADER = ("element", "location", "status", "λ pre", "λ post", "Γ_A", "s_a", "s_e", "d_a")
ROWS = [
    ["robosoa/services/world_database/very_long_module_name.py", "framework", "modified",
     "1234", "123456", "99", "3→5", "13→15", "0"],
    ["a.py", "base", "added", "-", "7", "7", "-→1", "-→2", "-→0"],
]  # fmt: skip


@pytest.mark.parametrize("width", [60, 80, 100, 120])
def test_a_table_fits_the_width_without_cutting_a_name_or_a_number(width: int) -> None:
    table = rows_table("elements", HEADER, ROWS, 3, width, ("d_a", "s_e"))
    text = to_text(table, width=width)
    lines = text.splitlines()
    assert all(len(line) <= width for line in lines)
    assert "…" not in text
    first = "".join(line.split("│")[1].strip() for line in lines if line.startswith("│"))
    assert "robosoa/services/world_database/very_long_module_name.py" in first  # wrapped, whole
    shown = [str(column.header) for column in table.columns]
    assert ("123456" in text) == ("λ post" in shown)  # a number is shown whole or not at all
    words = " ".join(text.split())
    if len(shown) < len(HEADER):
        left_out = ", ".join(name for name in HEADER if name not in shown)
        assert f"{left_out} left out at {width} columns (--format json has them)" in words
    else:
        assert "left out" not in words


def test_the_least_useful_columns_go_first_then_the_rightmost() -> None:
    table = rows_table("elements", HEADER, ROWS, 3, 80, ("d_a", "s_e"))
    shown = [str(column.header) for column in table.columns]
    assert "d_a" not in shown and "s_e" not in shown
    assert shown[:3] == ["element", "location", "status"]
    assert table.caption is not None and str(table.caption).startswith("s_e, d_a")


def test_a_wide_terminal_shows_every_column() -> None:
    table = rows_table("elements", HEADER, ROWS, 3, 200)
    assert [str(column.header) for column in table.columns] == list(HEADER)
    assert table.caption is None
