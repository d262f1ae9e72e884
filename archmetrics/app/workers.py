"""Parser processes that cannot take the run down with them.

Every file is parsed in a worker process (docs/security.md, "Bounded work per file"):

- a worker's address space is capped (``limits.worker-memory``): a file that needs more is a
  ``MemoryError`` in the worker, reported for that file, or, if the parser's native code
  cannot cope, the worker's death;
- a file that takes longer than ``limits.file-seconds`` of wall-clock time gets its worker
  killed;
- a worker that dies (a crash in native code, the kernel's OOM killer, the time limit) is
  replaced; the file it was reading is reported as not measured, with the reason, and the
  rest of its batch goes to the next worker;
- a worker exits when archmetrics does (``PR_SET_PDEATHSIG`` on Linux, else a watch on the
  parent's pid), so a cancelled CI job leaves no parser behind.

A worker tells the parent which file it is reading, and since when, through two shared
numbers, so none of this costs a message per file.
"""

from __future__ import annotations

import ctypes
import gc
import multiprocessing
import multiprocessing.connection
import multiprocessing.context
import os
import signal
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager, suppress
from dataclasses import dataclass
from typing import Any, Generic, TypeVar

from archmetrics.facts import FileFacts
from archmetrics.parsers import DEFAULT_LIMITS, LanguageTable, ParseLimits, parse_source
from archmetrics.parsers.text import declares_generated_bytes
from archmetrics.sources import codec

T = TypeVar("T")
Task = tuple[str, bytes, str]
"""What a worker parses: (path, content, language)."""


@dataclass(frozen=True, slots=True)
class WorkerLimits:
    """What one file may cost a worker (configured under ``[tool.archmetrics.limits]``)."""

    file_seconds: float = 120.0  # wall-clock time to parse one file
    worker_memory: int = 4 << 30  # bytes of address space per worker process
    parser: ParseLimits = DEFAULT_LIMITS  # what the parsers themselves refuse (size, depth)
    # a file whose first lines say it is generated is not read further (the diff excludes
    # such files: a Cython module of 8.7 MB cost 38 s and 680 MB); those facts say only
    # ``generated`` and are never cached (a scan reads the file whole)
    skip_generated: bool = False


@dataclass(frozen=True, slots=True)
class Parsed:
    """A worker's answer for one file: the facts in the cache's encoding, or why there are
    none (the file is then reported as not measured)."""

    encoded: bytes | None
    failure: str | None = None
    cacheable: bool = True  # False: the outcome depended on the clock (a parse cut off)
    unread: bool = False  # True: generated, read no further (``WorkerLimits.skip_generated``)


Deliver = Callable[[T, Parsed], None]


# ----------------------------------------------------------------------------------- worker


def die_with_parent() -> None:
    """Have the kernel kill this process when its parent exits (Linux), else watch for it.

    A worker's parent is archmetrics or the fork server, which does the same
    (:mod:`archmetrics.app.forkserver_guard`), so a worker goes when archmetrics goes,
    however it went."""
    parent = os.getppid()
    if sys.platform.startswith("linux"):
        with suppress(OSError, AttributeError):
            libc = ctypes.CDLL(None, use_errno=True)
            if libc.prctl(1, signal.SIGKILL, 0, 0, 0) == 0:  # PR_SET_PDEATHSIG
                if os.getppid() != parent:  # the parent died before the call
                    os._exit(1)
                return

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(1.0)
        os._exit(1)

    threading.Thread(target=watch, daemon=True).start()


def _cap_memory(limit: int) -> None:
    """Allow ``limit`` bytes of address space beyond what the worker holds as it starts (a
    forked worker starts with its parent's)."""
    try:
        import resource
    except ImportError:  # not on POSIX: the time limit still holds
        return
    try:
        with open("/proc/self/statm") as statm:
            held = int(statm.read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError):
        held = 0
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    cap = held + limit if hard == resource.RLIM_INFINITY else min(held + limit, hard)
    with suppress(ValueError, OSError):
        resource.setrlimit(resource.RLIMIT_AS, (cap, hard))


