"""The frozen values a change computation returns, and their JSON shape (a public contract).

Field names are the JSON keys: a :class:`Summary` is one location's (or the total's) metrics
S, an :class:`ElementChange` one element's change set with its pre/post metrics M. ``to_dict``
gives plain JSON types: ints, floats, strings, lists, and None (``null``) where a value is
undefined -- always with a note saying why (docs/metrics.md, "Conventions").
"""

from __future__ import annotations

import heapq
from collections.abc import Iterator, Mapping
from dataclasses import dataclass, replace
from enum import StrEnum
from functools import cached_property
from typing import NamedTuple, Protocol

from archmetrics.changeset.locations import Location
from archmetrics.changeset.statement_diff import FileChange
from archmetrics.complexity import FileMetrics, FunctionMetrics

JsonValue = int | float | str | None | list["JsonValue"] | dict[str, "JsonValue"]


class Coupling(NamedTuple):
    """One element's coupling in one revision, from the coupling layer: s_a, s_e, d_a, d_e."""

    s_a: int = 0
    s_e: int = 0
    d_a: int = 0
    d_e: int = 0


class Metrics(NamedTuple):
    """M: an element's (or a location's summed) size, complexity and coupling in one revision.

    A named tuple (a diff makes two per element, 56,000 for a tree of 28,000 elements);
    ``+`` adds field by field, as the sums of eqs. 6.2-6.31 do."""

    loc: int = 0  # λ, logical lines of code (thesis p. 103)
    sloc: int = 0  # physical non-blank, non-comment lines (informative; not in any equation)
    vg: int = 0  # McCabe v_g, summed over functions (eq. 6.31)
    s_a: int = 0
    s_e: int = 0
    d_a: int = 0
    d_e: int = 0

    def __add__(self, other: tuple[int, ...]) -> Metrics:  # type: ignore[override]
        return Metrics(*(a + b for a, b in zip(self, other, strict=True)))

    def as_tuple(self) -> tuple[int, int, int, int, int, int, int]:
        return (self.loc, self.sloc, self.vg, self.s_a, self.s_e, self.d_a, self.d_e)

    def to_dict(self) -> dict[str, JsonValue]:
        return dict(zip(_METRIC_FIELDS, self, strict=True))


_METRIC_FIELDS = Metrics._fields


class Status(StrEnum):
    """What happened to an element's change set."""

    ADDED = "added"  # no file of it existed before
    REMOVED = "removed"  # no file of it exists after
    MODIFIED = "modified"  # it existed on both sides and Γ > 0
    UNCHANGED = "unchanged"  # it existed on both sides and Γ = 0


class MeasuredFile(Protocol):
    """What a comparison reads of a file besides its statements: a file's facts, or its row
    when it is not diffed (changeset/rows.py)."""

    @property
    def path(self) -> str: ...

    @property
    def language(self) -> str: ...

    @property
    def loc(self) -> int: ...

    @property
    def sloc(self) -> int: ...

    @property
    def vg(self) -> int: ...

    @property
    def parsed(self) -> bool: ...

    @property
    def generated(self) -> bool: ...


@dataclass(frozen=True, slots=True)
class FilePair:
    """One file across the two revisions (the caller pairs them, following git renames)."""

    pre: MeasuredFile | None
    post: MeasuredFile | None

    def __post_init__(self) -> None:
        if self.pre is None and self.post is None:
            raise ValueError("a file pair needs at least one side")

    @property
    def path(self) -> str:
        """The post path, or the pre path of a removed file."""
        side = self.post or self.pre
        assert side is not None
        return side.path


class ElementChange(NamedTuple):
    """An element's change set: its files' statement changes and its metrics before and after
    (a named tuple: a diff makes one per element of the tree)."""

    element: str
    location: Location
    files: tuple[str, ...]  # post paths (pre path for removed files), sorted
    status: Status
    pre: Metrics | None  # None: the element did not exist before
    post: Metrics | None  # None: the element no longer exists
    added: int
    removed: int
    modified: int
    file_changes: tuple[FileChange, ...] = ()  # the detail behind added/removed/modified
    # link sites its files have after and not before, and before and not after: (role,
    # endpoint key or None when unknown, how many)
    links_added: tuple[LinkChange, ...] = ()
    links_removed: tuple[LinkChange, ...] = ()

    def to_dict(self) -> dict[str, JsonValue]:
        # a diff writes one per element of the tree (28,000 in a large one): the fields by
        # unpacking, the enums' values as stored (``_value_``: ``.value`` is a property)
        element, location, files, status, pre, post, added, removed, modified = self[:9]
        return {
            "element": element,
            "location": location._value_,
            "files": list(files),
            "status": status._value_,
            "pre": None if pre is None else dict(zip(_METRIC_FIELDS, pre, strict=True)),
            "post": None if post is None else dict(zip(_METRIC_FIELDS, post, strict=True)),
            "added": added,
            "removed": removed,
            "modified": modified,
            "links_added": link_records(self.links_added),
            "links_removed": link_records(self.links_removed),
        }


LinkChange = tuple[str, str | None, int]


def link_records(changes: tuple[LinkChange, ...]) -> list[JsonValue]:
    """Link changes as JSON records: role, endpoint (null: not known statically), count."""
    return [{"role": role, "endpoint": key, "count": count} for role, key, count in changes]


