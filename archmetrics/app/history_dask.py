"""A history on a Dask cluster (``dask.distributed``): the work a commit range holds, spread
over machines that have no clone of the repository and no shared file system.

Two kinds of task, chosen for locality:

1. **file versions to parse**: the distinct versions the range adds that the facts cache
   lacks, in batches; the client reads their bytes from git and sends them, a worker parses
   them as a parser process does here (``_parse_one``: the same function) and sends back
   the encoded facts, which the client keeps in its cache;
2. **contiguous commit ranges**: a listing of the range's first parent tree, each commit's
   changes, and the facts of every file version the range reads (scattered once to the
   cluster, shared by every range that reads them); a worker walks the range as this
   process would (app/history_walk.py, with a facts cache of its own in a temporary
   folder) and sends back each commit's step.

Results equal a run on this machine: the same functions, on the same facts. A worker lost
mid-run loses its tasks, which Dask runs again elsewhere (they are pure). What the client
holds: the list of commits and their changes, each finished step, and a future per
scattered fact (the facts themselves live on the workers).
"""

from __future__ import annotations

import itertools
import logging
import tempfile
from collections.abc import Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

from archmetrics.app.collect import Selected, not_measured
from archmetrics.app.diff_options import DiffOptions
from archmetrics.app.history_walk import (
    FileVersions,
    ListedSnapshot,
    ListedTrees,
    Walk,
    kept_step,
    record_bytes,
)
from archmetrics.app.progress import Progress
from archmetrics.app.workers import Parsed, WorkerLimits, _parse_one
from archmetrics.changeset.history import CommitStep
from archmetrics.parsers import LanguageTable
from archmetrics.sources import codec
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.gitdelta import Delta
from archmetrics.sources.githistory import Commit, commit_deltas
from archmetrics.sources.snapshot import SourceFile

if TYPE_CHECKING:
    import git as gitpython
    from distributed import Client

PARSE_BATCH = 32  # file versions per parse task
SCATTER_BATCH = 500  # facts per scatter
RANGES_PER_WORKER = 4  # commit ranges per worker: enough to even out their lengths


class ClusterError(RuntimeError):
    """The cluster cannot run this history; the message says why."""


def _dask() -> Any:
    try:
        import distributed
    except ImportError as error:
        raise ClusterError(
            "--scheduler and --workers need Dask: pip install 'archmetrics[dask]'"
        ) from error
    return distributed


@contextmanager
def cluster(scheduler: str | None, workers: int | None) -> Iterator[Client]:
    """A client of the cluster at ``scheduler``, or of a local cluster of ``workers``
    processes (one thread each: parsing is CPU-bound Python)."""
    distributed = _dask()
    if scheduler is not None:
        try:
            client = distributed.Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as error:
            raise ClusterError(f"{scheduler}: no Dask scheduler answers: {error}") from error
        with client:
            yield client
        return
    count = workers or 1
    with (
        distributed.LocalCluster(
            n_workers=count, threads_per_worker=1, processes=True, dashboard_address=None,
            silence_logs=logging.CRITICAL,  # its shutdown's heartbeats are not the user's news
        ) as local,
        distributed.Client(local) as client,
    ):
        yield client


# ------------------------------------------------------------------------- on a worker


def parse_versions(
    tasks: list[tuple[str, bytes, str]], overrides: tuple[tuple[str, str], ...],
    limits: WorkerLimits,
) -> list[Parsed]:  # fmt: skip
    """A batch of (path, content, language) parsed as a parser process parses it."""
    table = LanguageTable.default(dict(overrides))
    return [_parse_one(path, data, language, table, limits) for path, data, language in tasks]


@dataclass(frozen=True, slots=True)
class RangeTask:
    """A contiguous range of first-parent commits, and what a worker needs to walk it."""

    options: DiffOptions
    salt: str  # the facts cache's salt (the parser limits in force)
    fingerprint: str  # the client's facts fingerprint: the worker's must be the same
    base: tuple[tuple[str, str], ...]  # path -> blob of the first commit's parent's tree
    commits: tuple[Commit, ...]
    deltas: tuple[Delta, ...]
    unread: tuple[tuple[str, str], ...]  # (blob, language) read no further: generated


