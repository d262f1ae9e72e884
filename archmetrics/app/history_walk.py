"""Walking a history: commits measured in order, each side patched from its parent's in
memory (app/tree.py) and compared with it (app/diff.py), each step kept as it is found.

The walk is the same in this process and on a Dask worker; what differs is where the trees
come from (:class:`Trees`): here, the repository (each commit a revision; a parent's side
its kept state or its tree read whole); on a worker, a listing of the range's first tree
patched with each commit's changes, every fact it needs shipped with the task.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterable, Sequence
from typing import Protocol

from archmetrics.app.collect import Selected
from archmetrics.app.coupling import configuration_files
from archmetrics.app.diff import compare_sides
from archmetrics.app.diff_options import DiffOptions
from archmetrics.app.progress import NoProgress, Progress
from archmetrics.app.tree import Side, patched_side, state_key, whole_side
from archmetrics.changeset.history import CommitStep, commit_step, step_from_record, step_record
from archmetrics.parsers import LanguageTable
from archmetrics.sources import Snapshot
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.gitdelta import Delta, Pending
from archmetrics.sources.githistory import Commit
from archmetrics.sources.snapshot import SourceError, SourceFile

KEEP_EVERY = 200  # steps written to the cache at least this often: an interrupted run resumes
Keep = Callable[[Sequence[tuple[str, bytes]]], None]


class Trees(Protocol):
    """Where a walk's trees come from."""

    def snapshot(self, commit: Commit, delta: Delta) -> Snapshot:
        """``commit``'s tree, whose changes from its first parent are ``delta``."""

    def parent_side(self, commit: Commit, options: DiffOptions) -> Side:
        """The side of ``commit``'s first parent, when the walk does not hold it."""


def record_bytes(step: CommitStep) -> bytes:
    return json.dumps(step_record(step), separators=(",", ":")).encode()


def kept_step(data: bytes) -> CommitStep | None:
    """The step a record holds, or None for anything :func:`record_bytes` did not write
    (the facts cache, where records are kept, is not trusted)."""
    try:
        return step_from_record(json.loads(data))
    except ValueError:
        return None


class FileVersions:
    """The file versions a range of commits adds that have a language: each parsed once,
    before the commits that hold them are walked (or found in the facts cache)."""

    def __init__(self, options: DiffOptions, cache: FactsCache | None) -> None:
        self.options = options
        self.cache = cache
        self.table = LanguageTable.default(dict(options.languages))
        self.configuration = configuration_files(options.packs)

    def language(self, path: str) -> str | None:
        return self.table.language_of(path) or self.configuration(path)

    def wanted(self, changes: Iterable[Delta]) -> list[Selected]:
        """The distinct (blob, language) of ``changes`` that the cache has no facts for."""
        found: dict[tuple[str, str], Selected] = {}
        for delta in changes:
            for file in delta.changed:
                language = self.language(file.path)
                if language is not None and file.blob and (file.blob, language) not in found:
                    found[(file.blob, language)] = Selected(file, language)
        return [s for s in found.values() if not self._known(s)]

    def _known(self, selected: Selected) -> bool:
        cache = self.cache
        if cache is None:
            return False
        blob, language = selected.file.blob, selected.language
        return cache.has(blob, language) or cache.marked_unread(blob, language)


class Walk:
    """Commits measured in order under ``options``; each step handed to ``keep`` with its
    key, in batches and whatever ends the walk early."""

    def __init__(
        self,
        trees: Trees,
        options: DiffOptions,
        cache: FactsCache | None,
        keep: Keep | None = None,
        progress: Progress | None = None,
    ) -> None:
        self.trees = trees
        self.options = options
        self.cache = cache
        self.keep = keep
        self.progress = progress or NoProgress()
        self.pending: list[tuple[str, bytes]] = []
        self.pre: Side | None = None

    def steps(
        self, commits: Iterable[tuple[Commit, Delta]], keys: dict[str, str]
    ) -> dict[str, CommitStep]:
        found: dict[str, CommitStep] = {}
        try:
            for commit, delta in commits:
                found[commit.id] = step = self.step(commit, delta)
                if self.keep is not None:
                    self.pending.append((keys[commit.id], record_bytes(step)))
                    if len(self.pending) >= KEEP_EVERY:
                        self.flush()
                self.progress.advance()
        finally:
            self.flush()
        return found

    def keep_state(self) -> None:
        """The last commit's tree state kept in the cache (as a diff keeps the states it
        builds): the next history of this branch, one commit longer, starts from it."""
        side, cache = self.pre, self.cache
        tree = getattr(side.snapshot, "tree", None) if side is not None else None
        if side is None or cache is None or not tree:
            return
        from archmetrics.sources.statecodec import encode

        cache.put_total(state_key(tree, self.options, cache), encode(side.state))

    def flush(self) -> None:
        if self.keep is not None and self.pending:
            self.keep(self.pending)
        self.pending = []

    def step(self, commit: Commit, delta: Delta) -> CommitStep:
        """``commit`` against its first parent, as ``diff --base C^ --head C`` measures it."""
        pre = self.pre
        if pre is None or getattr(pre.snapshot, "commit", None) != commit.parent:
            pre = self.trees.parent_side(commit, self.options)
        snapshot = self.trees.snapshot(commit, delta)
        quiet, options, cache = NoProgress(), self.options, self.cache
        post = patched_side(snapshot, pre, options, cache, quiet, Pending(lambda: delta, []))
        post = post or whole_side(snapshot, options, cache, quiet)
        renames = post.renames if post.renames is not None else delta.renames
        change = compare_sides(pre, post, renames, options, quiet, cache)
        self.pre = post
        return commit_step(change)


class ListedSnapshot:
    """A commit's tree as a listing (path -> blob) without its repository: a worker has the
    facts of every file it needs, so nothing is read."""

    def __init__(self, files: dict[str, str], commit: str, tree: str) -> None:
        self.listing = files
        self.commit = commit
        self.tree = tree
        self.label = commit

    def files(self) -> tuple[SourceFile, ...]:
        return tuple(SourceFile(path, blob) for path, blob in sorted(self.listing.items()))

    def read(self, file: SourceFile) -> bytes:
        raise SourceError(f"{file.path}: a history worker has no repository to read it from")

    def after(self, delta: Delta, commit: str, tree: str) -> ListedSnapshot:
        """The tree ``delta`` makes of this one."""
        files = dict(self.listing)
        for path in delta.removed:
            files.pop(path, None)
        for old in delta.renames:
            files.pop(old, None)
        files.update((f.path, f.blob) for f in delta.changed)
        return ListedSnapshot(files, commit, tree)


class ListedTrees:
    """The trees of a contiguous range of first-parent commits, from the listing of the
    first one's parent and each commit's changes."""

    def __init__(self, base: ListedSnapshot | None, cache: FactsCache | None) -> None:
        self.last = base
        self.cache = cache

    def snapshot(self, commit: Commit, delta: Delta) -> Snapshot:
        base = self.last or ListedSnapshot({}, "", "")
        self.last = base.after(delta, commit.id, commit.tree)
        return self.last

    def parent_side(self, commit: Commit, options: DiffOptions) -> Side:
        base = self.last or ListedSnapshot({}, commit.parent or "", commit.parent_tree)
        if base.commit != (commit.parent or ""):
            raise SourceError(f"{commit.id}: not the next commit of this range")
        return whole_side(base, options, self.cache, NoProgress())
