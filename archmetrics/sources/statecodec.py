"""A tree's state (app/tree.py) to and from a cache record: compressed JSON, read back field
by field. The cache file is not trusted: a record that is not exactly what ``encode`` writes
raises :class:`~archmetrics.sources.codec.CodecError`, and the caller recomputes the state.

The record is columns, files named by their position: per file its path, blob, language,
λ, SLOC, v_g and flags; the parse warnings; the measured files in coupling order; each
element with its files; each file's dependency records and link-site records; each
element's four coupling values.
"""

from __future__ import annotations

import json
import zlib
from collections.abc import Callable, Sequence
from typing import Any, TypeVar

from archmetrics.changeset.locations import Location
from archmetrics.changeset.model import ExcludedFile
from archmetrics.changeset.rows import FileRow
from archmetrics.changeset.state import TreeState
from archmetrics.changeset.unchanged import ElementRow
from archmetrics.coupling.elements import Element
from archmetrics.coupling.index import CouplingIndex, Dep, Site, Values
from archmetrics.facts import ParseWarning, Severity
from archmetrics.sources.codec import CodecError

FORMAT = 1
_PARSED, _GENERATED = 1, 2
_SEVERITIES = frozenset(s.value for s in Severity)
_RESOLUTIONS = frozenset({"internal", "external", "unresolved"})
_ROLES = frozenset({"initiate", "receive", "use"})
_LOCATIONS = frozenset(loc.value for loc in Location)
_T = TypeVar("_T")


def encode(state: TreeState) -> bytes:
    """The record of a tree's state."""
    rows, index = state.rows, state.index
    position = {row.path: i for i, row in enumerate(rows)}
    numbers: list[int] = []
    for row in rows:
        flags = (_PARSED if row.parsed else 0) | (_GENERATED if row.generated else 0)
        numbers += (row.loc, row.sloc, row.vg, flags)
    document = {
        "format": FORMAT,
        "files": [r.path for r in rows],
        "blobs": [r.blob for r in rows],
        "languages": [r.language for r in rows],
        "numbers": numbers,
        "warnings": [
            [i, w.line, w.message, w.severity.value]
            for i, row in enumerate(rows)
            for w in row.warnings
        ],
        "measured": [position[p] for p in index.paths],
        "elements": [
            [e.name, [position[p] for p in e.files], list(e.languages)] for e in index.elements
        ],
        "deps": [
            [position[p], [[-1 if t is None else position[t], r, n] for t, r, n in deps]]
            for p, deps in index.deps.items()
        ],
        "sites": [[position[p], [list(s) for s in sites]] for p, sites in index.sites.items()],
        "values": [n for e in index.elements for n in index.values[e.name]],
        # the diff's grouping of every selected file: none when the coupling's is the same
        "groups": None if _same(state.groups, index.elements) else [
            [e.name, [position[p] for p in e.files]] for e in state.groups
        ],
        "table": [_table_row(state.table.get(e.name), e, position) for e in state.groups],
        "excluded": [[position[x.path], x.reason] for x in state.excluded],
    }
    # ASCII escapes: a warning may quote a lone surrogate, which no UTF-8 holds
    return zlib.compress(json.dumps(document, separators=(",", ":")).encode(), 1)


def _same(groups: Sequence[Element], elements: Sequence[Element]) -> bool:
    return len(groups) == len(elements) and all(
        (a.name, a.files) == (b.name, b.files) for a, b in zip(groups, elements, strict=True)
    )


def _table_row(
    row: ElementRow | None, element: Element, position: dict[str, int]
) -> list[Any] | None:
    """An element's row: its location, notes, λ, SLOC and v_g, and its measured files when
    they are not all of its files; none when it has no measured file."""
    if row is None:
        return None
    files = None if row.files == tuple(sorted(element.files)) else [position[p] for p in row.files]
    return [row.location.value, list(row.notes), row.loc, row.sloc, row.vg, files]


