"""One side of a diff: a snapshot's state (changeset/state.py) and its files' facts, read
when asked for (docs/performance.md, "Incremental diffs").

A commit's state is kept in the facts cache under its tree id (and all that decides the
state: archmetrics's code, the parser settings, the options); a diff whose base state is
known patches it with what git says differs for the head (gitdelta.py) instead of listing,
reading and coupling the whole head tree: the changed files are parsed, their dependencies
resolved again, the link sites of the files that reach them found again, and the values of
the elements that any of it touches counted again. A tree whose measured paths differ from
the base's is coupled whole (from the facts cache), and so is a delta larger than
:data:`PATCH_LIMIT` of the tree. Without a cache both sides are built whole: ``--no-cache``
measures from scratch. The result is the same whichever way it was found
(tests/app/test_tree.py holds the two to it on real histories).
"""

from __future__ import annotations

import hashlib
import json
from bisect import bisect_left
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

from archmetrics.app.collect import Selected, parse_all, select
from archmetrics.app.coupling import configuration_files, packs_digest
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.changeset.files import exclusion, measured_files
from archmetrics.changeset.rows import FileRow
from archmetrics.changeset.state import TreeState, owners, patched_state, tree_state
from archmetrics.coupling.index import CouplingIndex, LazyFacts, build_index
from archmetrics.coupling.index_patch import patch_index
from archmetrics.coupling.measure import link_tree
from archmetrics.coupling.rostree import configures
from archmetrics.facts import FileFacts
from archmetrics.parsers import LanguageTable
from archmetrics.sources import Snapshot, SourceFile
from archmetrics.sources.cache import FactsCache, code_fingerprint
from archmetrics.sources.codec import CodecError
from archmetrics.sources.gitdelta import Delta, Pending

if TYPE_CHECKING:
    from archmetrics.app.diff_options import DiffOptions

STATE_RECORD = "tree-state/1"
_CONFIGURATION = frozenset({"xml", "yaml"})  # a tree holding these is ROS: patched whole
PATCH_LIMIT = 0.25  # a delta touching more than this share of a tree's files: built whole


class MissingFacts(Exception):
    """A file's facts are in neither this run's memory nor the cache."""


@dataclass(eq=False)
class Side:
    """A snapshot, its state and its files' facts (those this run has, the rest read from
    the cache when asked for). ``changed``: the paths whose files differ from the side it
    was patched from, and ``renames`` (old -> new) as git found them; both None for a side
    not patched (the caller compares and asks git)."""

    snapshot: Snapshot
    state: TreeState
    cache: FactsCache | None
    known: dict[str, FileFacts] = field(default_factory=dict)
    changed: frozenset[str] | None = None
    renames: dict[str, str] | None = None
    by_path: dict[str, FileRow] = field(init=False)
    _owner: dict[str, str] | None = field(init=False, default=None)

    def __post_init__(self) -> None:
        self.by_path = {row.path: row for row in self.state.rows}

    @property
    def owner(self) -> dict[str, str]:
        """Each file's element name (computed once)."""
        if self._owner is None:
            self._owner = owners(self.state.groups)
        return self._owner

    def facts(self, path: str) -> FileFacts:
        """The facts of the file at ``path`` (:class:`MissingFacts` if there are none)."""
        found = self.known.get(path)
        if found is None:
            row = self.by_path[path]
            found = self.cache.get(row.blob, row.language, path) if self.cache else None
            if found is None:
                raise MissingFacts(path)
            self.known[path] = found
        return found

    def facts_of(self, paths: Iterable[str], options: DiffOptions,
                 progress: Progress) -> dict[str, FileFacts]:  # fmt: skip
        """The facts of ``paths``: those this run has, the others from the cache or parsed
        (in workers)."""
        wanted = set(paths)
        found = {path: self.known[path] for path in wanted if path in self.known}
        missing = [
            Selected(SourceFile(path, row.blob), row.language)
            for path in sorted(wanted - found.keys())
            for row in (self.by_path[path],)
        ]
        if missing:
            parsed = _parse(self.snapshot, missing, options, progress, self.cache, {})
            self.known.update((f.path, f) for f in parsed)
            found.update((f.path, f) for f in parsed)
        return found


def _parse(
    snapshot: Snapshot,
    selected: list[Selected],
    options: DiffOptions,
    progress: Progress,
    cache: FactsCache | None,
    blobs: dict[str, str],
) -> tuple[FileFacts, ...]:
    return parse_all(
        snapshot, selected, options.languages, options.jobs, progress, cache, options.limits, blobs
    )


