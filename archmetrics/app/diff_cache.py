"""What a diff keeps in the facts cache between runs: each file pair's change (by the two
blobs) and each file's link sites (by content), so that the next diff of a branch, a warm
rerun or the next stage of a series reads and matches only what changed."""

from __future__ import annotations

import functools
import hashlib
import json
from collections.abc import Callable, Iterator, Mapping, Sequence
from importlib import metadata
from typing import TypeVar

from archmetrics.app.coupling import packs_digest
from archmetrics.changeset.elements import Differ
from archmetrics.changeset.model import MeasuredFile
from archmetrics.changeset.rows import FileRow, diff_measured
from archmetrics.changeset.statement_diff import (
    CHANGE_RECORD,
    FileChange,
    change_from_record,
    change_record,
    diff_files,
    same_statements,
)
from archmetrics.coupling import CouplingOptions
from archmetrics.coupling.rules import RuleSet
from archmetrics.coupling.sitememo import RECORD, SiteMemo
from archmetrics.facts import FileFacts
from archmetrics.sources.cache import FactsCache, code_fingerprint


@functools.cache
def _rapidfuzz() -> str:
    return metadata.version("rapidfuzz")


class _CachedSites:
    """The facts cache as a store of link-site records (coupling/sitememo.py)."""

    def __init__(self, cache: FactsCache) -> None:
        self.cache = cache

    def get_many(self, keys: Sequence[str]) -> Mapping[str, bytes]:
        return self.cache.get_totals(keys)

    def put_many(self, items: Mapping[str, bytes]) -> None:
        self.cache.put_totals(items.items())


def site_memo(
    cache: FactsCache,
    measured: Sequence[MeasuredFile] | Mapping[str, FileRow],
    blobs: Mapping[str, str],
    options: CouplingOptions,
    packs: RuleSet,
) -> SiteMemo:
    """Each file's link sites kept in ``cache`` by content: a tree coupled after another that
    shares most of its files (the worktree after an edit, the next revision of a series)
    matches rules and traces endpoints only for the files whose reach changed. ``measured``:
    the measured files, or rows by path (each file's content then named when asked for:
    a patch asks for the few files it redoes)."""
    context = _digest(
        [RECORD, code_fingerprint(), cache.fingerprint, repr(options), packs_digest(packs)]
    )
    identity: Mapping[str, str]
    if isinstance(measured, Mapping):
        identity = _Contents(measured)
    else:
        identity = {f.path: f"{blobs[f.path]}:{f.language}" for f in measured if blobs.get(f.path)}
    return SiteMemo(_CachedSites(cache), context, identity)


class _Contents(Mapping[str, str]):
    """Each file's content id (blob and language), made from its row when asked for."""

    def __init__(self, rows: Mapping[str, FileRow]) -> None:
        self.rows = rows

    def __getitem__(self, path: str) -> str:
        row = self.rows[path]
        if not row.blob:
            raise KeyError(path)
        return f"{row.blob}:{row.language}"

    def __iter__(self) -> Iterator[str]:
        return iter(self.rows)

    def __len__(self) -> int:
        return len(self.rows)


_T = TypeVar("_T")


def _kept(
    cache: FactsCache | None,
    key: str | None,
    read: Callable[[bytes], _T | None],
    compute: Callable[[], _T],
    write: Callable[[_T], bytes],
) -> _T:
    """What ``cache`` keeps under ``key`` if ``read`` believes it (the cache file is not
    trusted: ``read`` gives None for anything it did not write), else ``compute``'s result,
    kept as ``write`` gives it. Without a cache or a key, computed."""
    if cache is None or key is None:
        return compute()
    data = cache.get_total(key)
    known = read(data) if data is not None else None
    if known is not None:
        return known
    value = compute()
    cache.put_total(key, write(value))
    return value


def _compact(value: object) -> bytes:
    """JSON without blanks, ASCII escapes (a text may hold a lone surrogate, which no UTF-8
    can)."""
    return json.dumps(value, separators=(",", ":")).encode()


def _digest(document: Sequence[object]) -> str:
    return hashlib.sha256(json.dumps(document).encode()).hexdigest()


def cached_differ(
    cache: FactsCache, pre: Mapping[str, FileRow], post: Mapping[str, FileRow]
) -> Differ:
    """``diff_measured`` with each file pair's change kept in ``cache`` under a digest of
    what decides it (:func:`change_key`): a diff that meets the same two blobs again (the
    next diff of a branch, a warm rerun, each stage of a series) reads neither file's
    statements. ``pre``, ``post``: each side's rows by path (their blobs)."""

    def diff(before: MeasuredFile | None, after: MeasuredFile | None) -> FileChange:
        if not isinstance(before, FileFacts | None) or not isinstance(after, FileFacts | None):
            return diff_measured(before, after)  # rows of one content: nothing to keep
        if before and after and same_statements(before.statements, after.statements):
            return diff_files(before, after)  # known equal without reading them
        pre_path, post_path = before.path if before else None, after.path if after else None

        def read(data: bytes) -> FileChange | None:
            try:
                return change_from_record(json.loads(data), pre_path, post_path)
            except ValueError:
                return None

        key = change_key(before, after, pre, post, cache.fingerprint)
        return _kept(
            cache,
            key,
            read,
            lambda: diff_files(before, after),
            lambda change: _compact(change_record(change)),
        )

    return diff


def change_key(
    pre: FileFacts | None,
    post: FileFacts | None,
    pre_rows: Mapping[str, FileRow],
    post_rows: Mapping[str, FileRow],
    parser: str,
) -> str | None:
    """A digest of what decides a file pair's change: this archmetrics's code (the pairing
    rule), rapidfuzz's version (its similarity), and each side's blob and language under the
    ``parser`` fingerprint of the facts cache, named by the record's kind (the cache's
    ``totals`` table holds trees' coupling too). None if a side's blob is unknown."""
    sides: list[object] = []
    for facts, rows in ((pre, pre_rows), (post, post_rows)):
        if facts is None:
            sides.append(None)
            continue
        row = rows.get(facts.path)
        if row is None or not row.blob:
            return None
        sides.append([row.blob, facts.language])
    document = [CHANGE_RECORD, code_fingerprint(), _rapidfuzz(), parser, sides]
    return f"{CHANGE_RECORD}:{_digest(document)}"
