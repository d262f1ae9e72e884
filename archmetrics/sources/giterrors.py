"""What a failed git command means, in one line: the error every git reader raises."""

from __future__ import annotations

from pathlib import Path

import git
from git.exc import GitCommandError

from archmetrics.sources.snapshot import SourceError


def explain(repo: git.Repo, error: GitCommandError, doing: str) -> SourceError:
    """A one-line error for a git command that failed, saying why where git says it."""
    stderr = str(error.stderr or "")
    if "dubious ownership" in stderr:
        where = repo.working_tree_dir or repo.git_dir
        return SourceError(
            f"{where}: git refuses to read a repository owned by another user; if you trust "
            f"it: git config --global --add safe.directory {where}"
        )
    if "promisor remote" in stderr or "lazy fetching disabled" in stderr:
        return SourceError(
            f"{doing}: the object is not in this partial clone and archmetrics does not fetch; "
            "fetch it first (e.g. git fetch --refetch, or clone without --filter)"
        )
    if is_shallow(repo):
        return SourceError(
            f"{doing}: not in this shallow clone; fetch the history first "
            "(git fetch --unshallow, or fetch-depth: 0 in CI)"
        )
    last = stderr.strip().splitlines()[-1] if stderr.strip() else f"exit {error.status}"
    return SourceError(f"{doing}: git failed: {last.removeprefix('stderr: ').strip()}")


def is_shallow(repo: git.Repo) -> bool:
    """Whether ``repo`` is a shallow clone (its history cut at some depth)."""
    return (Path(repo.git_dir) / "shallow").is_file()
