"""Element change sets (thesis p. 73): an element's file changes, status and pre/post metrics M.

Files are grouped into elements by name (the coupling layer's ``group_elements`` naming); a
file pair whose pre and post paths belong to different elements is split into a removal from
the old element and an addition to the new one, so each element's before/after stays whole.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

from archmetrics.changeset.locations import Location, LocationRules
from archmetrics.changeset.model import (
    ElementChange,
    FilePair,
    LinkChange,
    MeasuredFile,
    Metrics,
    Status,
)
from archmetrics.changeset.rows import diff_measured
from archmetrics.changeset.statement_diff import FileChange
from archmetrics.facts import FileFacts

CouplingValues = tuple[int, int, int, int]
Links = Mapping[str, tuple[tuple[str, str | None], ...]]  # a tree's link sites by file

# How a file pair's change is found: diff_measured, or a function that gives what it would
# give (the application's, which keeps changes in the cache by the files' blobs)
Differ = Callable[[MeasuredFile | None, MeasuredFile | None], FileChange]


class ElementLike(Protocol):
    """What an element grouping provides (``archmetrics.coupling.elements.Element`` fits)."""

    @property
    def name(self) -> str: ...

    @property
    def files(self) -> tuple[str, ...]: ...


@dataclass(frozen=True, slots=True)
class Side:
    """One revision's coupling values; ``values`` None means coupling was not measured."""

    label: str  # "pre" or "post"
    values: Mapping[str, CouplingValues] | None  # s_a, s_e, d_a, d_e (a Coupling or a tuple)
    dynamic_zero: bool = False  # the thesis convention (p. 100): d_a = d_e = 0 before
    links: Links | None = None  # each file's link sites as the coupling index keeps them


def link_changes(
    pre_files: Iterable[str], post_files: Iterable[str], sides: tuple[Side, Side]
) -> tuple[tuple[LinkChange, ...], tuple[LinkChange, ...]]:
    """The link sites (role and endpoint) ``post_files`` have that ``pre_files`` had not,
    and the reverse, each with how many (a publisher added on a topic the element already
    published on is one more); none when a side has no link records."""
    before, after = sides[0].links, sides[1].links
    if before is None or after is None:
        return (), ()
    old = Counter(s for path in pre_files for s in before.get(path, ()) if s[0] != _ALSO)
    new = Counter(s for path in post_files for s in after.get(path, ()) if s[0] != _ALSO)
    return _listed(new - old), _listed(old - new)


_ALSO = "also"  # a key a receiving site also receives: no site (coupling/index.py)


def _listed(changes: Counter[tuple[str, str | None]]) -> tuple[LinkChange, ...]:
    return tuple((role, key, count) for (role, key), count in sorted(changes.items(), key=_by_key))


def _by_key(item: tuple[tuple[str, str | None], int]) -> tuple[str, str]:
    (role, key), _ = item
    return (key or "", role)


def element_index(elements: Iterable[ElementLike]) -> dict[str, str]:
    """path -> element name; the same name twice is merged, a path in two names is an error."""
    index: dict[str, str] = {}
    for element in elements:
        for path in element.files:
            owner = index.setdefault(path, element.name)
            if owner != element.name:
                raise ValueError(f"{path!r} is in two elements: {owner!r} and {element.name!r}")
    return index


def assign(pairs: Iterable[FilePair], index: Mapping[str, str]) -> dict[str, list[FilePair]]:
    """Pairs per element name; unlisted files are their own element, named by their path."""
    groups: dict[str, list[FilePair]] = {}
    for pair in pairs:
        pre_owner = index.get(pair.pre.path, pair.pre.path) if pair.pre else None
        post_owner = index.get(pair.post.path, pair.post.path) if pair.post else None
        owner = post_owner or pre_owner  # a renamed file follows itself into its new element
        assert owner is not None
        groups.setdefault(owner, []).append(pair)
    return groups