def decode(data: bytes) -> TreeState:
    """The state ``encode`` wrote; :class:`CodecError` for anything else."""
    try:
        document = _loads(zlib.decompress(data))
    except (zlib.error, ValueError) as error:
        raise CodecError(f"not a tree state: {error}") from error
    if not isinstance(document, dict) or document.get("format") != FORMAT:
        raise CodecError("not a tree state of this format")
    files = _strings(document.get("files"))
    count = len(files)
    rows = _rows(document, files)
    at = _positions(count)
    paths = tuple(files[i] for i in _list(document.get("measured"), at))
    elements = tuple(_element(e, files, at) for e in _list(document.get("elements"), _is_list))
    deps = {files[i]: tuple(_dep(d, files, at) for d in found) for i, found in _pairs("deps", document, at)}
    sites = {files[i]: tuple(_site(s) for s in found) for i, found in _pairs("sites", document, at)}
    numbers = _list(document.get("values"), _natural)
    if len(numbers) != 4 * len(elements):
        raise CodecError("coupling values do not match the elements")
    values: dict[str, Values] = {
        e.name: (numbers[4 * k], numbers[4 * k + 1], numbers[4 * k + 2], numbers[4 * k + 3])
        for k, e in enumerate(elements)
    }
    index = CouplingIndex(paths, elements, deps, sites, values)
    _consistent(files, index)
    groups = elements
    if document.get("groups") is not None:
        groups = tuple(_group(g, files, at) for g in _list(document.get("groups"), _is_list))
    if len({p for e in groups for p in e.files}) != sum(len(e.files) for e in groups):
        raise CodecError("a file in two elements of a tree state")
    table = _table(_list(document.get("table"), lambda v: v is None or isinstance(v, list)),
                   groups, files, at)  # fmt: skip
    excluded = tuple(_excluded(x, files, at) for x in _list(document.get("excluded"), _is_list))
    return TreeState(rows, index, groups, table, excluded)


def _group(entry: list[Any], files: list[str], at: Callable[[object], bool]) -> Element:
    if not (len(entry) == 2 and isinstance(entry[0], str)):
        raise CodecError("a malformed element in a tree state")
    return Element(entry[0], tuple(files[i] for i in _list(entry[1], at)), ())


def _table(
    entries: list[Any], groups: Sequence[Element], files: list[str], at: Callable[[object], bool]
) -> dict[str, ElementRow]:
    if len(entries) != len(groups):
        raise CodecError("element rows do not match the elements")
    table = {}
    for entry, element in zip(entries, groups, strict=True):
        if entry is None:
            continue
        if not (
            len(entry) == 6 and entry[0] in _LOCATIONS and all(map(_natural, entry[2:5]))
            and (entry[5] is None or isinstance(entry[5], list))
        ):  # fmt: skip
            raise CodecError("a malformed element row in a tree state")
        members = tuple(sorted(element.files))
        if entry[5] is not None:
            members = tuple(files[i] for i in _list(entry[5], at))
            if not set(members) <= set(element.files):
                raise CodecError("an element row names a file of another element")
        notes = tuple(_strings(entry[1]))
        table[element.name] = ElementRow(members, Location(entry[0]), notes, *entry[2:5])
    return table


def _excluded(entry: list[Any], files: list[str], at: Callable[[object], bool]) -> ExcludedFile:
    if not (len(entry) == 2 and at(entry[0]) and isinstance(entry[1], str)):
        raise CodecError("a malformed excluded file in a tree state")
    return ExcludedFile(files[entry[0]], entry[1])


def _consistent(files: list[str], index: CouplingIndex) -> None:
    """What the rest of a diff relies on: files named once, each measured file in exactly
    one element, records only for measured files, dependencies only into measured files."""
    measured = set(index.paths)
    members = [p for e in index.elements for p in e.files]
    if (
        len(set(files)) != len(files)
        or len(measured) != len(index.paths)
        or len(members) != len(measured)
        or set(members) != measured
        or len({e.name for e in index.elements}) != len(index.elements)
        or not measured.issuperset(index.deps)
        or not measured.issuperset(index.sites)
        or any(t is not None and t not in measured for d in index.deps.values() for t, _, _ in d)
    ):
        raise CodecError("an inconsistent tree state")


