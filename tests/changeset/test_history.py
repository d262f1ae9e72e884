"""Per-element figures over a history, and the step records the cache keeps (pure)."""

from __future__ import annotations

import json

import pytest

from archmetrics.changeset.history import (
    CommitStep,
    element_totals,
    step_from_record,
    step_record,
)
from archmetrics.changeset.locations import Location
from archmetrics.changeset.model import ElementChange, Metrics, Status, Summary


def _summary(loc_scale: float | None, vg_scale: float | None) -> Summary:
    return Summary(0, 0, 0, 0, 100, 110, loc_scale, 1, 0, 0, 1, 1.0, 50, 52, vg_scale, 2, 2.0,
                   0.5, ("a note",), unparsed=2)  # fmt: skip


def _element(name: str, vg_pre: int, vg_post: int, added: int, removed: int = 0) -> ElementChange:
    return ElementChange(
        name, Location.BASE, (f"{name}.c",), Status.MODIFIED,
        Metrics(10, 12, vg_pre), Metrics(11, 13, vg_post), added, removed, 0,
    )  # fmt: skip


def _step(loc_scale: float | None, vg_scale: float | None, *elements: ElementChange) -> CommitStep:
    summary = _summary(loc_scale, vg_scale)
    return CommitStep({k: summary for k in ("base", "new", "framework", "total")}, elements)


def test_an_elements_totals_scale_each_commit_by_its_locations_factors() -> None:
    steps = [
        _step(1.1, 2.0, _element("a", 5, 8, added=4)),  # Γ' = 4.4, ΔVg' = 6
        _step(None, None, _element("a", 8, 9, added=2, removed=1)),  # scales taken as 1: 3, 1
        _step(0.5, 1.0, _element("b", 3, 3, added=10)),  # Γ' = 5, ΔVg' = 0
    ]
    a, b = element_totals(steps)
    found = {t.element: t for t in (a, b)}
    assert found["a"].commits == 2
    assert found["a"].scaled_changes == pytest.approx(4.4 + 3.0)
    assert found["a"].scaled_delta_vg == pytest.approx(6.0 + 1.0)
    assert found["a"].cost == pytest.approx(7.4 / 7.0)
    assert (found["b"].scaled_changes, found["b"].cost) == (5.0, 0.0)  # eq. 6.38's case
    assert [t.element for t in (a, b)] == ["a", "b"]  # by ΣΓ'


def test_an_element_back_where_it_started_costs_zero_not_the_scales_rounding() -> None:
    steps = [
        _step(1.0, 1.00001, _element("a", 5, 7, added=8)),
        _step(1.0, 1.00002, _element("a", 7, 5, added=0, removed=8)),
    ]
    (only,) = element_totals(steps)
    assert only.scaled_delta_vg != 0.0 and only.cost == 0.0


def test_a_record_round_trips_and_a_strange_one_is_refused() -> None:
    step = _step(1.1, None, _element("a", 5, 8, added=4))
    record = json.loads(json.dumps(step_record(step)))
    assert set(record["locations"]["total"]) == set(step.summaries["total"].to_dict())
    assert step_from_record(record) == step
    assert json.dumps(step_record(step_from_record(record))) == json.dumps(step_record(step))
    broken = json.loads(json.dumps(record))
    broken["locations"]["total"]["cost"] = "high"
    assert step_from_record(broken) is None
    broken = json.loads(json.dumps(record))
    broken["elements"][0]["status"] = "exploded"
    assert step_from_record(broken) is None
    assert step_from_record({**record, "schema": "history-step/0"}) is None
    assert step_from_record([1, 2]) is None
