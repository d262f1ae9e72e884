"""Git through GitPython: revisions, the index and the working tree as snapshots.

Blobs are read through GitPython's object database, which keeps one long-lived
``git cat-file --batch`` process per repository instead of one subprocess per file.
Nothing here writes to the repository.
"""

from __future__ import annotations

from pathlib import Path

import git
from git.exc import BadName, GitCommandError, InvalidGitRepositoryError, NoSuchPathError

from archmetrics.sources.snapshot import (
    EMPTY,
    INDEX,
    WORKTREE,
    DirectorySnapshot,
    SourceError,
    SourceFile,
)

EMPTY_TREE = "4b825dc642cb6eb9a060e54bf8d69288fbee4904"


def is_repository(path: Path) -> bool:
    try:
        git.Repo(path, search_parent_directories=True)
    except (InvalidGitRepositoryError, NoSuchPathError):
        return False
    return True


def open_repository(path: Path) -> git.Repo:
    try:
        return git.Repo(path, search_parent_directories=True)
    except NoSuchPathError as error:
        raise SourceError(f"{path}: no such directory") from error
    except InvalidGitRepositoryError as error:
        raise SourceError(f"{path}: not inside a git repository") from error


def toplevel(repo: git.Repo) -> Path:
    if repo.working_tree_dir is None:
        raise SourceError(f"{repo.git_dir}: a bare repository has no working tree")
    return Path(repo.working_tree_dir)


def resolve(repo: git.Repo, rev: str) -> str:
    """The commit id ``rev`` names; SourceError with a one-line message when it names none."""
    try:
        return str(repo.commit(rev).hexsha)
    except (BadName, ValueError, GitCommandError) as error:
        raise SourceError(f"unknown revision {rev!r}") from error


def has_commits(repo: git.Repo) -> bool:
    try:
        repo.head.commit  # noqa: B018 -- raises when HEAD points at no commit yet
    except ValueError:
        return False
    return True


def effective_spec(repo: git.Repo, spec: str) -> str:
    """``spec``, except that HEAD in a repository with no commits yet is the empty tree."""
    return EMPTY if spec == "HEAD" and not has_commits(repo) else spec


def _ls(repo: git.Repo, *args: str) -> list[str]:
    out: str = repo.git.execute(["git", *args], strip_newline_in_stdout=False)
    return [entry for entry in out.split("\0") if entry]


class _BlobReader:
    def __init__(self, repo: git.Repo):
        self.repo = repo

    def read(self, file: SourceFile) -> bytes:
        try:
            data: bytes = self.repo.odb.stream(bytes.fromhex(file.blob)).read()
        except (ValueError, GitCommandError) as error:
            raise SourceError(f"{file.path}: cannot read blob {file.blob}") from error
        return data


class RevisionSnapshot(_BlobReader):
    """The tree of a commit."""

    def __init__(self, repo: git.Repo, rev: str):
        super().__init__(repo)
        self.commit = resolve(repo, rev)
        self.label = rev

    def files(self) -> tuple[SourceFile, ...]:
        found = []
        for entry in _ls(self.repo, "ls-tree", "-r", "-z", "--full-tree", self.commit):
            meta, path = entry.split("\t", 1)
            mode, kind, blob = meta.split(" ")
            if kind == "blob" and mode != "120000":  # skip symlinks and submodules
                found.append(SourceFile(path, blob))
        return tuple(sorted(found))


class IndexSnapshot(_BlobReader):
    """What is staged (stage 0 entries; an unmerged path is read from stage 2, 'ours')."""

    label = INDEX

    def files(self) -> tuple[SourceFile, ...]:
        found: dict[str, SourceFile] = {}
        for entry in _ls(self.repo, "ls-files", "-s", "-z"):
            meta, path = entry.split("\t", 1)
            mode, blob, stage = meta.split(" ")
            if mode == "120000" or mode == "160000" or stage not in ("0", "2"):
                continue
            found[path] = SourceFile(path, blob)
        return tuple(sorted(found.values()))


class WorktreeSnapshot(DirectorySnapshot):
    """The working tree: tracked and untracked files that .gitignore does not exclude."""

    def __init__(self, repo: git.Repo):
        root = toplevel(repo)
        paths = _ls(repo, "ls-files", "-z", "--cached", "--others", "--exclude-standard")
        super().__init__(root, sorted(set(paths)), label=WORKTREE)


def renames(repo: git.Repo, base: str, head: str) -> dict[str, str]:
    """Paths renamed between two snapshot specs, old -> new, as ``git diff -M`` finds them."""
    args = ["diff", "-M", "--name-status", "-z", "--no-ext-diff", "--diff-filter=R"]
    base, head = effective_spec(repo, base), effective_spec(repo, head)
    if base == EMPTY or head == EMPTY:
        return {}
    if head == WORKTREE and base == INDEX:
        pass  # plain `git diff`: index -> working tree
    elif head == WORKTREE:
        args.append(resolve(repo, base))
    elif head == INDEX:
        args += ["--cached", resolve(repo, base) if base != INDEX else "HEAD"]
    elif base in (INDEX, WORKTREE):
        args += ["-R", resolve(repo, head)] + (["--cached"] if base == INDEX else [])
    else:
        args += [resolve(repo, base), resolve(repo, head)]
    fields = _ls(repo, *args)
    pairs: dict[str, str] = {}
    for i in range(0, len(fields) - 2, 3):
        status, old, new = fields[i : i + 3]
        if status.startswith("R"):
            pairs[old] = new
    return pairs


def tags_in_order(path: Path) -> tuple[str, ...]:
    """The repository's tags in history order (by how many commits lie behind each, then by
    name): the stages of a study subject, oldest first."""
    repo = open_repository(path)
    names = [str(tag) for tag in repo.tags]
    if not names:
        raise SourceError(f"{path}: no tags to take stages from; give --revisions")
    depth = {name: int(repo.git.rev_list("--count", f"{name}^{{commit}}")) for name in names}
    return tuple(sorted(names, key=lambda name: (depth[name], name)))
