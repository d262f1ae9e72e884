"""A tree's state (changeset/state.py) to and from a cache record: compressed JSON, read
back field by field. The cache file is not trusted: a record that is not exactly what
``encode`` writes raises :class:`~archmetrics.sources.codec.CodecError`, and the caller
recomputes the state.

The record is flat columns, files named by their position and names of a few kinds (a
language, a resolution, a role, a location) by theirs in a table: reading a numpy-sized
state is a few list checks in C (every number's type and range, every text's type), not a
check per field, and the coupling index's dependency records are made only for the files a
patch reads (sources/deptable.py).
"""

from __future__ import annotations

import json
import zlib
from collections.abc import Iterable, Mapping, Sequence
from itertools import accumulate, repeat
from typing import Any

from archmetrics.changeset.locations import Location
from archmetrics.changeset.model import ExcludedFile
from archmetrics.changeset.rows import FileRow
from archmetrics.changeset.state import TreeState
from archmetrics.changeset.unchanged import ElementRow
from archmetrics.coupling.elements import Element
from archmetrics.coupling.index import CouplingIndex, Site, Values
from archmetrics.facts import ParseWarning, Severity
from archmetrics.sources.codec import CodecError
from archmetrics.sources.deptable import RESOLUTIONS as _RESOLUTIONS
from archmetrics.sources.deptable import DepTable
from archmetrics.sources.statecolumns import (
    bad as _bad,
)
from archmetrics.sources.statecolumns import (
    ints as _ints,
)
from archmetrics.sources.statecolumns import (
    lists as _lists,
)
from archmetrics.sources.statecolumns import (
    lists_of as _lists_of,
)
from archmetrics.sources.statecolumns import (
    loads as _loads,
)
from archmetrics.sources.statecolumns import (
    split as _split,
)
from archmetrics.sources.statecolumns import (
    texts as _texts,
)

FORMAT = 4
_PARSED, _GENERATED = 1, 2
_SEVERITIES = tuple(s.value for s in Severity)
_SEVERITY_MEMBERS = tuple(Severity)
_ROLES = ("initiate", "receive", "use", "also")
_LOCATIONS = tuple(loc for loc in Location)


def _codes(values: Iterable[str]) -> tuple[list[str], dict[str, int]]:
    table: dict[str, int] = {}
    for value in values:
        table.setdefault(value, len(table))
    return list(table), table


def _flat(groups: Iterable[Sequence[Any]]) -> tuple[list[Any], list[int]]:
    """Several lists as one, and each one's length."""
    flat: list[Any] = []
    lengths: list[int] = []
    for group in groups:
        flat.extend(group)
        lengths.append(len(group))
    return flat, lengths


def encode(state: TreeState) -> bytes:
    """The record of a tree's state."""
    rows, index = state.rows, state.index
    at = {row.path: i for i, row in enumerate(rows)}
    languages, language = _codes(
        [r.language for r in rows] + [lang for e in index.elements for lang in e.languages]
    )
    numbers: list[int] = []
    for row in rows:
        flags = (_PARSED if row.parsed else 0) | (_GENERATED if row.generated else 0)
        numbers += (row.loc, row.sloc, row.vg, flags, language[row.language])
    members, sizes = _flat([at[p] for p in e.files] for e in index.elements)
    element_at = {e.name: i for i, e in enumerate(index.elements)}
    kinds, kind_sizes = _flat([language[lang] for lang in e.languages] for e in index.elements)
    dep_files = list(index.deps)
    deps, dep_sizes = _flat(index.deps[p] for p in dep_files)
    site_files = list(index.sites)
    sites, site_sizes = _flat(index.sites[p] for p in site_files)
    document: dict[str, Any] = {
        "format": FORMAT,
        "files": [r.path for r in rows],
        "blobs": [r.blob for r in rows],
        "languages": languages,
        "numbers": numbers,
        "functions": [n for row in rows for n in (row.functions, row.estimated)],
        "warnings": [
            [i, w.line, w.message, _SEVERITIES.index(w.severity.value)]
            for i, row in enumerate(rows)
            for w in row.warnings
        ],
        "measured": [at[p] for p in index.paths],
        "elements": [[e.name for e in index.elements], members, sizes, kinds, kind_sizes],
        "deps": [
            [at[p] for p in dep_files],
            dep_sizes,
            [-1 if d.target_file is None else at[d.target_file] for d in deps],
            [_RESOLUTIONS.index(d.resolution) for d in deps],
            [d.name for d in deps],
        ],
        "sites": [
            [at[p] for p in site_files],
            site_sizes,
            [_ROLES.index(role) for role, _ in sites],
            [key for _, key in sites],
        ],
        "values": [n for e in index.elements for n in index.values[e.name]],
        "receivers": [
            [key, sorted(element_at[name] for name in names)]
            for key, names in sorted(index.receivers.items())
        ],
        "whole": index.whole,
        "groups": _groups(state, at),
        "table": _table_columns(state, at),
        "excluded": [[at[x.path] for x in state.excluded], [x.reason for x in state.excluded]],
    }
    # ASCII escapes: a warning may quote a lone surrogate, which no UTF-8 holds
    return zlib.compress(json.dumps(document, separators=(",", ":")).encode(), 1)


