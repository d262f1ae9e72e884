"""Snapshot -> facts: pick the source files, read them, parse them in worker processes."""

from __future__ import annotations

import os
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.workers import Parsed, Task, WorkerLimits, parse_in_workers
from archmetrics.config import LimitSettings, MacroSettings, Settings
from archmetrics.facts import FileFacts, ParseWarning, Severity
from archmetrics.parsers import LanguageTable, ParseLimits
from archmetrics.parsers.c_family_macro_rules import MacroNames
from archmetrics.parsers.limits import stack_bytes, too_large
from archmetrics.sources import Snapshot, SourceFile, codec
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.snapshot import Sized, blob_hash

BATCH = 16  # files per message to a worker
DEFAULT_LIMITS = WorkerLimits()


@dataclass(frozen=True, slots=True)
class Selected:
    """A source file picked for measuring, with the language its ending maps to."""

    file: SourceFile
    language: str


def select(
    snapshot: Snapshot,
    table: LanguageTable,
    keep: Callable[[str], bool] = lambda path: True,
    configuration: Callable[[str], str | None] | None = None,
) -> tuple[Selected, ...]:
    """The files of ``snapshot`` that have a language and that ``keep`` accepts: source by
    its ending, else configuration in the format ``configuration`` (from the rule packs,
    :func:`archmetrics.app.coupling.configuration_files`) gives for its path."""
    files = list(snapshot.files())
    in_tree = getattr(configuration, "in_tree", None)
    if in_tree is not None:  # rules naming files only inside ROS packages (package.xml)
        configuration = in_tree([f.path for f in files])
    chosen = []
    for file in files:
        language = table.language_of(file.path)
        if language is None and configuration is not None:
            language = configuration(file.path)
        if language is not None and keep(file.path):
            chosen.append(Selected(file, language))
    return tuple(chosen)


def usable_cores() -> int:
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def worker_count(jobs: int) -> int:
    """``jobs`` workers, or one per usable core when 0; never more than two per core (more
    cannot speed up parsing, and a configured ``jobs = 100000`` must not fork that many)."""
    cores = usable_cores()
    return min(jobs, 2 * cores) if jobs > 0 else cores


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
    limits: WorkerLimits = DEFAULT_LIMITS,
    blobs: dict[str, str] | None = None,
) -> tuple[FileFacts, ...]:
    """Facts for every selected file, in the order given: from the cache when it has them,
    else from worker processes (:mod:`archmetrics.app.workers`) within ``limits``.
    ``blobs``, if given, receives each selected path's git blob id (hashed here for a file
    read from disk)."""
    progress = progress or NoProgress()
    results: list[FileFacts | None] = [None] * len(selected)
    todo: list[_Todo] = []
    max_bytes = limits.parser.max_bytes
    for index, item in enumerate(selected):
        blob, data = item.file.blob, None
        if not blob:  # a file on disk: hash it the way git would (over the limit: unread)
            size = snapshot.size(item.file) if isinstance(snapshot, Sized) else None
            if size is not None and size > max_bytes:
                results[index] = too_large(item.file.path, item.language, size, limits.parser)
                continue
            data = snapshot.read(item.file)
            blob = blob_hash(data)
        if blobs is not None:
            blobs[item.file.path] = blob
        hit = cache.get(blob, item.language, item.file.path) if cache else None
        if hit is None and cache and limits.skip_generated and cache.unread(blob, item.language):
            hit = FileFacts(path=item.file.path, language=item.language, generated=True)
        if hit is None:
            todo.append(_Todo(index, item, blob, data))
        results[index] = hit
    progress.start("parsing", len(todo))

    def deliver(entry: _Todo, answer: Parsed) -> None:
        path, language = entry.item.file.path, entry.item.language
        progress.advance()
        if blobs is not None:
            blobs[path] = entry.blob
        if answer.encoded is None:  # over a limit: reported, never cached (it may pass later)
            results[entry.index] = not_measured(path, language, answer.failure or "unknown")
            return
        if cache is not None and answer.unread:  # known generated: no facts, a mark
            cache.mark_unread(entry.blob, language)
        if cache is not None and answer.cacheable:  # stored as each file arrives, and
            # its statements and call sites read back from there when first used
            cache.put_encoded([(entry.blob, language, answer.encoded)])
            again = cache.reader(entry.blob, language)
            facts = codec.decode(answer.encoded, path, again, cache.forgetter(entry.blob, language))
            cache.remember(entry.blob, facts)
        else:
            facts = codec.decode(answer.encoded, path)
        results[entry.index] = facts

    todo = largest_first(todo, snapshot, results, limits)
    workers = worker_count(jobs)
    size = batch_size(len(todo), workers)
    batches = [todo[i : i + size] for i in range(0, len(todo), size)]
    try:
        parse_in_workers(
            batches,
            lambda batch: [_payload(snapshot, e) for e in batch],
            deliver,
            workers,
            overrides,
            limits,
        )
    finally:
        progress.stop()
    return tuple(f for f in results if f is not None)


