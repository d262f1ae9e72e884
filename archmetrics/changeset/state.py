"""A tree's state: what a diff reads of one tree besides the facts of the files it diffs
(pure; kept in the facts cache by app/tree.py, docs/performance.md "Incremental diffs").

* ``rows``: every selected file's row (path, blob, language, λ, SLOC, v_g, flags, warnings);
* ``index``: the coupling index of the measured files (coupling/index.py);
* ``groups``: the elements of all the selected files, as a diff groups a tree's paths;
* ``table``: each element's row (changeset/unchanged.py) and the files left out, as the
  change-set engine finds them for the tree compared with itself.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from archmetrics.changeset.locations import LocationRules
from archmetrics.changeset.model import ExcludedFile
from archmetrics.changeset.rows import FileRow
from archmetrics.changeset.unchanged import ElementRow, element_rows
from archmetrics.coupling.elements import Element, group_elements
from archmetrics.coupling.index import CouplingIndex


@dataclass(frozen=True, slots=True)
class TreeState:
    rows: tuple[FileRow, ...]
    index: CouplingIndex
    groups: tuple[Element, ...]
    table: Mapping[str, ElementRow]
    excluded: tuple[ExcludedFile, ...]


def grouped(rows: Sequence[FileRow], per_file: bool | str) -> tuple[Element, ...]:
    """The elements of ``rows``' paths, as a diff groups them (by their endings' languages)."""
    return group_elements([row.path for row in rows], per_file)


def tree_state(
    rows: tuple[FileRow, ...],
    index: CouplingIndex,
    rules: LocationRules,
    per_file: bool | str,
    groups: tuple[Element, ...] | None = None,
) -> TreeState:
    """The state of a tree with these rows and coupling index, under ``rules``; ``groups``
    when known (the grouping of the same paths)."""
    groups = groups if groups is not None else grouped(rows, per_file)
    table, excluded = element_rows(rows, groups, rules)
    return TreeState(rows, index, groups, table, tuple(excluded))


def owners(groups: Sequence[Element]) -> dict[str, str]:
    """Each grouped path's element name."""
    return {path: element.name for element in groups for path in element.files}


def patched_state(
    origin: TreeState,
    rows: tuple[FileRow, ...],
    index: CouplingIndex,
    changed: frozenset[str],
    rules: LocationRules,
    per_file: bool | str,
    owner: Mapping[str, str] | None = None,
) -> TreeState:
    """The state of ``origin``'s tree with the files at ``changed`` paths changed, now
    holding ``rows`` and coupled as ``index``: the elements of the changed files get their
    rows again, the others keep theirs. Paths added or removed: the whole tree again."""
    if len(rows) != len(origin.rows) or any(
        a.path != b.path for a, b in zip(rows, origin.rows, strict=True)
    ):
        return tree_state(rows, index, rules, per_file)
    owner = owner if owner is not None else owners(origin.groups)
    touched = {owner[path] for path in changed if path in owner}
    elements = [e for e in origin.groups if e.name in touched]
    members = {path for e in elements for path in e.files}
    table, excluded = element_rows([r for r in rows if r.path in members], elements, rules)
    table.update((k, v) for k, v in origin.table.items() if k not in touched)
    excluded += [x for x in origin.excluded if owner.get(x.path) not in touched]
    excluded.sort(key=lambda x: (x.path, x.reason))
    return TreeState(rows, index, origin.groups, table, tuple(excluded))
