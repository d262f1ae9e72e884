"""Unchanged elements reported from their rows (changeset/unchanged.py): a comparison that
pairs only the elements holding a changed file and gives the others as rows reports what
the comparison pairing every file reports, on the study's real subjects."""

from __future__ import annotations

from itertools import pairwise
from pathlib import Path

import pytest

from archmetrics.changeset import ChangeReport, LocationRules, compute_change
from archmetrics.changeset.files import pair_files
from archmetrics.changeset.model import Coupling, FilePair
from archmetrics.changeset.unchanged import Unchanged, element_rows
from archmetrics.coupling import group_elements
from archmetrics.facts import FileFacts
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


def _both_ways(pre: list[FileFacts], post: list[FileFacts]) -> tuple[ChangeReport, ChangeReport]:
    values = {"wdb/wdb_store.py": Coupling(1, 2, 3, 4)}  # one element's, the rest missing
    paths = {f.path for f in (*pre, *post)}
    groups = group_elements(paths)
    whole = compute_change(pair_files(pre, post, {}), groups, RULES, values, {})
    changed = {
        f.path for f in (*pre, *post)
    } - {a.path for a in pre for b in post if a.path == b.path and a == b}
    owner = {p: e.name for e in groups for p in e.files}
    touched = {owner[p] for p in changed}
    before = {f.path: f for f in pre}
    after = {f.path: f for f in post}
    pairs = [
        FilePair(before.get(p), after.get(p))
        for e in groups
        if e.name in touched
        for p in e.files
    ]
    rows, excluded = element_rows(pre, groups, RULES)
    unchanged = Unchanged(
        {n: r for n, r in rows.items() if n not in touched},
        tuple(x for x in excluded if owner[x.path] not in touched),
    )
    kept = [e for e in groups if e.name in touched]
    fast = compute_change(pairs, kept, RULES, values, {}, unchanged=unchanged)
    return whole, fast


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
