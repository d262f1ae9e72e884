"""Unchanged elements reported from their rows (changeset/unchanged.py): a comparison that
pairs only the elements holding a changed file and gives the others as rows reports what
the comparison pairing every file reports, on the study's real subjects."""

from __future__ import annotations

import json
import zlib
from collections.abc import Mapping
from itertools import pairwise
from pathlib import Path

import pytest
from hypothesis import given
from hypothesis import strategies as st

from archmetrics.changeset import ChangeReport, LocationRules, compute_change
from archmetrics.changeset.files import pair_files
from archmetrics.changeset.locations import Location
from archmetrics.changeset.model import Coupling, FilePair
from archmetrics.changeset.unchanged import ElementRow, PlainElements, Unchanged, element_rows
from archmetrics.coupling import group_elements
from archmetrics.facts import FileFacts
from archmetrics.reports.json_report import diff_dict, dumps, render_diff
from archmetrics.reports.model import DiffReport
from tests.coupling.trees import tree_facts

STUDY = Path(__file__).resolve().parents[2] / "fixtures" / "study"
RULES = LocationRules.from_mapping(
    {"new": ["wdb/**", "backend/**"], "framework": ["proxy/**", "service/**", "*.h"]},
    exclude=["**/test_*.py"],
)


def _facts(folder: Path) -> list[FileFacts]:
    sources = {
        p.relative_to(folder).as_posix(): p.read_text("utf-8", "replace")
        for p in sorted(folder.rglob("*"))
        if p.suffix in {".c", ".h", ".py"} and p.is_file()
    }
    return tree_facts(sources)


Values = Mapping[str, Coupling]


def _both_ways(
    pre: list[FileFacts],
    post: list[FileFacts],
    values: tuple[Values, Values] | None = None,
    dynamic_pre_zero: bool = False,
) -> tuple[ChangeReport, ChangeReport]:
    """The report pairing every file, and the one pairing only the changed elements'
    files; ``values``: coupling before and after (default: one element's before, none
    after)."""
    before_values, after_values = values or ({"wdb/wdb_store.py": Coupling(1, 2, 3, 4)}, {})
    paths = {f.path for f in (*pre, *post)}
    groups = group_elements(paths)
    zero = {"dynamic_pre_zero": dynamic_pre_zero}
    whole = compute_change(
        pair_files(pre, post, {}), groups, RULES, before_values, after_values, **zero
    )
    changed = {f.path for f in (*pre, *post)} - {
        a.path for a in pre for b in post if a.path == b.path and a == b
    }
    owner = {p: e.name for e in groups for p in e.files}
    touched = {owner[p] for p in changed}
    before = {f.path: f for f in pre}
    after = {f.path: f for f in post}
    pairs = [
        FilePair(before.get(p), after.get(p)) for e in groups if e.name in touched for p in e.files
    ]
    rows, excluded = element_rows(pre, groups, RULES)
    unchanged = Unchanged(
        {n: r for n, r in rows.items() if n not in touched},
        tuple(x for x in excluded if owner[x.path] not in touched),
    )
    kept = [e for e in groups if e.name in touched]
    fast = compute_change(
        pairs, kept, RULES, before_values, after_values, unchanged=unchanged, **zero
    )
    return whole, fast


def _untouched(pre: list[FileFacts], post: list[FileFacts]) -> set[str]:
    """The measured elements none of whose files differ between the two trees."""
    groups = group_elements({f.path for f in (*pre, *post)})
    before = {f.path: f for f in pre}
    after = {f.path: f for f in post}
    measured = element_rows(pre, groups, RULES)[0]
    return {
        e.name
        for e in groups
        if e.name in measured
        and all(p in before and p in after and before[p] == after[p] for p in e.files)
    }