def state_key(tree: str, options: DiffOptions, cache: FactsCache) -> str:
    """A digest of all that decides a tree's state: archmetrics's code, the facts' parser
    fingerprint (with its settings), the languages, the exclusion and location rules,
    whether generated files are read, the coupling options, the rule packs and the tree."""
    document = [
        STATE_RECORD, code_fingerprint(), cache.fingerprint, options.languages,
        repr(options.rules), options.limits.skip_generated, repr(options.coupling),
        packs_digest(options.packs), tree,
    ]  # fmt: skip
    return f"{STATE_RECORD}:{hashlib.sha256(json.dumps(document).encode()).hexdigest()}"


def begin_delta(base: Snapshot, head: Snapshot, cache: FactsCache | None) -> Pending | None:
    """Git set to work out what differs from ``base`` (a commit) to ``head``, when a patch
    may use it (with a cache): started before the base's state is read, so that git walks
    the tree while that is done."""
    commit = getattr(base, "commit", None)
    delta_from = getattr(head, "delta_from", None)
    if cache is None or commit is None or delta_from is None:
        return None
    pending: Pending = delta_from(commit)
    return pending


def side_of(
    snapshot: Snapshot,
    options: DiffOptions,
    cache: FactsCache | None,
    progress: Progress | None = None,
    origin: Side | None = None,
    delta: Pending | None = None,
) -> Side:
    """The side of ``snapshot``: its state read from the cache, patched from ``origin``'s
    (a commit's side) where git can say what differs (``delta``: git already asked, by
    :func:`begin_delta`), or built whole."""
    from archmetrics.sources.statecodec import decode, encode

    progress = progress or NoProgress()
    tree = getattr(snapshot, "tree", None) if cache is not None else None
    key = state_key(tree, options, cache) if cache is not None and tree else None
    if key is not None and cache is not None and (data := cache.get_total(key)) is not None:
        try:
            return Side(snapshot, decode(data), cache)
        except CodecError:
            pass  # not believed: built again below, and kept over it
    # without a cache, both sides are built whole: --no-cache measures from scratch
    side = None
    if origin and cache:
        side = patched_side(snapshot, origin, options, cache, progress, delta)
    side = side or whole_side(snapshot, options, cache, progress)
    if key is not None and cache is not None:
        cache.put_total(key, encode(side.state))
    return side


def whole_side(
    snapshot: Snapshot, options: DiffOptions, cache: FactsCache | None, progress: Progress
) -> Side:
    """Every file of ``snapshot`` read (from the cache or parsed) and the tree coupled."""
    table = LanguageTable.default(dict(options.languages))
    selected = select(snapshot, table, configuration=configuration_files(options.packs))
    blobs: dict[str, str] = {}
    facts = _parse(snapshot, list(selected), options, progress, cache, blobs)
    rows = tuple(FileRow.of(f, blobs[f.path]) for f in facts)
    progress.phase(f"coupling {snapshot.label}")
    index = _couple(facts, rows, options, cache)
    state = tree_state(rows, index, options.rules, options.coupling.grouping)
    return Side(snapshot, state, cache, {f.path: f for f in facts})


def _couple(
    facts: Iterable[FileFacts],
    rows: Iterable[FileRow],
    options: DiffOptions,
    cache: FactsCache | None,
) -> CouplingIndex:
    from archmetrics.app.diff_cache import site_memo

    measured = measured_files(facts, options.rules)
    blobs = {row.path: row.blob for row in rows}
    memo = site_memo(cache, measured, blobs, options.coupling, options.packs) if cache else None
    links = link_tree(measured, options.coupling, options.packs, memo)
    return build_index(links, [f.path for f in measured])


