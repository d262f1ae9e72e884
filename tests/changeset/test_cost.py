"""Chapter 6 arithmetic against hand-computed values, field by field, including open cases."""

from __future__ import annotations

import json

import pytest

from archmetrics.changeset.cost import Sums, location_summary, total_summary
from archmetrics.changeset.model import SUMMARY_FIELDS, Metrics, Summary


def codes(summary: Summary) -> list[str]:
    return [note.split(":", 1)[0] for note in summary.notes]


BASE = Sums(
    pre=Metrics(loc=100, sloc=120, vg=20, s_a=3, s_e=4, d_a=1, d_e=0),
    post=Metrics(loc=110, sloc=130, vg=24, s_a=5, s_e=4, d_a=2, d_e=3),
    added=12,
    removed=2,
    modified=5,
)
NEW = Sums(
    pre=Metrics(),
    post=Metrics(loc=40, sloc=50, vg=6, s_e=2, d_e=1),
    added=40,
    removed=0,
    modified=0,
)


def test_ordinary_location() -> None:
    s = location_summary(BASE)
    assert (s.delta_s_a, s.delta_s_e, s.delta_d_a, s.delta_d_e) == (2, 0, 1, 3)  # 6.1-6.9
    assert (s.loc_pre, s.loc_post) == (100, 110)
    assert s.loc_scale == pytest.approx(1.1)  # 110 / 100 (6.20)
    assert (s.added, s.removed, s.modified, s.changes) == (12, 2, 5, 19)  # 6.15-6.18
    assert s.scaled_changes == pytest.approx(20.9)  # 1.1 * 19 (6.25)
    assert (s.vg_pre, s.vg_post, s.delta_vg) == (20, 24, 4)  # 6.30
    assert s.vg_scale == pytest.approx(1.2)  # 24 / 20 (6.33)
    assert s.scaled_delta_vg == pytest.approx(4.8)  # 1.2 * 4 (6.35)
    assert s.cost == pytest.approx(20.9 / 4.8)  # 6.37
    assert s.notes == ()


def test_location_with_nothing_before_uses_unit_scales_and_says_so() -> None:
    s = location_summary(NEW)
    assert (s.delta_s_a, s.delta_s_e, s.delta_d_a, s.delta_d_e) == (0, 2, 0, 1)
    assert (s.loc_pre, s.loc_post, s.loc_scale) == (0, 40, None)
    assert (s.changes, s.scaled_changes) == (40, 40.0)
    assert (s.vg_pre, s.vg_post, s.vg_scale, s.delta_vg, s.scaled_delta_vg) == (0, 6, None, 6, 6.0)
    assert s.cost == pytest.approx(40 / 6)
    assert codes(s) == ["loc_scale_undefined_pre_zero", "vg_scale_undefined_pre_zero"]


def test_negative_complexity_change_gives_negative_cost_with_a_note() -> None:
    s = location_summary(Sums(Metrics(loc=50, vg=10), Metrics(loc=40, vg=8), 0, 10, 2))
    assert (s.changes, s.loc_scale) == (12, 0.8)
    assert s.scaled_changes == pytest.approx(9.6)
    assert (s.delta_vg, s.vg_scale) == (-2, 0.8)
    assert s.scaled_delta_vg == pytest.approx(-1.6)
    assert s.cost == pytest.approx(-6.0)
    assert codes(s) == ["cost_negative_complexity_decreased"]


def test_no_complexity_change_means_zero_cost_by_6_38() -> None:
    s = location_summary(Sums(Metrics(loc=10, vg=3), Metrics(loc=11, vg=3), 1, 0, 0))
    assert s.scaled_changes == pytest.approx(1.1)
    assert (s.delta_vg, s.vg_scale, s.scaled_delta_vg, s.cost) == (0, 1.0, 0.0, 0.0)
    assert codes(s) == ["cost_zero_no_complexity_change"]


def test_location_deleted_entirely() -> None:
    s = location_summary(Sums(Metrics(loc=30, vg=5, s_e=2), Metrics(), 0, 30, 0))
    assert (s.loc_scale, s.changes, s.scaled_changes) == (0.0, 30, 0.0)
    assert (s.delta_vg, s.vg_scale, s.scaled_delta_vg, s.cost) == (-5, 0.0, 0.0, 0.0)
    assert str(s.scaled_delta_vg) == "0.0"  # not -0.0
    assert s.delta_s_e == -2
    assert codes(s) == ["loc_scale_zero_post_empty", "vg_scale_zero_post_empty"]


def test_empty_location_is_all_zero_with_undefined_scales() -> None:
    s = location_summary(Sums(Metrics(), Metrics(), 0, 0, 0), notes=("carried: along",))
    assert (s.changes, s.scaled_changes, s.scaled_delta_vg, s.cost) == (0, 0.0, 0.0, 0.0)
    assert (s.loc_scale, s.vg_scale) == (None, None)
    assert codes(s) == ["carried", "location_empty"]


def test_total_scales_come_from_total_sizes_not_from_location_sums() -> None:
    base, new = location_summary(BASE), location_summary(NEW)
    empty = location_summary(Sums(Metrics(), Metrics(), 0, 0, 0))
    t = total_summary([base, new, empty])
    assert (t.delta_s_a, t.delta_s_e, t.delta_d_a, t.delta_d_e) == (2, 2, 1, 4)  # 6.3-6.10
    assert (t.added, t.removed, t.modified, t.changes) == (52, 2, 5, 59)  # 6.11-6.14
    assert (t.loc_pre, t.loc_post, t.loc_scale) == (100, 150, 1.5)  # 6.19
    assert t.scaled_changes == pytest.approx(88.5)  # 1.5 * 59 (6.21)
    assert t.scaled_changes != pytest.approx(base.scaled_changes + new.scaled_changes)  # 60.9
    assert (t.vg_pre, t.vg_post, t.delta_vg, t.vg_scale) == (20, 30, 10, 1.5)  # 6.29, 6.32
    assert t.scaled_delta_vg == pytest.approx(15.0)  # 6.34
    assert t.cost == pytest.approx(88.5 / 15.0)  # 6.36
    assert t.notes == ()


def test_to_dict_is_the_json_contract() -> None:
    s = location_summary(NEW)
    d = s.to_dict()
    assert tuple(d) == (*SUMMARY_FIELDS, "unparsed")  # unparsed: set by the diff use case
    assert d["loc_scale"] is None and d["vg_scale"] is None
    assert isinstance(d["scaled_changes"], float) and isinstance(d["cost"], float)
    assert isinstance(d["changes"], int) and isinstance(d["notes"], list)
    round_trip = json.loads(json.dumps(d))
    assert round_trip["loc_scale"] is None and round_trip["notes"][0].startswith("loc_scale_")