def _measured(facts: list[FileFacts], seed: int) -> dict[str, Coupling]:
    """Coupling values for every element of a tree (made up, distinct per element)."""
    names = sorted(e.name for e in group_elements({f.path for f in facts}))
    numbers = {n: zlib.crc32(n.encode()) % 1000 for n in names}  # the same in either tree
    return {n: Coupling(k + seed, 2 * k, k % 3, k % 5 + seed) for n, k in numbers.items()}


def _diff_json(change: ChangeReport) -> str:
    return render_diff(DiffReport("a", "b", change))


def _stage_pairs() -> list[tuple[Path, Path]]:
    found = []
    for manifest in sorted(STUDY.glob("**/manifest.toml")):
        stages = [p for p in sorted(manifest.parent.iterdir()) if p.is_dir()]
        found += list(pairwise(stages))
    return found


@pytest.mark.parametrize("stages", _stage_pairs(), ids=lambda s: str(s[1].relative_to(STUDY)))
def test_unchanged_elements_from_rows_report_what_pairing_every_file_reports(
    stages: tuple[Path, Path],
) -> None:
    whole, fast = _both_ways(_facts(stages[0]), _facts(stages[1]))
    assert fast.to_dict() == whole.to_dict()
    assert fast.elements == whole.elements


def test_a_tree_compared_with_itself_is_all_rows() -> None:
    facts = _facts(STUDY / "wdb" / "soa" / "second")
    whole, fast = _both_ways(facts, facts)
    assert fast == whole
    assert all(e.status.value == "unchanged" for e in fast.elements)


@pytest.mark.parametrize("dynamic_pre_zero", [False, True])
@pytest.mark.parametrize("stages", _stage_pairs(), ids=lambda s: str(s[1].relative_to(STUDY)))
def test_unchanged_elements_kept_as_columns_report_what_pairing_every_file_reports(
    stages: tuple[Path, Path], dynamic_pre_zero: bool
) -> None:
    """Coupling measured on both sides, the same for most elements: those are kept as
    columns (``plain``), and the report, its elements, its sums and its JSON text are the
    report pairing every file's; an element whose coupling differs is made as before."""
    pre, post = _facts(stages[0]), _facts(stages[1])
    before = _measured(pre, 0)
    after = {**_measured(post, 0), "wdb/wdb_store.py": Coupling(9, 9, 9, 9)}
    whole, fast = _both_ways(pre, post, (before, after), dynamic_pre_zero)
    untouched = _untouched(pre, post) - {"wdb/wdb_store.py"}
    assert set(fast.plain.names if fast.plain else ()) == untouched
    assert whole.plain is None
    assert fast == whole
    assert fast.to_dict() == whole.to_dict()
    assert _diff_json(fast) == _diff_json(whole) == dumps(diff_dict(DiffReport("a", "b", whole)))
    assert fast.changed() == [e for e in whole.elements if e.status.value != "unchanged"]
    assert fast.unchanged_count() == sum(e.status.value == "unchanged" for e in whole.elements)


@given(
    names=st.lists(st.text(max_size=6), unique=True, max_size=4),
    files=st.lists(st.text(max_size=6), max_size=3),
    numbers=st.lists(st.integers(0, 1 << 62), min_size=7, max_size=7),
    location=st.sampled_from(list(Location)),
    dynamic_pre_zero=st.booleans(),
)
def test_kept_elements_records_are_their_change_sets_records(
    names: list[str], files: list[str], numbers: list[int], location: Location,
    dynamic_pre_zero: bool,
) -> None:  # fmt: skip
    """``PlainElements.records`` gives what ``to_dict`` of each change set gives."""
    names.sort()
    row = ElementRow(tuple(files), location, (), *numbers[:3])
    values = {n: Coupling(*numbers[3:]) for n in names}
    plain = PlainElements(tuple(names), dict.fromkeys(names, row), values, dynamic_pre_zero)
    assert plain.records() == [change.to_dict() for change in plain.changes()]
    assert [json.dumps(r) for r in plain.records()] == [
        json.dumps(c.to_dict()) for c in plain.changes()
    ]
