"""One base..new comparison: file pairs in, a :class:`ChangeReport` out (pure, no I/O).

``compute_change(pairs, elements, rules, coupling_pre, coupling_post)``

* ``pairs``: every measured file of either revision as a :class:`FilePair` (pre facts or None,
  post facts or None); the caller pairs files across revisions, following git renames.
* ``elements``: the element grouping (``archmetrics.coupling.elements.group_elements`` over the
  union of both revisions' paths, or any objects with ``name`` and ``files``); None groups the
  paths with ``group_elements``. Files no element lists are elements of their own.
* ``rules``: :class:`LocationRules` -- locations by path glob, exclusions.
* ``coupling_pre`` / ``coupling_post``: element name -> :class:`Coupling` (s_a, s_e, d_a, d_e)
  measured on each tree by the coupling layer (:func:`coupling_by_element` converts a
  ``CouplingReport``); None when coupling was not measured (zeros, flagged in the notes).
* ``dynamic_pre_zero``: apply the thesis convention (p. 100) that d_a and d_e are 0 before the
  integration, instead of the values measured on the pre tree (the default).
* ``diff``: how a file pair's statement change is found (``diff_files``, or a function that
  gives what it gives: the application keeps changes in the cache by the files' blobs).

Excluded files count nowhere and are listed with their reason: a side whose path matches an
exclude glob or whose facts say ``generated`` is dropped alone; a pair with a side no parser
could read is dropped whole. Every location appears in the report, empty
or not; sums run over all elements of a location, changed or not (docs/metrics.md).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from archmetrics.changeset.cost import Sums, location_summary, total_summary
from archmetrics.changeset.elements import (
    CouplingValues,
    Differ,
    ElementLike,
    Links,
    Side,
    assign,
    element_change,
    element_index,
)
from archmetrics.changeset.files import measured_pairs
from archmetrics.changeset.locations import Location, LocationRules
from archmetrics.changeset.model import (
    ChangeReport,
    Coupling,
    ElementChange,
    ExcludedFile,
    FilePair,
    Metrics,
)
from archmetrics.changeset.rows import diff_measured
from archmetrics.changeset.unchanged import PlainElements, Unchanged, unchanged_change
from archmetrics.coupling.elements import group_elements
from archmetrics.coupling.model import CouplingReport


def coupling_by_element(report: CouplingReport) -> dict[str, Coupling]:
    """The coupling layer's per-element results as the mapping :func:`compute_change` takes."""
    return {e.element.name: Coupling(e.s_a, e.s_e, e.d_a, e.d_e) for e in report.elements}


def _sums(elements: Sequence[ElementChange], plain: tuple[Metrics, Metrics] | None = None) -> Sums:
    """Σ_i over the change sets of one location (eqs. 6.2, 6.5, 6.7, 6.9, 6.16-6.18, 6.31);
    ``plain``: the sums of its unchanged elements kept as columns, before and after."""
    pre = [e.pre for e in elements if e.pre is not None]
    post = [e.post for e in elements if e.post is not None]
    if plain is not None:
        pre.append(plain[0])
        post.append(plain[1])
    return Sums(
        Metrics(*map(sum, zip(*pre, strict=True))) if pre else Metrics(),
        Metrics(*map(sum, zip(*post, strict=True))) if post else Metrics(),
        sum(e.added for e in elements),
        sum(e.removed for e in elements),
        sum(e.modified for e in elements),
    )


def side_notes(sides: tuple[Side, Side]) -> list[str]:
    notes: list[str] = []
    for side in sides:
        if side.values is None:
            notes.append(
                f"coupling_not_measured_{side.label}: no {side.label} coupling values were given;"
                " s_a, s_e, d_a, d_e taken as 0"
            )
    if sides[0].dynamic_zero:
        notes.append("dynamic_pre_zero: d_a, d_e before integration taken as 0 (thesis p. 100)")
    return notes


def compute_change(
    pairs: Iterable[FilePair],
    elements: Iterable[ElementLike] | None,
    rules: LocationRules,
    coupling_pre: Mapping[str, CouplingValues] | None,
    coupling_post: Mapping[str, CouplingValues] | None,
    *,
    dynamic_pre_zero: bool = False,
    diff: Differ = diff_measured,
    unchanged: Unchanged | None = None,
    links: tuple[Links | None, Links | None] = (None, None),
) -> ChangeReport:
    """Chapter 6 metrics of one comparison: per location, total, per element, exclusions.

    ``unchanged``: elements none of whose files changed, reported from their rows; their
    pairs are then left out of ``pairs`` (a diff of two trees that share most files pairs
    only the files of the elements that hold a changed one). ``links``: each side's link
    sites by file (the coupling index's), from which each element's link changes are
    listed."""
    kept, excluded = measured_pairs(pairs, rules)
    if elements is None:
        paths = {f.path for p in kept for f in (p.pre, p.post) if f is not None}
        elements = group_elements(paths)
    groups = assign(kept, element_index(elements))
    rows = unchanged.elements if unchanged else {}
    if rows.keys() & groups.keys():
        raise ValueError("an element is both unchanged and paired")
    sides = (
        Side("pre", coupling_pre, dynamic_pre_zero, links[0]),
        Side("post", coupling_post, links=links[1]),
    )
    changes: list[ElementChange] = []
    notes: list[tuple[Location, str]] = []
    plain: list[str] = []
    before, after = coupling_pre, coupling_post
    for name in sorted(groups.keys() | rows.keys()):
        row = rows.get(name)
        if row is not None and before is not None and after is not None:
            found = after.get(name)
            if found is not None and before.get(name) == found:  # kept as columns
                plain.append(name)
                if row.notes:
                    notes += [(row.location, n) for n in row.notes]
                continue
        element_notes: list[str] = []
        if row is not None:
            change = unchanged_change(name, row, sides, element_notes)
        else:
            change = element_change(name, groups[name], rules, sides, element_notes, diff)
        changes.append(change)
        if element_notes:
            notes += [(change.location, n) for n in element_notes]
    if unchanged and unchanged.excluded:
        excluded = sorted([*excluded, *unchanged.excluded], key=lambda x: (x.path, x.reason))
    columns = PlainElements(tuple(plain), rows, after or {}, dynamic_pre_zero) if plain else None
    return report_of(changes, excluded, side_notes(sides), notes, columns)


def report_of(
    changes: Iterable[ElementChange],
    excluded: Iterable[ExcludedFile] = (),
    common: Iterable[str] = (),
    notes: Iterable[tuple[Location, str]] = (),
    plain: PlainElements | None = None,
) -> ChangeReport:
    """S(L) per location and S_tot from element change sets however they were found: by
    diffing files (:func:`compute_change`) or from an integration plan (changeset/plan.py).

    ``common`` notes apply to every location, ``notes`` to one location each."""
    changes = tuple(changes)
    common = tuple(common)
    by_location: dict[Location, list[str]] = {loc: [] for loc in Location}
    for location, note in notes:
        by_location[location].append(note)
    located: dict[Location, list[ElementChange]] = {loc: [] for loc in Location}
    for change in changes:
        located[change.location].append(change)
    kept = plain.sums() if plain else {}
    summaries = tuple(
        (loc, location_summary(_sums(located[loc], kept.get(loc)), (*common, *by_location[loc])))
        for loc in Location
    )
    all_notes = [*common, *(n for loc in Location for n in by_location[loc])]
    total = total_summary((s for _, s in summaries), all_notes)
    return ChangeReport(summaries, total, changes, tuple(excluded), plain)