def _metrics(
    element: str, files: Sequence[MeasuredFile], side: Side, notes: list[str]
) -> Metrics | None:
    """M of one side: λ, SLOC, v_g summed over the files, coupling from the coupling layer."""
    if not files:
        return None
    loc = sum(f.loc for f in files)
    sloc = sum(f.sloc for f in files)
    vg = sum(f.vg for f in files)
    return side_metrics(element, loc, sloc, vg, side, notes)


def side_metrics(
    element: str, loc: int, sloc: int, vg: int, side: Side, notes: list[str]
) -> Metrics:
    """M of one side of an element with these sums, coupling from the coupling layer (a
    missing value is 0 and noted; d_a, d_e are 0 before under the thesis convention)."""
    s_a = s_e = d_a = d_e = 0
    if side.values is not None:
        found = side.values.get(element)
        if found is None:
            notes.append(
                f"coupling_missing_{side.label}: element {element!r} has no {side.label}"
                " coupling values; taken as 0"
            )
        else:
            s_a, s_e, d_a, d_e = found
    if side.dynamic_zero:
        d_a = d_e = 0
    return Metrics(loc, sloc, vg, s_a, s_e, d_a, d_e)


def file_location(
    element: str, pairs: Sequence[FilePair], rules: LocationRules, notes: list[str]
) -> Location:
    """Where most of the element's files are (ties: its first file's); mixed ones are flagged."""
    by_file = [rules.location_of(p.path) for p in sorted(pairs, key=lambda p: p.path)]
    counts = Counter(by_file)
    location = max(counts, key=lambda loc: (counts[loc], -by_file.index(loc)))
    if len(counts) > 1:
        spread = ", ".join(sorted(loc.value for loc in counts))
        notes.append(
            f"element_mixed_locations: element {element!r} has files in {spread};"
            f" counted in {location.value}"
        )
    return location


def _status(pre: Metrics | None, post: Metrics | None, changes: int) -> Status:
    if pre is None:
        return Status.ADDED
    if post is None:
        return Status.REMOVED
    return Status.MODIFIED if changes else Status.UNCHANGED


def _reconfigured(pairs: Sequence[FilePair]) -> int:
    """How many of the files changed their configuration tables (facts.ConfigTable)."""
    return sum(
        1
        for p in pairs
        if isinstance(p.pre, FileFacts)  # a row stands for a file that did not change
        and isinstance(p.post, FileFacts)
        and p.pre.tables != p.post.tables
    )


def element_change(
    element: str,
    pairs: Sequence[FilePair],
    rules: LocationRules,
    sides: tuple[Side, Side],
    notes: list[str],
    diff: Differ = diff_measured,
) -> ElementChange:
    """The change set of one element: statement diffs of its files, status, M before and after."""
    found = [diff(p.pre, p.post) for p in sorted(pairs, key=lambda p: p.path)]
    # the detail of the files that changed (a file unchanged has none to give)
    file_changes = tuple(c for c in found if c.total or c.approximate)
    for change in file_changes:
        if change.approximate:
            notes.append(
                f"pairing_approximate: {change.post_path or change.pre_path!r} has a replace run"
                " too large for exact pairing; modified statements were paired greedily"
            )
    pre = _metrics(element, [p.pre for p in pairs if p.pre], sides[0], notes)
    post = _metrics(element, [p.post for p in pairs if p.post], sides[1], notes)
    added = sum(c.added for c in file_changes)
    removed = sum(c.removed for c in file_changes)
    modified = sum(c.modified for c in file_changes)
    links = link_changes(
        [p.pre.path for p in pairs if p.pre], [p.post.path for p in pairs if p.post], sides
    )
    return ElementChange(
        element=element,
        location=file_location(element, pairs, rules, notes),
        files=tuple(sorted(p.path for p in pairs)),
        # a configuration file has no statements: a change of its tables is its change
        status=_status(pre, post, added + removed + modified + _reconfigured(pairs)),
        pre=pre,
        post=post,
        added=added,
        removed=removed,
        modified=modified,
        file_changes=file_changes,
        links_added=links[0],
        links_removed=links[1],
    )