def walk_range(task: RangeTask, facts: list[tuple[str, str, bytes]]) -> list[tuple[str, bytes]]:
    """Each commit of ``task`` measured, as (commit id, step record)."""
    with (
        tempfile.TemporaryDirectory(prefix="archmetrics-history-") as folder,
        FactsCache(Path(folder) / "facts.sqlite3", task.salt) as cache,
    ):
        if cache.fingerprint != task.fingerprint:
            raise ClusterError(
                "this worker's archmetrics makes other facts than the client's (another "
                "version, Python or parser library): install the same versions on both"
            )
        cache.put_encoded(facts)
        for blob, language in task.unread:
            cache.mark_unread(blob, language)
        first = task.commits[0]
        base = ListedSnapshot(dict(task.base), first.parent or "", first.parent_tree)
        walk = Walk(ListedTrees(base, cache), task.options, cache)
        steps = walk.steps(zip(task.commits, task.deltas, strict=True), {})
    return [(commit, record_bytes(step)) for commit, step in steps.items()]


# ------------------------------------------------------------------------- on the client


def contiguous(commits: Sequence[Commit], size: int) -> list[list[int]]:
    """Indexes of ``commits`` cut into ranges of at most ``size`` in which each commit's
    first parent is the commit before it."""
    ranges: list[list[int]] = []
    for index, commit in enumerate(commits):
        previous = commits[index - 1].id if index else None
        if not ranges or commit.parent != previous or len(ranges[-1]) >= size:
            ranges.append([])
        ranges[-1].append(index)
    return ranges


