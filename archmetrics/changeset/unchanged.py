"""Elements none of whose files changed, as a tree's state keeps them (pure).

In a diff of two trees that share most of their files, most elements are unchanged: their
change set is empty and their λ, SLOC, v_g and location are the same on both sides. A tree's
state keeps each element's :class:`ElementRow` (computed here, by the change-set engine's
own rules), so that such a diff reports the unchanged elements from the rows and diffs only
the elements that hold a changed file (compute.py; docs/performance.md, "Incremental diffs").
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple

from archmetrics.changeset.elements import (
    CouplingValues,
    ElementLike,
    Side,
    assign,
    element_index,
    file_location,
    link_changes,
    side_metrics,
)
from archmetrics.changeset.files import measured_pairs
from archmetrics.changeset.locations import Location, LocationRules
from archmetrics.changeset.model import (
    ElementChange,
    ExcludedFile,
    FilePair,
    JsonValue,
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
    added, removed = link_changes(row[0], row[0], sides)
    return _new(
        ElementChange,
        (name, row[1], row[0], _UNCHANGED, pre, post, 0, 0, 0, (), added, removed),
    )


_new = tuple.__new__
_UNCHANGED = Status.UNCHANGED


def _metrics(name: str, row: ElementRow, side: Side, notes: list[str]) -> Metrics:
    found = side.values.get(name) if side.values is not None else None
    if found is None:  # the general case, with its notes
        return side_metrics(name, row.loc, row.sloc, row.vg, side, notes)
    if side.dynamic_zero:  # d_a, d_e taken as 0 (side_metrics)
        return _new(Metrics, (*row[3:], found[0], found[1], 0, 0))
    return _new(Metrics, row[3:] + tuple(found))


@dataclass(frozen=True, slots=True)
class PlainElements:
    """Unchanged elements whose coupling values were measured on both sides and are the
    same: their change sets follow from their rows and values alone, so a report keeps
    them as these columns and makes an :class:`ElementChange` of one only when asked
    (``change``). A tree of 28,000 elements in which one file changed is mostly such
    elements; the JSON report writes them from here (``records``) and the location sums
    add them up from here (``sums``). ``names`` are sorted."""

    names: tuple[str, ...]
    rows: Mapping[str, ElementRow]
    values: Mapping[str, CouplingValues]  # the same before and after
    dynamic_pre_zero: bool

    def __len__(self) -> int:
        return len(self.names)

    def change(self, name: str) -> ElementChange:
        """The element's change set, as :func:`unchanged_change` makes it (its values are
        measured on both sides: no notes)."""
        return unchanged_change(name, self.rows[name], self._sides(), [])

    def changes(self) -> Iterator[ElementChange]:
        sides, rows = self._sides(), self.rows
        return (unchanged_change(name, rows[name], sides, []) for name in self.names)

    def _sides(self) -> tuple[Side, Side]:
        return Side("pre", self.values, self.dynamic_pre_zero), Side("post", self.values)

    def sums(self) -> dict[Location, tuple[Metrics, Metrics]]:
        """Σ of the elements' metrics before and after, per location (integers: the same
        in any order of addition)."""
        located: dict[Location, list[tuple[int, ...]]] = {loc: [] for loc in Location}
        rows, values = self.rows, self.values
        for name in self.names:
            row = rows[name]
            located[row[1]].append(row[3:] + tuple(values[name]))
        sums = {}
        for location, items in located.items():
            post = Metrics(*map(sum, zip(*items, strict=True))) if items else Metrics()
            pre = post._replace(d_a=0, d_e=0) if self.dynamic_pre_zero else post
            sums[location] = (pre, post)
        return sums

    def records(self) -> list[dict[str, JsonValue]]:
        """Each element's ``to_dict`` (its change set's JSON record), in ``names`` order,
        made from the columns: a dictionary per element and one per metrics tuple, where
        the change set would make three tuples as well."""
        rows, values, zero = self.rows, self.values, self.dynamic_pre_zero
        fields = _METRIC_FIELDS
        made: list[dict[str, JsonValue]] = []
        for name in self.names:
            row, found = rows[name], values[name]
            post: dict[str, JsonValue] = dict(zip(fields, row[3:] + tuple(found), strict=True))
            pre: dict[str, JsonValue] = {**post, "d_a": 0, "d_e": 0} if zero else post
            made.append(
                {
                    "element": name,
                    "location": row[1]._value_,
                    "files": list(row[0]),
                    "status": "unchanged",
                    "pre": pre,
                    "post": post,
                    "added": 0,
                    "removed": 0,
                    "modified": 0,
                    "links_added": [],  # its values are the same on both sides
                    "links_removed": [],
                }
            )
        return made


_METRIC_FIELDS = Metrics._fields
