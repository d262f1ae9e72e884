"""A repository or folder opened once per command: where its settings, snapshots and renames
come from.

Opening a repository costs a GitPython object and a ``git rev-parse`` (git's own ownership
and sanity checks run there). A command opens its repository once, as a :class:`Checkout`,
and asks it for every snapshot, rename list and tag it needs; the settings and rule packs are
read from its ``root``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from archmetrics.sources.snapshot import (
    EMPTY,
    INDEX,
    WORKTREE,
    DirectorySnapshot,
    EmptySnapshot,
    Snapshot,
    SourceError,
)

if TYPE_CHECKING:
    import git as gitpython


@dataclass(frozen=True, slots=True, eq=False)
class Checkout:
    """``root``: the top of the repository (or the folder, outside git); ``repo``: the
    repository, None outside git."""

    root: Path
    repo: gitpython.Repo | None = None

    def snapshot(self, spec: str | None) -> Snapshot:
        """The snapshot ``spec`` names: None (the files on disk), ``EMPTY``, ``WORKTREE``,
        ``INDEX`` or any git revision (outside git, only None and ``EMPTY``)."""
        from archmetrics.sources import git

        if spec == EMPTY:
            return EmptySnapshot()
        if self.repo is None:
            if spec is None:
                return DirectorySnapshot(self.root)
            raise SourceError(f"{self.root}: not inside a git repository")
        if spec is not None and git.effective_spec(self.repo, spec) == EMPTY:
            return EmptySnapshot(label=f"{spec} (no commits yet)")
        if spec is None or spec == WORKTREE:
            return git.WorktreeSnapshot(self.repo)
        if spec == INDEX:
            return git.IndexSnapshot(self.repo)
        return git.RevisionSnapshot(self.repo, spec)

    def renames(self, base: str, head: str) -> dict[str, str]:
        """Paths git finds renamed from ``base`` to ``head``, old -> new (none outside git)."""
        from archmetrics.sources import git

        return {} if self.repo is None else git.renames(self.repo, base, head)

    def merge_base(self, first: str, second: str) -> str:
        """The commit ``git diff first...second`` compares from (``second`` WORKTREE or
        INDEX: from HEAD's merge base, as ``git diff --merge-base first`` does)."""
        from archmetrics.sources import git

        if self.repo is None:
            raise SourceError(f"{self.root}: not inside a git repository")
        special = (EMPTY, WORKTREE, INDEX)
        if first in special or second == EMPTY:
            raise SourceError(f"{first}...{second}: a merge base needs two commits")
        return git.merge_base(self.repo, first, "HEAD" if second in special else second)

    def commit_id(self, spec: str) -> str | None:
        """The commit ``spec`` names; None for EMPTY, WORKTREE, INDEX, outside git, or HEAD
        before the first commit."""
        from archmetrics.sources import git

        if self.repo is None or spec in (EMPTY, WORKTREE, INDEX):
            return None
        if git.effective_spec(self.repo, spec) == EMPTY:
            return None
        return git.resolve(self.repo, spec)

    def staged_paths(self) -> frozenset[str]:
        """The paths the index changes against HEAD (none outside git)."""
        from archmetrics.sources import git

        return frozenset() if self.repo is None else git.staged_paths(self.repo)

    def file_at(self, spec: str, path: str, limit: int) -> bytes | None:
        """The bytes of the file ``path`` (POSIX, from the top) at ``spec`` (a revision or
        INDEX), None when there is none (``EMPTY``, a repository with no commit yet, or no
        such file); SourceError for a symbolic link, a submodule or a file over ``limit``
        bytes (revision_files.py)."""
        from archmetrics.sources import git
        from archmetrics.sources.revision_files import file_at

        if self.repo is None or spec == EMPTY or git.effective_spec(self.repo, spec) == EMPTY:
            return None
        commit = INDEX if spec == INDEX else git.resolve(self.repo, spec)
        return file_at(self.repo, commit, path, limit, spec)

    def tags(self) -> tuple[str, ...]:
        """The repository's tags, oldest first (``git.tags_in_order``)."""
        from archmetrics.sources import git

        if self.repo is None:
            raise SourceError(f"{self.root}: not inside a git repository")
        return git.tags_in_order(self.repo)


def open_checkout(path: Path) -> Checkout:
    """The repository holding ``path``, opened, or the folder ``path`` (or a file's folder)
    outside git."""
    from archmetrics.sources import git

    repo = git.find_repository(path)
    if repo is None:
        return Checkout(path if path.is_dir() or not path.exists() else path.parent)
    return Checkout(git.toplevel(repo), repo)


def open_snapshot(root: Path, spec: str | None) -> Snapshot:
    """The snapshot ``spec`` names in the repository or directory at ``root``.

    ``spec`` is None (the files on disk), ``EMPTY``, ``WORKTREE``, ``INDEX`` or any git revision.
    A command that needs several opens the repository once
    (:func:`open_checkout`) and asks it for each.
    """
    if spec == EMPTY:
        return EmptySnapshot()
    if spec is None:
        from archmetrics.sources import git

        if not git.is_repository(root):
            return Checkout(root).snapshot(None)
    return open_checkout(root).snapshot(spec)