class ClusterWalk:
    """A history's missing commits walked on a Dask cluster, from this client."""

    def __init__(
        self,
        client: Client,
        repo: gitpython.Repo,
        options: DiffOptions,
        cache: FactsCache,
        salt: str,
        progress: Progress,
    ) -> None:
        self.client = client
        self.repo = repo
        self.options = options
        self.cache = cache
        self.salt = salt
        self.progress = progress
        self.versions = FileVersions(options, cache)
        self.scattered: dict[tuple[str, str], Any] = {}
        self.failed: dict[tuple[str, str], str] = {}  # versions no worker could parse, why
        self.uncached: dict[tuple[str, str], bytes] = {}  # facts whose parse was cut short
        self.workers = max(1, len(client.scheduler_info().get("workers", {})))

    def run(
        self, commits: Sequence[Commit], keys: dict[str, str]
    ) -> tuple[dict[str, CommitStep], int]:
        """The steps of ``commits`` (each kept in the cache as it comes), and how many file
        versions were parsed."""
        deltas = list(commit_deltas(self.repo, commits))
        size = max(1, -(-len(commits) // (self.workers * RANGES_PER_WORKER)))
        ranges = contiguous(commits, size)
        bases = [self._listing(commits[indexes[0]]) for indexes in ranges]
        # every version the ranges read: their first trees' and what their commits add
        firsts = Delta(tuple(f for base in bases for f in base), frozenset(), {}, {})
        todo = self.versions.wanted([firsts, *deltas])
        self._parse(todo)
        futures = {}
        for indexes, base in zip(ranges, bases, strict=True):
            task = self._task(base, [commits[i] for i in indexes], [deltas[i] for i in indexes])
            facts = [self.scattered[k] for k in self._needed(task)]
            futures[self.client.submit(walk_range, task, facts, pure=False)] = len(indexes)
        found: dict[str, CommitStep] = {}
        self.progress.start("measuring commits", len(commits))
        for future in _dask().as_completed(futures):
            records: list[tuple[str, bytes]] = future.result()
            self.cache.put_totals([(keys[commit], data) for commit, data in records])
            for commit, data in records:
                step = kept_step(data)
                if step is None:
                    raise ClusterError(f"{commit}: a worker sent a step this cannot read")
                found[commit] = step
            self.progress.advance(futures[future])
        self.progress.stop()
        return found, len(todo)

    def _listing(self, first: Commit) -> tuple[SourceFile, ...]:
        """The files of ``first``'s parent's tree (none for a root commit)."""
        from archmetrics.sources.git import RevisionSnapshot

        if first.parent is None:
            return ()
        return RevisionSnapshot(self.repo, first.parent, first.parent, first.parent_tree).files()

    def _task(
        self, base: Sequence[SourceFile], commits: list[Commit], deltas: list[Delta]
    ) -> RangeTask:
        listing = tuple((f.path, f.blob) for f in base)
        task = RangeTask(self.options, self.salt, self.cache.fingerprint, listing,
                         tuple(commits), tuple(deltas), ())  # fmt: skip
        needed = self._needed(task)
        unread = tuple(k for k in needed if self.cache.marked_unread(*k))
        self._scatter([k for k in needed if k not in unread and k not in self.scattered])
        return RangeTask(task.options, task.salt, task.fingerprint, task.base, task.commits,
                         task.deltas, unread)  # fmt: skip

    def _needed(self, task: RangeTask) -> list[tuple[str, str]]:
        """The (blob, language) of every file the range reads: its first tree's and every
        version its commits add, that have a language (not those read no further)."""
        files = [*task.base, *((f.path, f.blob) for d in task.deltas for f in d.changed)]
        needed: dict[tuple[str, str], None] = {}
        for path, blob in files:
            language = self.versions.language(path)
            if language is not None and blob:
                needed[(blob, language)] = None
        unread = set(task.unread)
        return [k for k in needed if k not in unread]

    def _scatter(self, keys: list[tuple[str, str]]) -> None:
        """Each fact ``keys`` names sent to the cluster once, in batches."""
        for start in range(0, len(keys), SCATTER_BATCH):
            chunk = keys[start : start + SCATTER_BATCH]
            records = self.cache.get_encoded(chunk)
            items = []
            for key in chunk:
                data = records.get(key) or self.uncached.get(key)
                if data is None:  # not measured within the limits: the walk reports why
                    why = self.failed.get(key, "its facts were lost from the cache")
                    data = codec.encode(not_measured(key[0], key[1], why))
                items.append((*key, data))
            futures = self.client.scatter(items)  # type: ignore[no-untyped-call]
            self.scattered.update(zip(chunk, futures, strict=True))

    def _parse(self, todo: list[Selected]) -> None:
        """``todo`` parsed on the cluster, a few batches in flight per worker (the client
        holds only their bytes), each answer kept in the cache as it comes."""
        if not todo:
            return
        from archmetrics.sources.git import Blobs

        blobs, client, options = Blobs(self.repo), self.client, self.options
        batches = [todo[i : i + PARSE_BATCH] for i in range(0, len(todo), PARSE_BATCH)]
        self.progress.start("parsing", len(todo))

        def submit(batch: list[Selected]) -> Any:
            tasks = [(s.file.path, blobs.read(s.file), s.language) for s in batch]
            return client.submit(parse_versions, tasks, options.languages, options.limits,
                                 pure=False)  # fmt: skip

        waiting = iter(batches)
        futures = {submit(b): b for b in itertools.islice(waiting, 2 * self.workers + 1)}
        running = _dask().as_completed(list(futures))
        for future in running:
            self._keep(futures.pop(future), future.result())
            following = next(waiting, None)
            if following is not None:
                added = submit(following)
                futures[added] = following
                running.add(added)
        self.progress.stop()

    def _keep(self, batch: list[Selected], answers: list[Parsed]) -> None:
        cache = self.cache
        for selected, answer in zip(batch, answers, strict=True):
            key = (selected.file.blob, selected.language)
            if answer.encoded is None:
                self.failed[key] = answer.failure or "unknown"
            elif answer.unread:
                cache.mark_unread(*key)
            elif answer.cacheable:
                cache.put_encoded([(*key, answer.encoded)])
            else:  # cut off by the clock: used in this run, never kept (as parse_all does)
                self.uncached[key] = answer.encoded
            self.progress.advance()
