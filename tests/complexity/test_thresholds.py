"""Scan thresholds (``--fail-on 'vg(function) > 15'``): read, refused with a reason, checked."""

from __future__ import annotations

import re

import pytest

from archmetrics.complexity.thresholds import (
    ThresholdError,
    Unit,
    check_thresholds,
    parse_threshold,
)

F = [
    Unit("small", "a.c", 1, {"vg": 2, "loc": 10}),
    Unit("branchy", "a.c", 20, {"vg": 12, "loc": 30}),
    Unit("long", "b.c", 5, {"vg": 4, "loc": 90}),
    Unit("both", "b.c", 99, {"vg": 16, "loc": 80}),
]


def _failing(text: str) -> list[str]:
    return [f.unit.name for f in check_thresholds([parse_threshold(text)], {"function": F})]


@pytest.mark.parametrize(
    ("text", "failing"),
    [  # worst first: the furthest past the limit of its first failing condition, relative
        # to the limit (both: (16 - 10) / 10 = 0.6 before branchy's 0.2)
        ("vg(function) > 10", ["both", "branchy"]),
        ("vg(function) >= 12", ["both", "branchy"]),
        ("loc(function) > 60 and vg(function) > 10", ["both"]),
        # long by loc (30 / 60 = 0.5), both by loc (20 / 60), branchy by vg (2 / 10)
        ("loc(function) > 60 or vg(function) > 10", ["long", "both", "branchy"]),
        # `and` binds tighter: small fails by the first group alone (==: 0 past its limit)
        ("vg(function) == 2 or loc(function) > 60 and vg(function) > 10", ["both", "small"]),
        ("  vg ( function )<3  ", ["small"]),
        ("vg(function) != 2", ["branchy", "long", "both"]),
        ("vg(function) > 1e3", []),
    ],
)
def test_a_threshold_fails_the_units_it_holds_for(text: str, failing: list[str]) -> None:
    assert _failing(text) == failing


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        ("vg > 15", "is not FIELD(UNIT) OP NUMBER"),
        ("vg(method) > 15", "unknown unit 'method'"),
        ("sloc(function) > 15", "a function has no 'sloc'"),
        ("vg(function) > 15 and loc(file) > 9", "must name one unit"),
        ("vg(function) > 15 and", "is not FIELD(UNIT) OP NUMBER"),
        ("vg(function) >> 15", "is not FIELD(UNIT) OP NUMBER"),
        ("", "is not FIELD(UNIT) OP NUMBER"),
    ],
)
def test_a_threshold_that_cannot_be_read_says_why(text: str, reason: str) -> None:
    with pytest.raises(ThresholdError, match=re.escape(reason)):
        parse_threshold(text)


def test_a_failure_names_the_unit_where_it_is_and_the_numbers_read() -> None:
    threshold = parse_threshold("loc(function) > 60 and vg(function) > 10")
    [failure] = check_thresholds([threshold], {"function": F})
    text = "gate failed: loc(function) > 60 and vg(function) > 10: b.c:99 both (loc = 80, vg = 16)"
    assert str(failure) == text
    file = parse_threshold("loc(file) > 5")
    [failure] = check_thresholds([file], {"file": [Unit("b.c", "b.c", None, {"loc": 170})]})
    assert str(failure) == "gate failed: loc(file) > 5: b.c (loc = 170)"
    total = parse_threshold("vg(total) > 5")
    assert check_thresholds([total], {"function": F}) == ()  # no unit of that kind: nothing
