"""compute_change on real snippets through the real parsers and the real coupling layer.

A small integration: base code (client/) starts using a new store (wdb/, Python) and a new
framework component (proxy/link.h + proxy/link.c, C). Every number below is worked by hand.
"""

from __future__ import annotations

import pytest

from archmetrics.changeset import (
    ChangeReport,
    FilePair,
    Location,
    LocationRules,
    Status,
    compute_change,
    coupling_by_element,
)
from archmetrics.coupling.measure import measure_coupling
from archmetrics.facts import FileFacts
from tests.harness import facts_of

PRE = {
    "client/main.py": """\
import client.util

def run(xs):
    total = 0
    for x in xs:
        total += client.util.scale(x)
    return total
""",
    "client/util.py": """\
def scale(x):
    return 2 * x
""",
}
POST = {
    **PRE,
    "client/main.py": """\
import client.util
import wdb.store

def run(xs):
    # sum, then store it
    total = 0
    for x in xs:
        total += client.util.scale(x)
    if total:
        wdb.store.put(total)
    return total
""",
    "wdb/store.py": """\
_DATA = []

def put(v):
    if v is None:
        return False
    _DATA.append(v)
    return True
""",
    "proxy/link.h": """\
#ifndef LINK_H
#define LINK_H
int link_send(int v);
#endif
""",
    "proxy/link.c": """\
#include "link.h"

int link_send(int v)
{
    if (v < 0) {
        return -1;
    }
    return v;
}
""",
}
RULES = LocationRules.from_mapping({"new": ["wdb/**"], "framework": ["proxy/**"]})


def _tree(sources: dict[str, str]) -> dict[str, FileFacts]:
    language = {"py": "python", "c": "c", "h": "c"}
    return {p: facts_of(s, language[p.rsplit(".", 1)[1]], p) for p, s in sources.items()}


@pytest.fixture(scope="module")
def report() -> ChangeReport:
    pre, post = _tree(PRE), _tree(POST)
    pairs = [FilePair(pre.get(p), post.get(p)) for p in sorted(pre.keys() | post.keys())]
    coupling_pre = coupling_by_element(measure_coupling(list(pre.values())))
    coupling_post = coupling_by_element(measure_coupling(list(post.values())))
    return compute_change(pairs, None, RULES, coupling_pre, coupling_post)


def test_elements(report: ChangeReport) -> None:
    summary = {
        e.element: (e.location, e.status, e.added, e.removed, e.modified) for e in report.elements
    }
    assert summary == {
        # + import wdb.store, + if total:, + wdb.store.put(total); the comment counts nothing
        "client/main.py": (Location.BASE, Status.MODIFIED, 3, 0, 0),
        "client/util.py": (Location.BASE, Status.UNCHANGED, 0, 0, 0),
        "wdb/store.py": (Location.NEW, Status.ADDED, 6, 0, 0),
        # header and implementation form one component
        "proxy/link": (Location.FRAMEWORK, Status.ADDED, 6, 0, 0),
    }
    link = next(e for e in report.elements if e.element == "proxy/link")
    assert link.files == ("proxy/link.c", "proxy/link.h")
    assert link.pre is None and link.post is not None and link.post.vg == 2


def test_base(report: ChangeReport) -> None:
    s = report.location(Location.BASE)
    assert (s.loc_pre, s.loc_post, s.changes) == (8, 11, 3)  # main 6 -> 9, util 2
    assert s.loc_scale == 11 / 8 and s.scaled_changes == 3 * 11 / 8
    assert (s.vg_pre, s.vg_post, s.delta_vg) == (3, 4, 1)
    assert s.scaled_delta_vg == pytest.approx(4 / 3)
    assert s.cost == pytest.approx(4.125 / (4 / 3))  # 3.09375
    assert (s.delta_s_a, s.delta_s_e) == (0, 1)  # main now also imports wdb.store
    assert s.notes == ()


def test_new(report: ChangeReport) -> None:
    s = report.location(Location.NEW)
    assert (s.loc_pre, s.loc_post, s.loc_scale, s.scaled_changes) == (0, 6, None, 6.0)
    assert (s.vg_pre, s.vg_post, s.vg_scale, s.scaled_delta_vg, s.cost) == (0, 2, None, 2.0, 3.0)
    assert (s.delta_s_a, s.delta_s_e) == (1, 0)  # imported by client/main.py
    assert [n.split(":")[0] for n in s.notes] == [
        "loc_scale_undefined_pre_zero",
        "vg_scale_undefined_pre_zero",
    ]


def test_total_rescales_from_total_sizes(report: ChangeReport) -> None:
    t = report.total
    assert (t.loc_pre, t.loc_post, t.changes) == (8, 23, 15)  # + 6 (wdb) + 6 (proxy)
    assert t.loc_scale == 23 / 8 and t.scaled_changes == pytest.approx(15 * 23 / 8)
    assert (t.vg_pre, t.vg_post, t.delta_vg, t.vg_scale) == (3, 8, 5, 8 / 3)
    assert t.cost == pytest.approx((15 * 23 / 8) / (5 * 8 / 3))
    parts = sum(s.scaled_changes for _, s in report.locations)
    assert parts == pytest.approx(4.125 + 6 + 6) and t.scaled_changes != pytest.approx(parts)