def _worker_main(
    conn: multiprocessing.connection.Connection,
    overrides: tuple[tuple[str, str], ...],
    limits: WorkerLimits,
    status: Any,
) -> None:
    """Parse batches until the parent closes the pipe. ``status`` is ``[index, since]``: the
    file of the current batch being read and when it started (0 when idle).

    A worker builds and drops one file's tree after another, and almost nothing it builds is
    cyclic: the collector is off, what the worker holds from its start is frozen out of its
    reach, and the few cycles a batch leaves are collected at its end (docs/performance.md)."""
    die_with_parent()
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the parent's to handle
    _cap_memory(limits.worker_memory)
    table = LanguageTable.default(dict(overrides))
    gc.disable()
    gc.freeze()
    while True:
        try:
            batch: list[Task] | None = conn.recv()
        except (EOFError, OSError):
            return
        if batch is None:
            return
        answers = []
        for index, (path, data, language) in enumerate(batch):
            status[0], status[1] = index, time.monotonic()
            answers.append(_parse_one(path, data, language, table, limits))
        status[1] = 0.0
        del batch
        gc.collect()  # only what this batch made: the rest is frozen
        conn.send(answers)


def _parse_one(
    path: str, data: bytes, language: str, table: LanguageTable, limits: WorkerLimits
) -> Parsed:
    started = time.monotonic()
    if limits.skip_generated and declares_generated_bytes(data):
        unread = FileFacts(path=path, language=language, generated=True)
        return Parsed(codec.encode(unread), cacheable=False, unread=True)
    try:
        facts = parse_source(path, data, language, table, limits.parser)
        timed_out = not facts.parsed and time.monotonic() - started >= limits.parser.parse_seconds
        return Parsed(codec.encode(facts), cacheable=not timed_out)
    except MemoryError:
        gc.collect()
        return Parsed(None, f"needed more than {limits.worker_memory >> 20} MiB of memory")
    except RecursionError:
        return Parsed(None, "nested too deeply to measure")
    except Exception as error:  # a parser's bug must cost one file, not the run
        return Parsed(None, f"the parser failed: {type(error).__name__}: {error}")


# ----------------------------------------------------------------------------------- parent


class _Worker(Generic[T]):
    """A worker process, its pipe, its status and the batch it holds."""

    def __init__(
        self,
        context: Any,
        overrides: tuple[tuple[str, str], ...],
        limits: WorkerLimits,
    ):
        self.status: Any = context.Array("d", 2, lock=False)
        self.conn, child = context.Pipe()
        self.process = context.Process(
            target=_worker_main,
            args=(child, overrides, limits, self.status),
            daemon=True,
        )
        self.process.start()
        child.close()
        self.batch: list[T] = []

    def give(self, batch: list[T], tasks: list[Task]) -> None:
        self.status[0], self.status[1] = -1.0, 0.0
        self.batch = batch
        self.conn.send(tasks)

    def reading(self) -> int | None:
        """The index in its batch of the file it is parsing now, if it is parsing one."""
        return int(self.status[0]) if self.status[1] > 0 else None

    def overdue(self, now: float, seconds: float) -> bool:
        since: float = self.status[1]
        return bool(self.batch) and since > 0 and now - since > seconds

    def stop(self) -> None:
        with suppress(OSError):
            self.conn.close()
        if self.process.is_alive():
            self.process.kill()
        self.process.join(timeout=5)


FORK_BELOW = 48
"""Runs with fewer files fork their workers from this process: a fork server costs a new
interpreter (about 0.3 s), which a pre-commit diff of one file should not pay."""


def _context(files: int) -> Any:
    """Forked workers for a few files; for many, workers from a fork server, which start
    small (forked from here instead, each worker of a diff's second revision would inherit,
    and as its allocator touches the pages copy, all the facts of the first)."""
    methods = multiprocessing.get_all_start_methods()
    if files < FORK_BELOW and "fork" in methods:
        return multiprocessing.get_context("fork")
    if "forkserver" not in methods:
        return multiprocessing.get_context()
    context = multiprocessing.get_context("forkserver")
    # the fork server imports the parsers once; every worker starts with them loaded
    context.set_forkserver_preload(
        [
            "archmetrics.app.forkserver_guard",
            "archmetrics.parsers.python",
            "archmetrics.parsers.c_family",
        ]
    )
    return context