def _groups(state: TreeState, at: Mapping[str, int]) -> list[Any] | None:
    """The diff's grouping of every selected file, as it differs from the coupling's (which
    groups the measured files): the elements whose files differ or that only it has, and
    the names of the coupling's elements it lacks; none when they are the same."""
    coupled = {e.name: e.files for e in state.index.elements}
    names = {e.name for e in state.groups}
    other = [e for e in state.groups if coupled.get(e.name) != e.files]
    gone = [name for name in coupled if name not in names]
    if not other and not gone:
        return None
    members, sizes = _flat([at[p] for p in e.files] for e in other)
    return [[e.name for e in other], members, sizes, gone]


def _table_columns(state: TreeState, at: Mapping[str, int]) -> list[Any]:
    """Each group's element row: its location (-1: no measured file), λ, SLOC, v_g, notes,
    and its measured files where they are not all its files."""
    codes: list[int] = []
    numbers: list[int] = []
    notes: list[list[str]] = []
    partial: list[list[Any]] = []
    for k, element in enumerate(state.groups):
        row = state.table.get(element.name)
        if row is None:
            codes.append(-1)
            numbers += (0, 0, 0)
            notes.append([])
            continue
        codes.append(_LOCATIONS.index(row.location))
        numbers += (row.loc, row.sloc, row.vg)
        notes.append(list(row.notes))
        if row.files != element.files:
            partial.append([k, [at[p] for p in row.files]])
    flat, sizes = _flat(notes)
    return [codes, numbers, flat, sizes, partial]


_new = tuple.__new__  # a named tuple from its fields, without its class's Python-level __new__


def decode(data: bytes) -> TreeState:
    """The state ``encode`` wrote; :class:`CodecError` for anything else."""
    try:
        document = _loads(zlib.decompress(data))
    except (zlib.error, ValueError) as error:
        raise CodecError(f"not a tree state: {error}") from error
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        raise CodecError("not a tree state of this format")
    files = _texts(document.get("files"))
    count = len(files)
    languages = _texts(document.get("languages"))
    rows = _rows(document, files, languages)
    paths = tuple(map(files.__getitem__, _ints(document.get("measured"), 0, count)))
    elements = _elements(document.get("elements"), files, languages)
    deps = DepTable.read(document.get("deps"), files)
    sites = _sites(document.get("sites"), files)
    numbers = _ints(document.get("values"), 0, 1 << 62, 4 * len(elements))
    columns = (numbers[0::4], numbers[1::4], numbers[2::4], numbers[3::4])
    named = [e.name for e in elements]
    values: dict[str, Values] = dict(zip(named, zip(*columns, strict=True), strict=True))
    receivers = _receivers(document.get("receivers"), [e.name for e in elements])
    whole = document.get("whole")
    if not isinstance(whole, bool):
        raise _bad("no whole flag")
    index = CouplingIndex(paths, elements, deps, sites, values, receivers, whole)
    _consistent(files, index, deps)
    groups = elements
    if document.get("groups") is not None:
        groups = _regrouped(document.get("groups"), elements, files)
    table = _table(document.get("table"), groups, files)
    where, reasons = _lists(document.get("excluded"), 2)
    found = _ints(where, 0, count)
    excluded = tuple(
        ExcludedFile(files[i], r) for i, r in zip(found, _texts(reasons, len(found)), strict=True)
    )
    return TreeState(rows, index, groups, table, excluded)