@dataclass(frozen=True, slots=True)
class Summary:
    """S: the chapter-6 metrics of one location or of the total (equation numbers in cost.py)."""

    delta_s_a: int
    delta_s_e: int
    delta_d_a: int
    delta_d_e: int
    loc_pre: int
    loc_post: int
    loc_scale: float | None  # None: λ_pre = 0, see notes
    added: int
    removed: int
    modified: int
    changes: int
    scaled_changes: float
    vg_pre: int
    vg_post: int
    vg_scale: float | None  # None: Vg_pre = 0, see notes
    delta_vg: int
    scaled_delta_vg: float
    cost: float
    notes: tuple[str, ...] = ()
    # files the change touched that could not be parsed after it (a syntax error): dropped
    # from both sides (listed as excluded, not_parsed), counted here so a gate can fail them
    unparsed: int = 0

    def to_dict(self) -> dict[str, JsonValue]:
        out: dict[str, JsonValue] = {}
        for name in SUMMARY_FIELDS:
            value = getattr(self, name)
            out[name] = list(value) if isinstance(value, tuple) else value
        out["unparsed"] = self.unparsed
        return out


SUMMARY_FIELDS: tuple[str, ...] = (
    "delta_s_a",
    "delta_s_e",
    "delta_d_a",
    "delta_d_e",
    "loc_pre",
    "loc_post",
    "loc_scale",
    "added",
    "removed",
    "modified",
    "changes",
    "scaled_changes",
    "vg_pre",
    "vg_post",
    "vg_scale",
    "delta_vg",
    "scaled_delta_vg",
    "cost",
    "notes",
)


@dataclass(frozen=True, slots=True)
class ExcludedFile:
    """A file left out of every number, and why (``exclude:<glob>``, ``generated``, ...)."""

    path: str
    reason: str

    def to_dict(self) -> dict[str, JsonValue]:
        return {"path": self.path, "reason": self.reason}


class PlainLike(Protocol):
    """Unchanged elements kept as columns, their change sets made when asked for
    (changeset/unchanged.py, ``PlainElements``)."""

    @property
    def names(self) -> tuple[str, ...]: ...

    def __len__(self) -> int: ...

    def changes(self) -> Iterator[ElementChange]: ...

    def records(self) -> list[dict[str, JsonValue]]: ...


class Touched(NamedTuple):
    """A file the change touched, as it is after the change, and its functions the change
    touched (a statement added, removed or modified inside them, or the function new):
    what a diff's function and file gates check (docs/ci.md, "Gates")."""

    file: FileMetrics
    functions: tuple[FunctionMetrics, ...]


def _element_name(change: ElementChange) -> str:
    return change.element


@dataclass(frozen=True, eq=False)
class ChangeReport:
    """Everything one base..new comparison measured: per location, total, elements, exclusions.

    ``computed``: the change sets made; ``plain``: unchanged elements kept as columns (a
    diff of two trees that share most files), whose change sets :attr:`elements` makes when
    first read. Two reports are equal when what they report is."""

    locations: tuple[tuple[Location, Summary], ...]  # always base, new, framework, in that order
    total: Summary
    computed: tuple[ElementChange, ...]  # sorted by element name
    excluded: tuple[ExcludedFile, ...]
    plain: PlainLike | None = None
    unmatched: tuple[str, ...] = ()  # location and exclude globs that matched no file
    touched: tuple[Touched, ...] = ()  # the files the change touched, after it

    @cached_property
    def elements(self) -> tuple[ElementChange, ...]:
        """Every element's change set, sorted by element name."""
        if not self.plain:
            return self.computed
        return tuple(heapq.merge(self.computed, self.plain.changes(), key=_element_name))

    def changed(self) -> list[ElementChange]:
        """The elements whose status is not unchanged (without making the plain ones)."""
        return [e for e in self.computed if e.status is not Status.UNCHANGED]

    def unchanged_count(self) -> int:
        return len(self.plain or ()) + sum(e.status is Status.UNCHANGED for e in self.computed)

    def _compared(self) -> tuple[object, ...]:
        return (self.locations, self.total, self.elements, self.excluded)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, ChangeReport):
            return NotImplemented
        return self._compared() == other._compared()

    def __hash__(self) -> int:
        return hash(self._compared())

    def with_unparsed(self, by_location: Mapping[Location, int]) -> ChangeReport:
        """This report with each location's (and the total's) count of touched files that
        could not be parsed."""
        locations = tuple(
            (loc, replace(summary, unparsed=by_location.get(loc, 0)))
            for loc, summary in self.locations
        )
        total = replace(self.total, unparsed=sum(by_location.values()))
        return replace(self, locations=locations, total=total)

    def location(self, location: Location) -> Summary:
        """The summary S(L) of one location."""
        return dict(self.locations)[location]

    def to_dict(self) -> dict[str, JsonValue]:
        return {
            "locations": {loc.value: summary.to_dict() for loc, summary in self.locations},
            "total": self.total.to_dict(),
            "elements": [e.to_dict() for e in self.elements],
            "excluded": [x.to_dict() for x in self.excluded],
        }
