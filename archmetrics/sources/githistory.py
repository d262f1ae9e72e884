"""A branch's history as git gives it: the commits of a range, each with its first parent's
tree, and what each commit changed, asked of git in a few processes for the whole range.

``git log`` lists the commits (oldest first); ``git cat-file --batch-check`` names the tree
of every parent the listing does not hold; ``git diff-tree --stdin`` gives, in one process
per batch of commits, the same records ``diff-tree -r -M PARENT COMMIT`` gives one commit at a
time (app/tree.py patches a tree's state with them, as a diff does). Like every git command
archmetrics runs, these run with the read-only environment of git.py.
"""

from __future__ import annotations

import re
from collections.abc import Iterator, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

from archmetrics.sources.gitdelta import Delta, read_delta, start_git
from archmetrics.sources.snapshot import SourceError

if TYPE_CHECKING:
    import git as gitpython

EMPTY_TREE = "4b825dc642cb6eb9a060e54bf8d69288fbee4904"
DELTA_BATCH = 2000  # commits per diff-tree process: its output is held until it ends
_OPTION = re.compile(r"^-")
_SEP = "\x1f"


@dataclass(frozen=True, slots=True)
class Commit:
    """One commit of a history: ``parent`` is its first parent (None for a root commit,
    measured against the empty tree), ``parent_tree`` that parent's tree."""

    id: str
    tree: str
    parent: str | None
    parent_tree: str
    time: int  # committer date, seconds since the epoch
    subject: str
    merge: bool


@dataclass(frozen=True, slots=True)
class Range:
    """Which commits: ``spec`` is a revision range as ``git log`` takes it (``v1..v2``,
    ``main``, ``A...B``); ``first_parent`` follows only first parents; ``merges`` keeps only
    merge commits; ``since``/``until`` are dates as git reads them; ``max_count`` keeps the
    newest N."""

    spec: str = "HEAD"
    first_parent: bool = True
    merges: bool = False
    since: str | None = None
    until: str | None = None
    max_count: int | None = None


def _run(repo: gitpython.Repo, args: Sequence[str], stdin: bytes | None = None) -> bytes:
    started = start_git(repo, *args, stdin=stdin is not None)
    command, process = started
    out, err = process.communicate(stdin)
    if process.returncode:
        raise _failed(repo, command, process.returncode, err)
    return out


def _failed(repo: gitpython.Repo, command: list[str], status: int, err: bytes) -> SourceError:
    """git's own first ``fatal:`` line (a range it cannot read names the revision there;
    its last lines are usage), or what :func:`explain` makes of the error."""
    from git.exc import GitCommandError

    from archmetrics.sources.giterrors import explain

    error = explain(repo, GitCommandError(command, status, err), f"git {command[1]}")
    fatal = [line for line in err.decode("utf-8", "replace").splitlines()
             if line.startswith("fatal: ")]  # fmt: skip
    if fatal and "shallow" not in str(error) and "partial clone" not in str(error):
        return SourceError(f"git {command[1]}: {fatal[0].removeprefix('fatal: ')}")
    return error


def list_commits(repo: gitpython.Repo, which: Range) -> tuple[Commit, ...]:
    """The commits of ``which``, oldest first (each against its first parent)."""
    for value in (which.spec, which.since or "", which.until or ""):
        if _OPTION.match(value):
            raise SourceError(f"{value!r}: a revision range or date, not an option")
    args = ["log", "-z", f"--format=%H{_SEP}%T{_SEP}%P{_SEP}%ct{_SEP}%s"]
    if which.first_parent:
        args.append("--first-parent")
    if which.merges:
        args.append("--merges")
    if which.since:
        args.append(f"--since={which.since}")
    if which.until:
        args.append(f"--until={which.until}")
    if which.max_count is not None:
        args.append(f"--max-count={which.max_count}")
    args += ["--end-of-options", which.spec, "--"]
    out = _run(repo, args)
    listed = []
    for entry in out.decode("utf-8", "replace").split("\0"):
        if not entry:
            continue
        commit, tree, parents, when, subject = entry.split(_SEP, 4)
        listed.append((commit, tree, parents.split(), int(when), subject))
    listed.reverse()
    trees = {commit: tree for commit, tree, *_ in listed}
    missing = sorted({p[0] for _, _, p, _, _ in listed if p and p[0] not in trees})
    trees.update(_trees(repo, missing))
    return tuple(
        Commit(commit, tree, p[0] if p else None, trees[p[0]] if p else EMPTY_TREE, when,
               subject, len(p) > 1)
        for commit, tree, p, when, subject in listed
    )  # fmt: skip


def _trees(repo: gitpython.Repo, commits: Sequence[str]) -> dict[str, str]:
    """The tree of each commit id, asked of one ``cat-file --batch-check``."""
    if not commits:
        return {}
    request = "".join(f"{c}^{{tree}}\n" for c in commits).encode()
    out = _run(repo, ["cat-file", "--batch-check=%(objectname)"], request)
    found = out.decode().split()
    if len(found) != len(commits) or any(len(t) not in (40, 64) for t in found):
        raise SourceError("git cat-file could not name the tree of every parent commit")
    return dict(zip(commits, found, strict=True))


def commit_deltas(repo: gitpython.Repo, commits: Sequence[Commit]) -> Iterator[Delta]:
    """What each commit changed from its first parent (the empty tree for a root commit),
    in order: ``diff-tree --stdin`` fed ``TREE PARENT_TREE`` pairs, one process per
    :data:`DELTA_BATCH` commits."""
    for start in range(0, len(commits), DELTA_BATCH):
        batch = commits[start : start + DELTA_BATCH]
        # two trees per line (a root commit's parent is the empty tree): the trees' own diff
        request = "".join(f"{c.parent_tree} {c.tree}\n" for c in batch).encode()
        args = ["diff-tree", "--stdin", "--always", "-r", "-z", "--raw", "-M"]
        yield from _split(_run(repo, args, request), batch)


def _split(out: bytes, batch: Sequence[Commit]) -> Iterator[Delta]:
    """``diff-tree --stdin --always -z`` output cut into one delta per line of input: each
    starts with a header naming the two trees compared (ended by a newline, not a NUL, so
    it shares its field with the first record), then its records (a field that starts
    with ``:`` where a record or a header may come is a record: a path is never read there,
    since every path follows its record's meta field)."""
    fields = out.decode("utf-8", "surrogateescape").split("\0")
    if fields and fields[-1] == "":
        fields.pop()
    at = 0
    for commit in batch:
        if at >= len(fields) or fields[at].startswith(":"):
            raise SourceError(f"git diff-tree gave no header for {commit.id}")
        header, _, first = fields[at].partition("\n")  # two trees' header ends in a newline
        if header != f"{commit.parent_tree} {commit.tree}":
            raise SourceError(f"git diff-tree answered for other trees than {commit.id}'s")
        if first:
            fields[at] = first
        else:
            at += 1
        start = at
        while at < len(fields) and fields[at].startswith(":"):
            status = fields[at].rsplit(" ", 1)[-1]
            at += 3 if status[:1] in ("R", "C") else 2
        delta = read_delta(fields[start:at])
        if delta is None:
            raise SourceError(f"git diff-tree gave a record it cannot read for {commit.id}")
        yield delta
    if at != len(fields):
        raise SourceError("git diff-tree gave more records than commits asked for")