def _rows(document: dict[str, Any], files: list[str], languages: list[str]) -> tuple[FileRow, ...]:
    count = len(files)
    blobs = _texts(document.get("blobs"), count)
    numbers = _ints(document.get("numbers"), 0, 1 << 62, 5 * count)
    if numbers and max(numbers[4::5], default=0) >= len(languages):
        raise _bad("an unknown language")
    warnings: dict[int, list[ParseWarning]] = {}
    for entry in _lists_of(document.get("warnings")):
        if not (
            len(entry) == 4 and type(entry[0]) is int and 0 <= entry[0] < count
            and type(entry[1]) is int and entry[1] >= 0 and isinstance(entry[2], str)
            and type(entry[3]) is int and 0 <= entry[3] < len(_SEVERITIES)
        ):  # fmt: skip
            raise _bad("a malformed warning")
        i, line, message, severity = entry
        warnings.setdefault(i, []).append(
            ParseWarning(files[i], line, message, _SEVERITY_MEMBERS[severity])
        )
    counts = _ints(document.get("functions"), 0, 1 << 62, 2 * count)
    pairs = zip(counts[0::2], counts[1::2], strict=True)
    if any(estimated > functions for functions, estimated in pairs):
        raise _bad("more functions estimated than a file has")
    flags = numbers[3::5]
    fields = zip(
        files,
        list(map(languages.__getitem__, numbers[4::5])),
        blobs,
        numbers[0::5],
        numbers[1::5],
        numbers[2::5],
        [bool(f & _PARSED) for f in flags],
        [bool(f & _GENERATED) for f in flags],
        [tuple(warnings.get(i, ())) for i in range(count)] if warnings else [()] * count,
        counts[0::2],
        counts[1::2],
        strict=True,
    )
    return tuple(map(_new, repeat(FileRow), fields))  # rows checked above: made directly


def _regrouped(
    value: object, elements: tuple[Element, ...], files: list[str]
) -> tuple[Element, ...]:
    """The diff's grouping: the coupling's, changed as the record says (``_groups``)."""
    names, members, sizes, gone = _lists(value, 4)
    other = _grouped(_texts(names), members, sizes, files, ())
    by_name = {e.name: e for e in elements}
    for name in _texts(gone):
        by_name.pop(name, None)
    by_name.update((e.name, e) for e in other)
    groups = tuple(sorted(by_name.values(), key=lambda e: e.name))
    if len({p for e in groups for p in e.files}) != sum(len(e.files) for e in groups):
        raise _bad("a file in two elements")
    return groups


def _grouped(names: list[str], members: object, sizes: object, files: list[str],
             kinds: Sequence[tuple[str, ...]]) -> tuple[Element, ...]:  # fmt: skip
    count = len(files)
    lengths = _ints(sizes, 0, count + 1, len(names))
    groups = _split(_ints(members, 0, count), lengths)
    pick = files.__getitem__
    members_of = [tuple(map(pick, g)) for g in groups]
    fields = zip(names, members_of, kinds or [()] * len(names), strict=True)
    return tuple(map(_new, repeat(Element), fields))


