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

from archmetrics.app.collect import Selected, parse_all
from archmetrics.app.coupling import configuration_files, packs_digest
from archmetrics.app.diff import DiffOptions, DiffRequest, compare_sides, diff_options
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.tree import STATE_RECORD, Side, patched_side, side_of, whole_side
from archmetrics.changeset.gates import check_gates
from archmetrics.changeset.history import (
    STEP_RECORD,
    CommitStep,
    commit_step,
    step_from_record,
    step_record,
)
from archmetrics.parsers import LanguageTable
from archmetrics.reports.model import HistoryEntry, HistoryReport
from archmetrics.sources.cache import FactsCache, code_fingerprint
from archmetrics.sources.checkout import Checkout, open_checkout
from archmetrics.sources.git import Blobs, RevisionSnapshot
from archmetrics.sources.gitdelta import Delta, Pending
from archmetrics.sources.githistory import Commit, Range, commit_deltas, list_commits
from archmetrics.sources.snapshot import EmptySnapshot, SourceError, SourceFile

DEFAULT_RANGE = Range()
KEEP_EVERY = 200  # steps written to the cache at least this often: an interrupted run resumes
WINDOW = 400  # commits whose new file versions are parsed together, before they are walked


@dataclass(frozen=True, slots=True)
class HistoryRequest:
    """``diff`` carries the repository, settings, locations, gates and jobs (its base and
    head are not read); ``range`` says which commits."""

    diff: DiffRequest
    range: Range = DEFAULT_RANGE


def step_key(options: DiffOptions, cache: FactsCache, commit: Commit) -> str:
    """A digest of all that decides one commit's step: archmetrics's code, the facts' parser
    fingerprint, the options a tree's state depends on, and the two trees compared."""
    document = [
        STEP_RECORD, STATE_RECORD, code_fingerprint(), cache.fingerprint, options.languages,
        repr(options.rules), options.limits.skip_generated, repr(options.coupling),
        packs_digest(options.packs), options.dynamic_pre_zero, commit.parent_tree, commit.tree,
    ]  # fmt: skip
    return f"{STEP_RECORD}:{hashlib.sha256(json.dumps(document).encode()).hexdigest()}"


def _kept(data: bytes) -> CommitStep | None:
    try:
        return step_from_record(json.loads(data))
    except ValueError:
        return None


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
    if checkout.repo is None:
        raise SourceError(f"{checkout.root}: history needs a git repository")
    progress.phase(f"listing the commits of {request.range.spec}")
    commits = list_commits(checkout.repo, request.range)
    keys = [step_key(options, cache, c) for c in commits] if cache is not None else []
    steps: dict[str, CommitStep] = {}
    if cache is not None:
        kept = cache.get_totals(keys)
        for commit, key in zip(commits, keys, strict=True):
            found = _kept(kept[key]) if key in kept else None
            if found is not None:
                steps[commit.id] = found
    missing = [c for c in commits if c.id not in steps]
    walker = _Walker(checkout, options, cache, progress)
    if missing:
        by_id = dict(zip((c.id for c in commits), keys, strict=False))
        steps.update(walker.walk(missing, by_id))
    entries = tuple(
        HistoryEntry(c.id, c.parent, c.time, c.subject, c.merge, steps[c.id],
                     check_gates(options.gates, steps[c.id].summaries))
        for c in commits
    )  # fmt: skip
    gates = tuple(g.text for g in options.gates)
    return HistoryReport(
        str(checkout.root), request.range.spec, entries, gates, len(missing), walker.parsed
    )