def largest_first(
    todo: list[_Todo], snapshot: Snapshot, results: list[FileFacts | None], limits: WorkerLimits
) -> list[_Todo]:
    """The files to parse, largest first where their sizes are known (read, on disk, or a
    blob's as git's object header gives it), so that the last batches hold the smallest: a
    worker that takes a batch of large files near the end keeps the run going while the
    others wait (numpy's f2c LAPACK files, 1 MB and 0.4 s each, came last in path order:
    0.5 s of one worker alone). Files of unknown size keep their order, after the others.
    A file over the size limit is not parsed, nor read: it goes to ``results`` as not
    measured, naming the limit."""
    sized = snapshot if isinstance(snapshot, Sized) else None

    def size(entry: _Todo) -> int:
        if entry.data is not None:
            return len(entry.data)
        known = sized.size(entry.item.file) if sized is not None else None
        return -1 if known is None else known

    sizes = [size(entry) for entry in todo]
    kept = []
    for index, entry in enumerate(todo):
        if sizes[index] > limits.parser.max_bytes:
            item = entry.item
            results[entry.index] = too_large(
                item.file.path, item.language, sizes[index], limits.parser
            )
        else:
            kept.append(index)
    order = sorted(kept, key=lambda index: -sizes[index])  # stable: ties keep their order
    return [todo[index] for index in order]


def worker_limits(settings: LimitSettings, macros: MacroSettings) -> WorkerLimits:
    """The configured limits as the worker pool and the parsers take them, with the C/C++
    macros the configuration names (the parsers' one other setting)."""
    parser = ParseLimits(
        max_bytes=int(settings.file_mb * (1 << 20)),
        max_depth=settings.nesting,
        parse_seconds=settings.parse_seconds,
        c_macros=MacroNames(macros.attribute, macros.function),
    )
    return WorkerLimits(settings.file_seconds, settings.worker_memory_mb << 20, parser)


def _payload(snapshot: Snapshot, entry: _Todo) -> Task:
    data = entry.data
    if data is None:
        data = snapshot.read(entry.item.file)
        # a work tree's file whose blob git's index gave (unchanged since it was staged, as
        # git sees it) may hold other bytes (a line-ending conversion): its facts are kept
        # under the blob of the bytes parsed, as for every other file
        entry.blob = blob_hash(data)
    return entry.item.file.path, data, entry.item.language


def batch_size(files: int, workers: int) -> int:
    """:data:`BATCH` files per message, fewer when there are too few to keep every worker busy."""
    return max(1, min(BATCH, -(-files // max(1, workers))))


def not_measured(path: str, language: str, why: str) -> FileFacts:
    """The facts of a file a worker could not read within its limits: none, and why."""
    warning = ParseWarning(path, 1, f"not measured: {why}", Severity.ERROR)
    return FileFacts(path=path, language=language, parsed=False, warnings=(warning,))


def limits_salt(settings: Settings) -> str:
    """The parser limits when they differ from the defaults (facts depend on them), the
    stack the parsers may use (their depth limits shrink on a small one), and the C/C++
    macros the configuration names."""
    limits = settings.limits
    parser = (limits.file_mb, limits.nesting, limits.parse_seconds)
    defaults = LimitSettings()
    changed = parser != (defaults.file_mb, defaults.nesting, defaults.parse_seconds)
    stack = stack_bytes()
    macros = settings.macros
    listed = [repr((macros.attribute, macros.function))] if macros != MacroSettings() else []
    return " ".join(
        [
            *(map(str, parser) if changed else []),
            *([str(stack)] if stack < 8 << 20 else []),
            *listed,
        ]
    )


def open_cache(path: Path, settings: Settings) -> FactsCache:
    """The facts cache at ``path`` for facts made under ``settings`` (their parser limits
    and macros salt its fingerprint, :func:`limits_salt`)."""
    return FactsCache(path, limits_salt(settings))
