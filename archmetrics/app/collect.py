"""Snapshot -> facts: pick the source files, read them, parse them (in parallel when many)."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

from archmetrics.app.progress import NoProgress, Progress
from archmetrics.facts import FileFacts
from archmetrics.parsers import LanguageTable, parse_source
from archmetrics.sources import Snapshot, SourceFile

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
    global _worker_table
    _worker_table = LanguageTable.default(dict(overrides))


def _parse_batch(batch: list[tuple[str, bytes, str]]) -> list[FileFacts]:
    assert _worker_table is not None
    return [parse_source(path, data, language, _worker_table) for path, data, language in batch]


def worker_count(jobs: int) -> int:
    """``jobs`` workers, or one per usable core when 0."""
    if jobs > 0:
        return jobs
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def parse_all(
    snapshot: Snapshot,
    selected: Sequence[Selected],
    overrides: tuple[tuple[str, str], ...] = (),
    jobs: int = 0,
    progress: Progress | None = None,
) -> tuple[FileFacts, ...]:
    """Facts for every selected file, in the order given."""
    progress = progress or NoProgress()
    table = LanguageTable.default(dict(overrides))
    workers = worker_count(jobs)
    progress.start("parsing", len(selected))
    try:
        if workers == 1 or len(selected) < PARALLEL_THRESHOLD:
            results = []
            for item in selected:
                data = snapshot.read(item.file)
                results.append(parse_source(item.file.path, data, item.language, table))
                progress.advance()
            return tuple(results)
        return _parse_parallel(snapshot, selected, overrides, workers, progress)
    finally:
        progress.stop()


def _parse_parallel(
    snapshot: Snapshot,
    selected: Sequence[Selected],
    overrides: tuple[tuple[str, str], ...],
    workers: int,
    progress: Progress,
) -> tuple[FileFacts, ...]:
    batches = [
        [(s.file.path, snapshot.read(s.file), s.language) for s in selected[i : i + BATCH]]
        for i in range(0, len(selected), BATCH)
    ]
    results: list[FileFacts] = []
    with ProcessPoolExecutor(workers, initializer=_init_worker, initargs=(overrides,)) as pool:
        for facts in pool.map(_parse_batch, batches):
            results.extend(facts)
            progress.advance(len(facts))
    return tuple(results)