@dataclass(slots=True)
class _Run(Generic[T]):
    pending: deque[list[T]]
    make_tasks: Callable[[list[T]], list[Task]]
    deliver: Deliver[T]
    limits: WorkerLimits
    dead_at_start: int = 0


def parse_in_workers(
    batches: Sequence[list[T]],
    make_tasks: Callable[[list[T]], list[Task]],
    deliver: Deliver[T],
    workers: int,
    overrides: tuple[tuple[str, str], ...] = (),
    limits: WorkerLimits = WorkerLimits(),
) -> None:
    """Parse every batch in ``workers`` processes; ``deliver`` gets each item and its
    :class:`Parsed` answer, in no particular order. ``make_tasks`` reads a batch's files
    only when a worker is free to take them, so memory stays bounded."""
    if not batches:
        return
    run = _Run(deque(batches), make_tasks, deliver, limits)
    context = _context(sum(len(batch) for batch in batches))
    with _crew(context, min(workers, len(batches)), overrides, limits) as crew:
        while run.pending or any(w.batch for w in crew):
            for worker in crew:
                if not worker.batch and run.pending:
                    _give_next(worker, run)
            for index, worker in enumerate(crew):
                if _watch(worker, run) is False:
                    worker.stop()
                    crew[index] = _Worker(context, overrides, limits)
            if not (run.pending and any(not worker.batch for worker in crew)):
                _wait(crew, limits)  # a worker that just answered gets its next batch first


@contextmanager
def _crew(
    context: Any,
    count: int,
    overrides: tuple[tuple[str, str], ...],
    limits: WorkerLimits,
) -> Iterator[list[_Worker[Any]]]:
    crew: list[_Worker[Any]] = []
    try:
        crew.extend(_Worker(context, overrides, limits) for _ in range(max(1, count)))
        yield crew
    finally:
        for worker in crew:
            worker.stop()


def _wait(crew: list[_Worker[Any]], limits: WorkerLimits) -> None:
    """Until a busy worker answers or dies, or it is time to look at the clocks again."""
    busy = [w for w in crew if w.batch]
    if not busy:
        return
    handles: list[Any] = [w.conn for w in busy] + [w.process.sentinel for w in busy]
    multiprocessing.connection.wait(handles, timeout=min(1.0, max(0.05, limits.file_seconds / 4)))


def _give_next(worker: _Worker[T], run: _Run[T]) -> None:
    batch = run.pending.popleft()
    worker.give(batch, run.make_tasks(batch))


def _watch(worker: _Worker[T], run: _Run[T]) -> bool | None:
    """Take what ``worker`` has for us. False: it is dead (or was killed) and must be replaced."""
    if not worker.batch:
        return True
    if worker.conn.poll():
        try:
            answers: list[Parsed] = worker.conn.recv()
        except (EOFError, OSError):
            return _lost(worker, run, _death(worker))
        batch, worker.batch = worker.batch, []
        if run.pending:  # its next batch first: it parses while these answers are delivered
            _give_next(worker, run)
        for item, answer in zip(batch, answers, strict=True):
            run.deliver(item, answer)
        return True
    if not worker.process.is_alive():
        return _lost(worker, run, _death(worker))
    if worker.overdue(time.monotonic(), run.limits.file_seconds):
        return _lost(worker, run, f"took longer than {run.limits.file_seconds:g} s to parse")
    return None


def _death(worker: _Worker[Any]) -> str:
    worker.process.join(timeout=1)
    code = worker.process.exitcode
    if code is not None and code < 0:
        with suppress(ValueError):
            return f"the parser process died ({signal.Signals(-code).name}) reading it"
    return f"the parser process died (exit {code}) reading it"


def _lost(worker: _Worker[T], run: _Run[T], why: str) -> bool:
    """``worker`` is gone: its current file is not measured, the rest of its batch is
    queued again."""
    batch, index = worker.batch, worker.reading()
    worker.batch = []
    if index is None:  # died before it began: try the batch again, but not forever
        run.dead_at_start += 1
        if run.dead_at_start > 3:
            raise RuntimeError(f"parser processes keep dying before they start ({why})")
        run.pending.appendleft(batch)
        return False
    run.deliver(batch[index], Parsed(None, why))
    rest = batch[:index] + batch[index + 1 :]
    if rest:
        run.pending.appendleft(rest)
    return False