def _elements(value: object, files: list[str], languages: list[str]) -> tuple[Element, ...]:
    names, members, sizes, kinds, kind_sizes = _lists(value, 5)
    names = _texts(names)
    codes = _ints(kinds, 0, len(languages))
    lengths = _ints(kind_sizes, 0, len(languages) + 1, len(names))
    if sum(lengths) != len(codes):
        raise _bad("lengths that do not add up")
    # each element's languages, one tuple per distinct list (most elements hold one file)
    ones = [(language,) for language in languages]
    made: dict[tuple[int, ...], tuple[str, ...]] = {}
    langs: list[tuple[str, ...]] = []
    start = 0
    for end in accumulate(lengths):
        if end - start == 1:
            langs.append(ones[codes[start]])
        else:
            key = tuple(codes[start:end])
            found = made.get(key)
            if found is None:
                found = made[key] = tuple(map(languages.__getitem__, key))
            langs.append(found)
        start = end
    return _grouped(names, members, sizes, files, langs)


def _receivers(value: object, names: list[str]) -> dict[str, frozenset[str]]:
    """Keys received without a site, each with the elements (by position) receiving it."""
    if not isinstance(value, list):
        raise _bad("no receivers")
    found: dict[str, frozenset[str]] = {}
    for entry in value:
        if not (isinstance(entry, list) and len(entry) == 2 and isinstance(entry[0], str)):
            raise _bad("a receiver that is not a key and its elements")
        found[entry[0]] = frozenset(names[i] for i in _ints(entry[1], 0, len(names)))
    return found


def _sites(value: object, files: list[str]) -> dict[str, tuple[Site, ...]]:
    where, sizes, roles, keys = _lists(value, 4)
    located = _ints(where, 0, len(files))
    lengths = _ints(sizes, 0, 1 << 62, len(located))
    codes = _ints(roles, 0, len(_ROLES))
    texts = _texts(keys, len(codes), none=True)
    spans = _split(list(zip(codes, texts, strict=True)), lengths)
    return {
        files[i]: tuple((_ROLES[role], key) for role, key in span)
        for i, span in zip(located, spans, strict=True)
    }


def _table(value: object, groups: Sequence[Element], files: list[str]) -> dict[str, ElementRow]:
    codes, numbers, notes, note_sizes, partial = _lists(value, 5)
    locations = _ints(codes, -1, len(_LOCATIONS), len(groups))
    sums = _ints(numbers, 0, 1 << 62, 3 * len(groups))
    texts = list(_split(_texts(notes), _ints(note_sizes, 0, 1 << 62, len(groups))))
    members: dict[int, tuple[str, ...]] = {}
    for entry in _lists_of(partial):
        if len(entry) != 2 or not (type(entry[0]) is int and 0 <= entry[0] < len(groups)):
            raise _bad("a malformed element row")
        chosen = tuple(files[i] for i in _ints(entry[1], 0, len(files)))
        if not set(chosen) <= set(groups[entry[0]].files):
            raise _bad("an element row naming a file of another element")
        members[entry[0]] = chosen
    named = [element.name for element in groups]
    own = [members.get(k) or element.files for k, element in enumerate(groups)]
    fields = zip(
        own,
        [_LOCATIONS[code] for code in locations],
        map(tuple, texts),
        sums[0::3],
        sums[1::3],
        sums[2::3],
        strict=True,
    )
    made = map(_new, repeat(ElementRow), fields)  # checked above: made directly
    return {name: row for name, row, code in zip(named, made, locations, strict=True) if code >= 0}


def _consistent(files: list[str], index: CouplingIndex, deps: DepTable) -> None:
    """What the rest of a diff relies on: files named once, each measured file in exactly
    one element, records only for measured files, dependencies only into measured files."""
    measured = set(index.paths)
    members = [p for e in index.elements for p in e.files]
    records = {files[i] for i in deps.where} | {files[t] for t in set(deps.targets) if t >= 0}
    if (
        len(set(files)) != len(files)
        or len(measured) != len(index.paths)
        or len(members) != len(measured)
        or set(members) != measured
        or len({e.name for e in index.elements}) != len(index.elements)
        or not measured.issuperset(records)
        or not measured.issuperset(index.sites)
    ):
        raise _bad("an inconsistent coupling index")