class _Walker:
    """The commits of a history that have no kept step, measured in order."""

    def __init__(
        self,
        checkout: Checkout,
        options: DiffOptions,
        cache: FactsCache | None,
        progress: Progress,
    ) -> None:
        assert checkout.repo is not None
        self.repo = checkout.repo
        self.options = options
        self.cache = cache
        self.progress = progress
        self.parsed = 0
        self.table = LanguageTable.default(dict(options.languages))
        self.configuration = configuration_files(options.packs)

    def walk(self, commits: Sequence[Commit], keys: dict[str, str]) -> dict[str, CommitStep]:
        """Each of ``commits`` measured, in order; every step is kept in the cache as it is
        found (in batches, and whatever ends the walk early), so none is measured twice."""
        found: dict[str, CommitStep] = {}
        self.pending: list[tuple[str, bytes]] = []
        try:
            self._walk(commits, keys, found)
        finally:
            self._keep()
            self.progress.stop()
        return found

    def _keep(self) -> None:
        if self.cache is not None and self.pending:
            self.cache.put_totals(self.pending)
        self.pending = []

    def _walk(
        self, commits: Sequence[Commit], keys: dict[str, str], found: dict[str, CommitStep]
    ) -> None:
        pre: Side | None = None
        deltas = commit_deltas(self.repo, commits)
        for start in range(0, len(commits), WINDOW):
            window = commits[start : start + WINDOW]
            changes = [next(deltas) for _ in window]
            self._parse(changes)
            self.progress.start("measuring commits", len(commits))
            self.progress.advance(start)
            for commit, delta in zip(window, changes, strict=True):
                if pre is None or getattr(pre.snapshot, "commit", None) != commit.parent:
                    pre = self._side_of_parent(commit)
                post = self._patched(commit, pre, delta)
                renames = post.renames if post.renames is not None else delta.renames
                change = compare_sides(pre, post, renames, self.options, NoProgress(), self.cache)
                step = found[commit.id] = commit_step(change)
                if self.cache is not None:
                    self.pending.append((keys[commit.id], _compact(step_record(step))))
                    if len(self.pending) >= KEEP_EVERY:
                        self._keep()
                pre = post
                self.progress.advance()

    def _side_of_parent(self, commit: Commit) -> Side:
        """The side of ``commit``'s parent: its kept state, or built whole."""
        if commit.parent is None:
            snapshot = EmptySnapshot()
            return whole_side(snapshot, self.options, self.cache, NoProgress())
        parent = RevisionSnapshot(self.repo, commit.parent, commit.parent, commit.parent_tree)
        self.progress.phase(f"reading {commit.parent[:12]}")
        return side_of(parent, self.options, self.cache, NoProgress())

    def _patched(self, commit: Commit, pre: Side, delta: Delta) -> Side:
        snapshot = RevisionSnapshot(self.repo, commit.id, commit.id, commit.tree)
        pending = Pending(lambda: delta, [])
        side = patched_side(snapshot, pre, self.options, self.cache, NoProgress(), pending)
        return side or whole_side(snapshot, self.options, self.cache, NoProgress())

    def _parse(self, changes: Sequence[Delta]) -> None:
        """Every file version ``changes`` add that has a language, parsed once (or found in
        the cache), so that walking them reads facts only."""
        wanted: dict[tuple[str, str], Selected] = {}
        for delta in changes:
            for file in delta.changed:
                language = self._language(file.path)
                if language is not None and file.blob:
                    key = (file.blob, language)
                    if key not in wanted:
                        wanted[key] = Selected(SourceFile(file.path, file.blob), language)
        todo = [s for s in wanted.values() if not self._known(s)]
        if not todo:
            return
        self.parsed += len(todo)
        options = self.options
        parse_all(
            Blobs(self.repo), todo, options.languages, options.jobs, self.progress,
            self.cache, options.limits,
        )  # fmt: skip

    def _known(self, selected: Selected) -> bool:
        cache = self.cache
        if cache is None:
            return False
        blob = selected.file.blob
        return cache.has(blob, selected.language) or cache.unread(blob, selected.language)

    def _language(self, path: str) -> str | None:
        return self.table.language_of(path) or self.configuration(path)


def _compact(value: object) -> bytes:
    return json.dumps(value, separators=(",", ":")).encode()
