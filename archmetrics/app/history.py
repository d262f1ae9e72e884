"""The ``history`` use case: every commit of a range measured against its first parent, with
what ``diff --base C^ --head C`` gives for each, at a cost that follows what changed.

The range is listed and every commit's changes asked of git in a few processes for the
whole range (sources/githistory.py). Each commit's step is kept in the facts cache under a
digest of what decides it (archmetrics's code, the parser settings, the options, the two
trees), so a second run, or a run interrupted and started again, measures only the commits
it has no step for. Those are measured in order: every file version they add is parsed
first, once (in workers; the facts cache is content-addressed), then each commit's side is
patched from its parent's, held in memory, as a diff patches a base state it read
(app/tree.py), and compared with it as a diff compares them (app/diff.py).
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from archmetrics.app.collect import limits_salt, parse_all
from archmetrics.app.coupling import packs_digest
from archmetrics.app.diff_options import DiffOptions, DiffRequest, diff_options
from archmetrics.app.history_walk import FileVersions, Walk, kept_step
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.tree import STATE_RECORD, Side, side_of, whole_side
from archmetrics.changeset.gates import check_gates
from archmetrics.changeset.history import STEP_RECORD, CommitStep
from archmetrics.reports.model import HistoryEntry, HistoryReport
from archmetrics.sources.cache import FactsCache, code_fingerprint
from archmetrics.sources.checkout import Checkout, open_checkout
from archmetrics.sources.git import Blobs, RevisionSnapshot
from archmetrics.sources.gitdelta import Delta
from archmetrics.sources.githistory import Commit, Range, commit_deltas, list_commits
from archmetrics.sources.snapshot import EmptySnapshot, Snapshot, SourceError

if TYPE_CHECKING:
    import git as gitpython

DEFAULT_RANGE = Range()
WINDOW = 400  # commits whose new file versions are parsed together, before they are walked
DECODED_IN_HISTORY = 3000  # decoded facts a history keeps in memory (a diff keeps 50,000)


@dataclass(frozen=True, slots=True)
class HistoryRequest:
    """``diff`` carries the repository, settings, locations, gates and jobs (its base and
    head are not read); ``range`` says which commits."""

    diff: DiffRequest
    range: Range = DEFAULT_RANGE
    scheduler: str | None = None  # a Dask scheduler's address: the walk runs on its cluster
    workers: int | None = None  # else this many local Dask workers (None: no Dask)


def step_keys(
    options: DiffOptions, cache: FactsCache, commits: Sequence[Commit]
) -> list[str]:
    """Per commit, a digest of all that decides its step: archmetrics's code, the facts'
    parser fingerprint, the options a tree's state depends on (made once), and the two
    trees compared."""
    document = [
        STEP_RECORD, STATE_RECORD, code_fingerprint(), cache.fingerprint, options.languages,
        repr(options.rules), options.limits.skip_generated, repr(options.coupling),
        packs_digest(options.packs), options.dynamic_pre_zero,
    ]  # fmt: skip
    settings = hashlib.sha256(json.dumps(document).encode()).hexdigest()
    pairs = (f"{settings} {c.parent_tree} {c.tree}".encode() for c in commits)
    return [f"{STEP_RECORD}:{hashlib.sha256(pair).hexdigest()}" for pair in pairs]




def run_history(
    request: HistoryRequest,
    progress: Progress | None = None,
    cache: FactsCache | None = None,
    checkout: Checkout | None = None,
    options: DiffOptions | None = None,
) -> HistoryReport:
    """Every commit of the range, oldest first, and the gates checked on each."""
    progress = progress or NoProgress()
    checkout = checkout or open_checkout(request.diff.root)
    options = options or diff_options(request.diff, checkout.root)
    if options.unit_gates:
        texts = ", ".join(repr(t.text) for t in options.unit_gates)
        raise SourceError(
            f"history checks gates on each commit's locations and total (cost(new) > 20),"
            f" not on functions or files: {texts} is for diff and scan"
        )
    if checkout.repo is None:
        raise SourceError(f"{checkout.root}: history needs a git repository")
    progress.phase(f"listing the commits of {request.range.spec}")
    commits = list_commits(checkout.repo, request.range)
    keys = step_keys(options, cache, commits) if cache is not None else []
    steps: dict[str, CommitStep] = {}
    if cache is not None:
        kept = cache.get_totals(keys)
        for commit, key in zip(commits, keys, strict=True):
            step = kept_step(kept[key]) if key in kept else None
            if step is not None:
                steps[commit.id] = step
    missing = [c for c in commits if c.id not in steps]
    parsed = 0
    if missing:
        by_id = dict(zip((c.id for c in commits), keys, strict=False))
        if request.scheduler is not None or request.workers is not None:
            measured, parsed = _walk_on_cluster(request, checkout, missing, by_id, options,
                                                cache, progress)  # fmt: skip
        else:
            measured, parsed = walk_here(checkout.repo, missing, by_id, options, cache, progress)
        steps.update(measured)
    entries = tuple(
        HistoryEntry(c.id, c.parent, c.time, c.subject, c.merge, steps[c.id],
                     check_gates(options.gates, steps[c.id].summaries))
        for c in commits
    )  # fmt: skip
    gates = tuple(g.text for g in options.gates)
    return HistoryReport(
        str(checkout.root), request.range.spec, entries, gates, len(missing), parsed
    )


class RepositoryTrees:
    """The trees of a history read from its repository: each commit a revision; a parent's
    side its kept state, or its tree read whole."""

    def __init__(self, repo: gitpython.Repo, cache: FactsCache | None) -> None:
        self.repo = repo
        self.cache = cache

    def snapshot(self, commit: Commit, delta: Delta) -> Snapshot:
        return RevisionSnapshot(self.repo, commit.id, commit.id, commit.tree)

    def parent_side(self, commit: Commit, options: DiffOptions) -> Side:
        if commit.parent is None:
            return whole_side(EmptySnapshot(), options, self.cache, NoProgress())
        parent = RevisionSnapshot(self.repo, commit.parent, commit.parent, commit.parent_tree)
        return side_of(parent, options, self.cache, NoProgress())


def _walk_on_cluster(
    request: HistoryRequest,
    checkout: Checkout,
    commits: Sequence[Commit],
    keys: dict[str, str],
    options: DiffOptions,
    cache: FactsCache | None,
    progress: Progress,
) -> tuple[dict[str, CommitStep], int]:
    from archmetrics.app.history_dask import ClusterWalk, cluster

    assert checkout.repo is not None
    if cache is None:
        raise SourceError("a history on a Dask cluster keeps its facts in a cache: leave it on")
    progress.phase("connecting to the Dask cluster")
    with cluster(request.scheduler, request.workers) as client:
        salt = limits_salt(request.diff.settings)
        walk = ClusterWalk(client, checkout.repo, options, cache, salt, progress)
        return walk.run(commits, keys)


def walk_here(
    repo: gitpython.Repo,
    commits: Sequence[Commit],
    keys: dict[str, str],
    options: DiffOptions,
    cache: FactsCache | None,
    progress: Progress,
) -> tuple[dict[str, CommitStep], int]:
    """``commits`` measured in this process (its parser workers parse what they add), in
    windows of :data:`WINDOW`; the steps, and how many file versions were parsed."""
    versions = FileVersions(options, cache)
    misses = cache.misses if cache is not None else 0
    if cache is not None:  # a commit reads its changed files and what reaches them, no more
        cache.decoded_limit = min(cache.decoded_limit, DECODED_IN_HISTORY)
    keep = cache.put_totals if cache is not None else None
    walk = Walk(RepositoryTrees(repo, cache), options, cache, keep, progress)
    deltas = commit_deltas(repo, commits)
    found: dict[str, CommitStep] = {}
    try:
        for start in range(0, len(commits), WINDOW):
            window = commits[start : start + WINDOW]
            changes = [next(deltas) for _ in window]
            todo = versions.wanted(changes)
            if todo:
                parse_all(Blobs(repo), todo, options.languages, options.jobs, progress, cache,
                          options.limits)  # fmt: skip
            progress.start("measuring commits", len(commits))
            progress.advance(start)
            found.update(walk.steps(zip(window, changes, strict=True), keys))
        walk.keep_state()
    finally:
        progress.stop()
    # every version parsed: those the commits add, and a first tree read whole (each was a
    # look-up the cache missed)
    return found, (cache.misses - misses if cache is not None else 0)
