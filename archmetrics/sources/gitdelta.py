"""What differs between a commit and another snapshot of its repository, as git finds it:
the files added or changed (with their blobs where git knows them), the files gone, and the
renames. A diff whose base state is known patches it with these instead of listing and
reading the whole head tree (app/tree.py, docs/performance.md "Incremental diffs").

Like every git command archmetrics runs, these run in the repository's safe environment
(gitenv.py: read-only, no program of the repository's configuration): plumbing
that compares without refreshing or writing the index. The commands a work tree needs run at
once, as git's own processes, while the caller goes on.
"""

from __future__ import annotations

import os
import subprocess
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from archmetrics.sources.paths import quote_path
from archmetrics.sources.snapshot import SourceFile

if TYPE_CHECKING:  # GitPython costs 45 ms to import: only the commands that read git do
    import git as gitpython

NO_BLOB = "0" * 40  # git's name for content it did not hash (a work tree file it saw change)
_REGULAR = frozenset({"100644", "100755"})


@dataclass(frozen=True, slots=True)
class Delta:
    """``changed``: the regular files added or changed (a blob of "" is to be read from
    disk and hashed); ``removed``: the paths gone, or no longer regular files; ``renames``:
    old path -> new path, as ``git diff -M`` pairs them. Paths are quoted (paths.py);
    ``on_disk``: the name on disk of a quoted path that differs from it."""

    changed: tuple[SourceFile, ...]
    removed: frozenset[str]
    renames: dict[str, str]
    on_disk: dict[str, str]


class _Git:
    """git processes started at once and read in turn."""

    def __init__(self, repo: gitpython.Repo) -> None:
        self.repo = repo
        self.env = {**os.environ, **repo.git.environment()}

    def start(self, *args: str, stdin: bool = False) -> tuple[list[str], subprocess.Popen[bytes]]:
        command = ["git", *args]
        process = subprocess.Popen(
            command, cwd=self.repo.working_dir, env=self.env,
            stdin=subprocess.PIPE if stdin else subprocess.DEVNULL,
            stdout=subprocess.PIPE, stderr=subprocess.PIPE,
        )  # fmt: skip
        return command, process

    def finish(self, started: tuple[list[str], subprocess.Popen[bytes]]) -> bytes:
        from git.exc import GitCommandError

        from archmetrics.sources.giterrors import explain

        command, process = started
        out, err = process.communicate()
        if process.returncode:
            error = GitCommandError(command, process.returncode, err)
            raise explain(self.repo, error, f"git {command[1]}")
        return out


def _flagged(tagged: bytes) -> bool:
    """Whether an entry of ``ls-files -z -v`` is tagged other than ``H``: each entry is a
    tag, a space, a path and a NUL, and a path holds no NUL, so the entries tagged ``H``
    are counted by ``bytes.count`` in C (a regular expression tried at every byte of the
    listing took 0.09 s for 77,000 files)."""
    entries = tagged.count(b"\0")
    plain = tagged.count(b"\0H ") + tagged.startswith(b"H ")
    return plain != entries  # (a listing cut short is taken as flagged: listed whole)


def _fields(out: bytes) -> list[str]:
    return [f for f in out.decode("utf-8", "surrogateescape").split("\0") if f]


def _read_raw(fields: Sequence[str]) -> tuple[list[tuple[str, str, str]], dict[str, str]] | None:
    """``--raw -z`` records as (path, new mode, new blob) and renames (old -> new); None for
    a record this cannot take (an unmerged path)."""
    records: list[tuple[str, str, str]] = []
    renames: dict[str, str] = {}
    i = 0
    while i < len(fields):
        meta = fields[i]
        if not meta.startswith(":"):
            return None
        _, new_mode, _, new_blob, status = meta[1:].split(" ")
        if status.startswith(("R", "C")):
            old, new = fields[i + 1], fields[i + 2]
            i += 3
            if status.startswith("R"):
                renames[old] = new
                records.append((old, "000000", NO_BLOB))
            records.append((new, new_mode, new_blob))
            continue
        if status == "U":
            return None
        path = fields[i + 1]
        i += 2
        records.append((path, "000000" if status == "D" else new_mode, new_blob))
    return records, renames


