"""Snapshot -> facts: pick the source files, read them, parse them (in parallel when many)."""

from __future__ import annotations

import gc
import multiprocessing
import multiprocessing.context
import os
from collections import deque
from collections.abc import Callable, Sequence
from concurrent.futures import Future, ProcessPoolExecutor
from dataclasses import dataclass

from archmetrics.app.progress import NoProgress, Progress
from archmetrics.facts import FileFacts
from archmetrics.parsers import LanguageTable, parse_source
from archmetrics.sources import Snapshot, SourceFile, codec
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.snapshot import blob_hash

PARALLEL_THRESHOLD = 48  # below this many files, a process pool costs more than it saves
BATCH = 16


@dataclass(frozen=True, slots=True)
class Selected:
    """A source file picked for measuring, with the language its ending maps to."""

    file: SourceFile
    language: str


def select(
    snapshot: Snapshot,
    table: LanguageTable,
    keep: Callable[[str], bool] = lambda path: True,
) -> tuple[Selected, ...]:
    """The files of ``snapshot`` that have a language and that ``keep`` accepts."""
    chosen = []
    for file in snapshot.files():
        language = table.language_of(file.path)
        if language is not None and keep(file.path):
            chosen.append(Selected(file, language))
    return tuple(chosen)


_worker_table: LanguageTable | None = None


def _init_worker(overrides: tuple[tuple[str, str], ...]) -> None:
    """A worker builds and drops one file's tree after another, and almost nothing it builds
    is cyclic: the collector is switched off, what the worker holds from its start (the
    parsers' modules) is moved out of its reach, and :func:`_parse_batch` collects the few
    cycles a batch leaves (``ast.literal_eval`` makes some) once at its end. A Python scan
    of numpy took 7 % less CPU so (docs/performance.md)."""
    global _worker_table
    _worker_table = LanguageTable.default(dict(overrides))
    gc.disable()
    gc.freeze()


def _parse_batch(batch: list[tuple[str, bytes, str]]) -> list[bytes]:
    """Facts for a batch, encoded the cache's way: ready to store, and cheaper to send and
    receive than pickle (a third of its cost when measured, docs/performance.md)."""
    assert _worker_table is not None
    encoded = [
        codec.encode(parse_source(path, data, language, _worker_table))
        for path, data, language in batch
    ]
    gc.collect()  # only what this batch made: the rest is frozen
    return encoded


def worker_count(jobs: int) -> int:
    """``jobs`` workers, or one per usable core when 0."""
    if jobs > 0:
        return jobs
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


@dataclass(slots=True)
class _Todo:
    index: int
    item: Selected
    blob: str
    data: bytes | None


def parse_all(
    snapshot: Snapshot,
    selected: Sequence[Selected],
    overrides: tuple[tuple[str, str], ...] = (),
    jobs: int = 0,
    progress: Progress | None = None,
    cache: FactsCache | None = None,
) -> tuple[FileFacts, ...]:
    """Facts for every selected file, in the order given: from the cache when it has them."""
    progress = progress or NoProgress()
    results: list[FileFacts | None] = [None] * len(selected)
    todo: list[_Todo] = []
    for index, item in enumerate(selected):
        blob, data = item.file.blob, None
        if not blob:  # a file on disk: hash it the way git would
            data = snapshot.read(item.file)
            blob = blob_hash(data)
        hit = cache.get(blob, item.language, item.file.path) if cache else None
        if hit is None:
            todo.append(_Todo(index, item, blob, data))
        results[index] = hit
    progress.start("parsing", len(todo))

    def keep(entry: _Todo, facts: FileFacts, encoded: bytes | None) -> None:
        results[entry.index] = facts
        if cache is not None:  # stored as each file arrives: encoded bytes are not held on
            data = encoded if encoded is not None else codec.encode(facts)
            cache.put_encoded([(entry.blob, facts.language, data)])
            cache.remember(entry.blob, facts)

    try:
        _parse(snapshot, todo, overrides, worker_count(jobs), progress, keep)
    finally:
        progress.stop()
    return tuple(f for f in results if f is not None)


Keep = Callable[[_Todo, FileFacts, bytes | None], None]
"""Receives each parsed file: its entry, its facts, and their encoding if a worker made it."""


def _payload(snapshot: Snapshot, entry: _Todo) -> tuple[str, bytes, str]:
    data = entry.data if entry.data is not None else snapshot.read(entry.item.file)
    return entry.item.file.path, data, entry.item.language


def _parse(
    snapshot: Snapshot,
    todo: Sequence[_Todo],
    overrides: tuple[tuple[str, str], ...],
    workers: int,
    progress: Progress,
    keep: Keep,
) -> None:
    """Parse each entry and hand it to ``keep``, in a process pool when there are many."""
    if workers == 1 or len(todo) < PARALLEL_THRESHOLD:
        table = LanguageTable.default(dict(overrides))
        for entry in todo:
            keep(entry, parse_source(*_payload(snapshot, entry), table), None)
            progress.advance()
        return
    _parse_parallel(snapshot, todo, overrides, workers, progress, keep)


def _parse_parallel(
    snapshot: Snapshot,
    todo: Sequence[_Todo],
    overrides: tuple[tuple[str, str], ...],
    workers: int,
    progress: Progress,
    keep: Keep,
) -> None:
    """Batches go to a process pool; at most a few batches per worker are read ahead, so
    memory stays bounded however large the tree is.

    The workers come from a fork server started before the first pool, while this process
    is still small: forked from here instead, each worker of a diff's second revision would
    inherit (and, as its allocator touches the pages, copy) all the facts of the first.
    """
    starts = range(0, len(todo), BATCH)
    window: deque[tuple[Future[list[bytes]], Sequence[_Todo]]] = deque()
    with _pool(workers, overrides) as pool:
        for batch in (todo[i : i + BATCH] for i in starts):
            payload = [_payload(snapshot, e) for e in batch]
            window.append((pool.submit(_parse_batch, payload), batch))
            if len(window) >= workers * 3:
                _collect(*window.popleft(), progress, keep)
        while window:
            _collect(*window.popleft(), progress, keep)


def _pool(workers: int, overrides: tuple[tuple[str, str], ...]) -> ProcessPoolExecutor:
    return ProcessPoolExecutor(
        workers,
        mp_context=_context(),
        initializer=_init_worker,
        initargs=(overrides,),
    )


def _context() -> multiprocessing.context.BaseContext:
    """The fork server where the platform has one (its workers start small), else the default."""
    if "forkserver" not in multiprocessing.get_all_start_methods():
        return multiprocessing.get_context()
    context = multiprocessing.get_context("forkserver")
    # the fork server imports the parsers once; every worker starts with them loaded
    context.set_forkserver_preload(
        ["archmetrics.app.collect", "archmetrics.parsers.python", "archmetrics.parsers.c_family"]
    )
    return context


def _collect(
    future: Future[list[bytes]], batch: Sequence[_Todo], progress: Progress, keep: Keep
) -> None:
    encoded = future.result()
    progress.advance(len(encoded))
    for data, entry in zip(encoded, batch, strict=True):
        keep(entry, codec.decode(data, entry.item.file.path), data)
