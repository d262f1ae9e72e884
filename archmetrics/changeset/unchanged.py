"""Elements none of whose files changed, as a tree's state keeps them (pure).

In a diff of two trees that share most of their files, most elements are unchanged: their
change set is empty and their λ, SLOC, v_g and location are the same on both sides. A tree's
state keeps each element's :class:`ElementRow` (computed here, by the change-set engine's
own rules), so that such a diff reports the unchanged elements from the rows and diffs only
the elements that hold a changed file (compute.py; docs/performance.md, "Incremental diffs").
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple

from archmetrics.changeset.elements import (
    ElementLike,
    Side,
    assign,
    element_index,
    file_location,
    side_metrics,
)
from archmetrics.changeset.files import measured_pairs
from archmetrics.changeset.locations import Location, LocationRules
from archmetrics.changeset.model import (
    ElementChange,
    ExcludedFile,
    FilePair,
    MeasuredFile,
    Metrics,
    Status,
)


class ElementRow(NamedTuple):
    """One element of a tree: its measured files (sorted), its location and the note that
    places an element spread over several locations, and λ, SLOC, v_g summed."""

    files: tuple[str, ...]
    location: Location
    notes: tuple[str, ...]
    loc: int
    sloc: int
    vg: int


@dataclass(frozen=True, slots=True)
class Unchanged:
    """Elements none of whose files changed between the two sides, and those elements'
    files that are left out of the measurement (with their reasons)."""

    elements: Mapping[str, ElementRow]
    excluded: tuple[ExcludedFile, ...] = ()


def element_rows(
    files: Sequence[MeasuredFile], elements: Iterable[ElementLike], rules: LocationRules
) -> tuple[dict[str, ElementRow], list[ExcludedFile]]:
    """The row of every element of a tree that has a measured file, and the tree's files
    left out, found as :func:`~archmetrics.changeset.compute.compute_change` finds them for
    a tree compared with itself."""
    kept, excluded = measured_pairs((FilePair(f, f) for f in files), rules)
    groups = assign(kept, element_index(elements))
    rows = {}
    for name, pairs in groups.items():
        notes: list[str] = []
        members = sorted(p.path for p in pairs)
        location = file_location(name, pairs, rules, notes)
        rows[name] = ElementRow(
            tuple(members),
            location,
            tuple(notes),
            sum(p.post.loc for p in pairs if p.post),
            sum(p.post.sloc for p in pairs if p.post),
            sum(p.post.vg for p in pairs if p.post),
        )
    return rows, excluded


def unchanged_change(
    name: str, row: ElementRow, sides: tuple[Side, Side], notes: list[str]
) -> ElementChange:
    """The change set of an element none of whose files changed: empty, its metrics the
    same on both sides but for coupling (notes in the order ``element_change`` gives them).
    Made for most elements of a large tree: the tuples are built directly (``_new``)."""
    pre = _metrics(name, row, sides[0], notes)
    post = _metrics(name, row, sides[1], notes)
    if row.notes:
        notes.extend(row.notes)
    return _new(ElementChange, (name, row[1], row[0], _UNCHANGED, pre, post, 0, 0, 0, ()))


_new = tuple.__new__
_UNCHANGED = Status.UNCHANGED


def _metrics(name: str, row: ElementRow, side: Side, notes: list[str]) -> Metrics:
    found = side.values.get(name) if side.values is not None else None
    if found is None:  # the general case, with its notes
        return side_metrics(name, row.loc, row.sloc, row.vg, side, notes)
    if side.dynamic_zero:  # d_a, d_e taken as 0 (side_metrics)
        return _new(Metrics, (*row[3:], found[0], found[1], 0, 0))
    return _new(Metrics, row[3:] + tuple(found))