def _loads(text: bytes) -> Any:
    import orjson

    try:
        return orjson.loads(text)
    except orjson.JSONDecodeError:  # an escaped lone surrogate: orjson refuses it, json reads it
        return json.loads(text)


def _is_list(value: object) -> bool:
    return isinstance(value, list)


def _natural(value: object) -> bool:
    return type(value) is int and value >= 0


def _positions(count: int) -> Callable[[object], bool]:
    return lambda value: type(value) is int and 0 <= value < count


def _list(value: object, check: Callable[[object], bool]) -> list[Any]:
    if not isinstance(value, list) or not all(map(check, value)):
        raise CodecError("a malformed list in a tree state")
    return value


def _strings(value: object) -> list[str]:
    return _list(value, lambda v: isinstance(v, str))


def _rows(document: dict[str, Any], files: list[str]) -> tuple[FileRow, ...]:
    count = len(files)
    blobs, languages = _strings(document.get("blobs")), _strings(document.get("languages"))
    numbers = _list(document.get("numbers"), _natural)
    if not (len(blobs) == len(languages) == count and len(numbers) == 4 * count):
        raise CodecError("tree state columns of different lengths")
    warnings: dict[int, list[ParseWarning]] = {}
    at = _positions(count)
    for entry in _list(document.get("warnings"), _is_list):
        if not (
            len(entry) == 4 and at(entry[0]) and _natural(entry[1])
            and isinstance(entry[2], str) and entry[3] in _SEVERITIES
        ):  # fmt: skip
            raise CodecError("a malformed warning in a tree state")
        i, line, message, severity = entry
        warnings.setdefault(i, []).append(ParseWarning(files[i], line, message, Severity(severity)))
    return tuple(
        FileRow(
            files[i], languages[i], blobs[i], numbers[4 * i], numbers[4 * i + 1],
            numbers[4 * i + 2], bool(numbers[4 * i + 3] & _PARSED),
            bool(numbers[4 * i + 3] & _GENERATED), tuple(warnings.get(i, ())),
        )  # fmt: skip
        for i in range(count)
    )


def _element(entry: list[Any], files: list[str], at: Callable[[object], bool]) -> Element:
    if not (len(entry) == 3 and isinstance(entry[0], str)):
        raise CodecError("a malformed element in a tree state")
    members = tuple(files[i] for i in _list(entry[1], at))
    return Element(entry[0], members, tuple(_strings(entry[2])))


def _pairs(
    name: str, document: dict[str, Any], at: Callable[[object], bool]
) -> list[tuple[int, list[Any]]]:
    found = []
    for entry in _list(document.get(name), _is_list):
        if not (len(entry) == 2 and at(entry[0])):
            raise CodecError(f"a malformed {name} entry in a tree state")
        found.append((entry[0], _list(entry[1], _is_list)))
    return found


def _dep(entry: list[Any], files: list[str], at: Callable[[object], bool]) -> Dep:
    outside = type(entry[0]) is int and entry[0] == -1
    if not (
        len(entry) == 3 and (outside or at(entry[0]))
        and entry[1] in _RESOLUTIONS and isinstance(entry[2], str)
    ):  # fmt: skip
        raise CodecError("a malformed dependency in a tree state")
    return Dep(None if outside else files[entry[0]], entry[1], entry[2])


def _site(entry: list[Any]) -> Site:
    if not (len(entry) == 2 and entry[0] in _ROLES and (entry[1] is None or isinstance(entry[1], str))):
        raise CodecError("a malformed link site in a tree state")
    return (entry[0], entry[1])