def patched_side(
    snapshot: Snapshot,
    origin: Side,
    options: DiffOptions,
    cache: FactsCache | None,
    progress: Progress,
    pending: Pending | None,
) -> Side | None:
    """``origin``'s state patched to ``snapshot``'s, or None where it cannot be (no commit
    on the origin side, no delta git can give, a delta too large)."""
    pending = pending or begin_delta(origin.snapshot, snapshot, cache)
    if pending is None:
        return None
    progress.phase(f"asking git what differs from {origin.snapshot.label} to {snapshot.label}")
    delta = pending()
    rows_before = origin.state.rows
    if delta is None or len(delta.changed) + len(delta.removed) > PATCH_LIMIT * len(rows_before):
        return None
    table = LanguageTable.default(dict(options.languages))
    configuration = configuration_files(options.packs)
    if configuration.markers:  # which folders are ROS packages: a new or gone one, built whole
        touched = {f.path for f in delta.changed} | set(delta.removed)
        if any(path.rpartition("/")[2] in configuration.markers for path in touched):
            return None
        configuration = configuration.in_tree(row.path for row in rows_before)
    selected = [
        Selected(f, language)
        for f in delta.changed
        if (language := table.language_of(f.path) or configuration(f.path)) is not None
    ]
    blobs: dict[str, str] = {}
    fresh = {f.path: f for f in _parse(snapshot, selected, options, progress, cache, blobs)}
    rows = _merged(origin, delta, {p: FileRow.of(f, blobs[p]) for p, f in fresh.items()})
    by_path = origin.by_path
    changed = frozenset(
        path
        for path in (*delta.removed, *fresh)
        if (row := by_path.get(path)) is None
        or path not in fresh
        or (row.blob, row.language) != (blobs[path], fresh[path].language)
    )
    progress.phase(f"coupling {snapshot.label}")
    side = Side(snapshot, origin.state, cache, dict(fresh), changed, dict(delta.renames))
    side.by_path = {row.path: row for row in rows}
    side.state = replace(origin.state, rows=rows)  # the index and the rest: patched below
    try:
        index = _patched_index(origin, side, changed, options, cache)
    except MissingFacts:  # the cache lost a file's facts since the state was kept
        return None
    rules, per_file = options.rules, options.coupling.grouping
    side.state = patched_state(origin.state, rows, index, changed, rules, per_file, origin.owner)
    return side


def _merged(origin: Side, delta: Delta, fresh: Mapping[str, FileRow]) -> tuple[FileRow, ...]:
    """``origin``'s rows with the delta's: its removed and its changed paths taken out, the
    rows of the changed files that have a language put in, each where it sorts (a snapshot
    lists its files in path order); an unchanged file keeps ``origin``'s row."""
    rows = list(origin.state.rows)
    for path in sorted(delta.removed | {f.path for f in delta.changed}):
        at = bisect_left(rows, path, key=_path)
        found = at < len(rows) and rows[at].path == path
        row = fresh.get(path)
        if row is None:
            if found:
                del rows[at]
        elif not found:
            rows.insert(at, row)
        elif rows[at] != row:
            rows[at] = row
    return tuple(rows)


def _path(row: FileRow) -> str:
    return row.path


def _patched_index(
    origin: Side, side: Side, changed: frozenset[str], options: DiffOptions,
    cache: FactsCache | None,
) -> CouplingIndex:  # fmt: skip
    """The coupling of ``side``, whose files at ``changed`` paths differ from ``origin``'s:
    ``origin``'s index patched when the measured files are the same paths in the same
    languages, else the tree coupled whole."""
    rules = options.rules

    def measured(row: FileRow | None) -> bool:
        return row is not None and row.parsed and exclusion(row, rules) is None

    redone: dict[str, FileFacts] = {}
    if (
        origin.state.index.whole
        or any(row.language in _CONFIGURATION for row in origin.state.rows)
        or any(configures(side.facts(path)) for path in changed if path in side.by_path)
    ):  # launch, parameter or plugin files rename sites or receive them (rosgraph.py)
        facts = [side.facts(row.path) for row in measured_files(side.state.rows, rules)]
        return _couple(facts, side.state.rows, options, cache)
    for path in sorted(changed):
        before, after = origin.by_path.get(path), side.by_path.get(path)
        if measured(before) != measured(after) or (
            before is not None and after is not None and before.language != after.language
        ):  # the measured paths differ: coupled whole
            facts = [side.facts(row.path) for row in measured_files(side.state.rows, rules)]
            return _couple(facts, side.state.rows, options, cache)
        if measured(after):
            redone[path] = side.facts(path)
    index = origin.state.index
    lazy = LazyFacts(frozenset(index.paths), side.facts)
    memo = None
    if cache is not None:
        from archmetrics.app.diff_cache import site_memo

        memo = site_memo(cache, side.by_path, {}, options.coupling, options.packs)
    return patch_index(index, redone, lazy, options.coupling, options.packs, memo)