def _delta(records: Sequence[tuple[str, str, str]], renames: dict[str, str],
           untracked: Sequence[str], regular: object) -> Delta:  # fmt: skip
    """The delta of ``records`` and of the ``untracked`` files; ``regular`` tells whether an
    untracked path (or one git found changed on disk) is a regular file to read."""
    changed: list[SourceFile] = []
    removed: set[str] = set()
    on_disk: dict[str, str] = {}
    for path, mode, blob in [*records, *((p, "100644", NO_BLOB) for p in untracked)]:
        shown = quote_path(path)
        if shown != path:
            on_disk[shown] = path
        keep = mode in _REGULAR and (blob != NO_BLOB or regular(path))  # type: ignore[operator]
        if keep:
            removed.discard(shown)
            changed.append(SourceFile(shown, "" if blob == NO_BLOB else blob))
        else:
            removed.add(shown)
    named = {quote_path(old): quote_path(new) for old, new in renames.items()}
    taken = {f.path for f in changed}
    return Delta(
        tuple(sorted(changed)),
        frozenset(removed - taken),
        named,
        on_disk,
    )


class Pending:
    """A delta git is working out: called, it waits for git and gives the delta (once);
    ``cancel`` stops the git processes of a delta no one needs after all."""

    def __init__(self, finish: Callable[[], Delta | None],
                 processes: Sequence[subprocess.Popen[bytes]]) -> None:  # fmt: skip
        self._finish: Callable[[], Delta | None] | None = finish
        self.processes = processes

    def __call__(self) -> Delta | None:
        if self._finish is None:
            raise RuntimeError("a pending delta is read once")
        finish, self._finish = self._finish, None
        return finish()

    def then(self, after: Callable[[Delta], None]) -> Pending:
        """This delta, with ``after`` done on it when it comes."""
        first = self._finish
        assert first is not None

        def finish() -> Delta | None:
            delta = first()
            if delta is not None:
                after(delta)
            return delta

        return Pending(finish, self.processes)

    def cancel(self) -> None:
        for process in self.processes:
            if process.returncode is not None:
                continue  # read already
            if process.poll() is None:
                process.kill()
            process.communicate()
        self._finish = None


def start_git(
    repo: gitpython.Repo, *args: str, stdin: bool = False
) -> tuple[list[str], subprocess.Popen[bytes]]:
    """``git ARGS`` started in ``repo`` with its read-only environment (stdin a pipe when
    asked for); the caller reads it."""
    return _Git(repo).start(*args, stdin=stdin)


def read_delta(fields: Sequence[str]) -> Delta | None:
    """The delta of ``diff-tree -z --raw`` fields between two trees (None for a record this
    cannot take)."""
    read = _read_raw(fields)
    return None if read is None else _delta(*read, (), lambda path: True)


def _pending(runner: _Git, started: tuple[list[str], subprocess.Popen[bytes]]) -> Pending:
    def finish() -> Delta | None:
        return read_delta(_fields(runner.finish(started)))

    return Pending(finish, [started[1]])


def commit_delta(repo: gitpython.Repo, base: str, head: str) -> Pending:
    """From commit ``base`` to commit ``head`` (commit ids)."""
    runner = _Git(repo)
    return _pending(runner, runner.start("diff-tree", "-r", "-z", "--raw", "-M", base, head))


def index_delta(repo: gitpython.Repo, base: str) -> Pending:
    """From commit ``base`` to what is staged."""
    runner = _Git(repo)
    return _pending(runner, runner.start("diff-index", "--cached", "-z", "--raw", "-M", base))


def worktree_delta(repo: gitpython.Repo, base: str, root: str) -> Pending:
    """From commit ``base`` to the work tree: what ``git diff-index`` finds changed (a file
    git saw change on disk has no blob yet: it is read and hashed when parsed) and the
    untracked files .gitignore does not exclude. None when an index entry is marked
    assume-unchanged or skip-worktree, or is unmerged (``ls-files -v`` tags those in other
    letters than H): git would take such an entry from the index, where the work tree
    snapshot reads the disk, so the caller lists the tree instead. The three git commands
    run at once, each walking the tree its own way, while the caller goes on."""
    runner = _Git(repo)
    started = (
        runner.start("diff-index", "-z", "--raw", "-M", base),
        runner.start("ls-files", "-z", "--others", "--exclude-standard"),
        runner.start("ls-files", "-z", "-v"),
    )

    def finish() -> Delta | None:
        diff, untracked, tagged = (runner.finish(s) for s in started)
        if _flagged(tagged):
            return None
        read = _read_raw(_fields(diff))
        if read is None:
            return None

        def regular(path: str) -> bool:
            full = os.path.join(root, path)
            return os.path.isfile(full) and not os.path.islink(full)

        return _delta(*read, _fields(untracked), regular)

    return Pending(finish, [process for _, process in started])
