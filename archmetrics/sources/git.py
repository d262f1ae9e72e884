"""Git through GitPython: revisions, the index and the working tree as snapshots.

Blobs are read through GitPython's object database, which keeps one long-lived
``git cat-file --batch`` process per repository instead of one subprocess per file.

Nothing here writes to the repository, reaches the network or runs a program the
repository's configuration names: every git command runs with
:func:`~archmetrics.sources.gitenv.safe_environment`, so git neither refreshes the index's
stat cache (which rewrites ``.git/index`` and takes ``index.lock``), nor fetches objects a
partial clone left out, nor runs ``core.fsmonitor``, filters or hooks. A revision or
object that is not in the clone is a one-line :class:`SourceError` saying so and how to
fetch it (docs/security.md).
"""

from __future__ import annotations

from pathlib import Path

import git
from git.exc import GitCommandError, GitError, InvalidGitRepositoryError, NoSuchPathError

from archmetrics.sources.gitdelta import (
    Pending,
    commit_delta,
    index_delta,
    worktree_delta,
)
from archmetrics.sources.gitenv import safe_environment
from archmetrics.sources.giterrors import explain, is_shallow
from archmetrics.sources.paths import quote_path
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
    except OSError as error:  # a symbolic-link loop, a folder we may not read
        raise SourceError(f"{path}: cannot read: {error.strerror or error}") from error
    return True


def open_repository(path: Path) -> git.Repo:
    """The repository holding ``path``, its git commands set to a safe environment."""
    repo = find_repository(path)
    if repo is None:
        if not path.exists():
            raise SourceError(f"{path}: no such directory")
        raise SourceError(f"{path}: not inside a git repository")
    return repo


def find_repository(path: Path) -> git.Repo | None:
    """The repository holding ``path`` (its git commands set to the environment of
    :func:`~archmetrics.sources.gitenv.safe_environment`: read-only, offline, no program of
    the repository's configuration), or None when no repository holds it; SourceError when
    one does but git cannot read it."""
    try:
        repo = git.Repo(path, search_parent_directories=True)
    except (InvalidGitRepositoryError, NoSuchPathError):
        return None
    except OSError as error:  # a symbolic-link loop, a folder we may not read
        raise SourceError(f"{path}: cannot read: {error.strerror or error}") from error
    repo.git.update_environment(**safe_environment())
    try:  # git's own checks (ownership, a broken .git) fail here, not halfway through
        repo.git.execute(["git", "rev-parse", "--git-dir"])
        names: str = repo.git.execute(["git", "config", "--list", "--name-only", "-z"])
    except GitCommandError as error:
        raise explain(repo, error, str(path)) from error
    # the filter and diff drivers the configuration defines, each one's programs disabled
    repo.git.update_environment(**safe_environment(names.split("\0")))
    return repo


def toplevel(repo: git.Repo) -> Path:
    if repo.working_tree_dir is None:
        raise SourceError(f"{repo.git_dir}: a bare repository has no working tree")
    return Path(repo.working_tree_dir)


def resolve(repo: git.Repo, rev: str) -> str:
    """The commit id ``rev`` names, in any syntax git accepts (``@{-1}``, ``v1^{commit}``,
    ``HEAD@{yesterday}``); SourceError with a one-line message when it names none."""
    try:
        out: str = repo.git.execute(
            ["git", "rev-parse", "--verify", "--quiet", "--end-of-options", f"{rev}^{{commit}}"]
        )
    except GitCommandError as error:
        if is_shallow(repo):
            raise SourceError(
                f"unknown revision {rev!r} in this shallow clone: if it is older than the "
                "clone's depth, fetch the history first (git fetch --unshallow, or "
                "fetch-depth: 0 in CI)"
            ) from error
        if error.stderr and "dubious ownership" in str(error.stderr):
            raise explain(repo, error, f"revision {rev!r}") from error
        raise SourceError(f"unknown revision {rev!r}") from error
    return out.strip()


def merge_base(repo: git.Repo, first: str, second: str) -> str:
    """The best common ancestor of two revisions, as ``git diff A...B`` compares from;
    SourceError when they share no history, or when a shallow clone cuts it off (with the
    fix: fetch the history)."""
    ends = (resolve(repo, first), resolve(repo, second))
    try:
        out: str = repo.git.execute(["git", "merge-base", "--end-of-options", *ends])
    except GitCommandError as error:
        if error.status != 1 or str(error.stderr or "").strip():
            raise explain(repo, error, f"the merge base of {first} and {second}") from error
        if is_shallow(repo):
            raise SourceError(
                f"{first} and {second}: no merge base in this shallow clone; fetch the history"
                " first (git fetch --deepen=200, or --unshallow; fetch-depth: 0 in CI)"
            ) from error
        raise SourceError(f"{first} and {second} share no history: no merge base") from error
    return out.strip().splitlines()[0]


def staged_paths(repo: git.Repo) -> frozenset[str]:
    """The paths the index changes against HEAD (every indexed path with no commit yet)."""
    if not has_commits(repo):
        return frozenset(quote_path(p) for p in _ls(repo, "ls-files", "-z"))
    listed = _ls(repo, "diff-index", "--cached", "--name-only", "--no-renames", "-z", "HEAD")
    return frozenset(quote_path(p) for p in listed)


def has_commits(repo: git.Repo) -> bool:
    try:
        repo.git.execute(["git", "rev-parse", "--verify", "--quiet", "HEAD^{commit}"])
    except GitCommandError:
        return False
    return True


def effective_spec(repo: git.Repo, spec: str) -> str:
    """``spec``, except that HEAD in a repository with no commits yet is the empty tree."""
    return EMPTY if spec == "HEAD" and not has_commits(repo) else spec


def _count(repo: git.Repo, commit: str) -> int:
    try:
        return int(repo.git.execute(["git", "rev-list", "--count", commit]))
    except GitCommandError as error:
        raise explain(repo, error, f"the history of {commit}") from error


def _ls(repo: git.Repo, *args: str) -> list[str]:
    try:
        out: str = repo.git.execute(["git", *args], strip_newline_in_stdout=False)
    except GitCommandError as error:
        raise explain(repo, error, f"git {args[0]}") from error
    return [entry for entry in out.split("\0") if entry]


class _BlobReader:
    def __init__(self, repo: git.Repo):
        self.repo = repo

    def size(self, file: SourceFile) -> int | None:
        """The blob's size, asked of git's long-lived ``cat-file --batch-check`` without
        reading the blob (a file over the size limit is never read); None if git cannot
        tell (reading it will say why)."""
        try:
            return int(self.repo.odb.info(bytes.fromhex(file.blob)).size)
        except (GitCommandError, ValueError, GitError):
            return None

    def read(self, file: SourceFile) -> bytes:
        try:
            data: bytes = self.repo.odb.stream(bytes.fromhex(file.blob)).read()
        except GitCommandError as error:
            raise explain(self.repo, error, f"{file.path} (blob {file.blob})") from error
        except (ValueError, GitError) as error:
            raise SourceError(
                f"{file.path}: cannot read blob {file.blob}: it is not in this clone "
                "(a partial clone? archmetrics does not fetch; fetch it first)"
            ) from error
        return data


class RevisionSnapshot(_BlobReader):
    """The tree of a commit. ``commit`` and ``tree``: the ids, when the caller knows them
    already (a history lists both for every commit), so that git is not asked again."""

    def __init__(self, repo: git.Repo, rev: str, commit: str = "", tree: str = ""):
        super().__init__(repo)
        self.commit = commit or resolve(repo, rev)
        self.label = rev
        self._tree = tree

    @property
    def tree(self) -> str:
        """The commit's tree id: what names this snapshot's content."""
        if not self._tree:
            self._tree = _ls(self.repo, "rev-parse", f"{self.commit}^{{tree}}")[0].strip()
        return self._tree

    def delta_from(self, commit: str) -> Pending:
        """What differs from ``commit`` (a commit id) to this commit (gitdelta.py)."""
        return commit_delta(self.repo, commit, self.commit)

    def files(self) -> tuple[SourceFile, ...]:
        found = []
        for entry in _ls(self.repo, "ls-tree", "-r", "-z", "--full-tree", self.commit):
            meta, path = entry.split("\t", 1)
            mode, kind, blob = meta.split(" ")
            if kind == "blob" and mode != "120000":  # skip symlinks and submodules
                found.append(SourceFile(quote_path(path), blob))
        return tuple(sorted(found))


class Blobs(_BlobReader):
    """A repository's blobs, read by id: the file versions a history parses before it walks
    the commits that hold them."""

    label = "history"

    def files(self) -> tuple[SourceFile, ...]:
        return ()


class IndexSnapshot(_BlobReader):
    """What is staged (stage 0 entries; an unmerged path is read from stage 2, 'ours')."""

    label = INDEX

    def delta_from(self, commit: str) -> Pending:
        """What differs from ``commit`` (a commit id) to what is staged (gitdelta.py)."""
        return index_delta(self.repo, commit)

    def files(self) -> tuple[SourceFile, ...]:
        found: dict[str, SourceFile] = {}
        for entry in _ls(self.repo, "ls-files", "-s", "-z"):
            meta, path = entry.split("\t", 1)
            mode, blob, stage = meta.split(" ")
            if mode == "120000" or mode == "160000" or stage not in ("0", "2"):
                continue
            found[path] = SourceFile(quote_path(path), blob)
        return tuple(sorted(found.values()))


class WorktreeSnapshot(DirectorySnapshot):
    """The working tree: tracked and untracked files that .gitignore does not exclude.

    A tracked file git finds unchanged since it was staged comes with the index's blob, so
    it is neither read nor hashed unless its facts must be parsed (then the bytes read are
    hashed, as every file's are): a diff of the work tree after editing one file reads that
    file, not every file (docs/performance.md). The tree is listed when its files are first
    asked for: a diff that patches a known state asks git what changed instead
    (:meth:`delta_from`)."""

    def __init__(self, repo: git.Repo):
        super().__init__(toplevel(repo), (), label=WORKTREE)
        self.repo = repo
        self._listed = False

    def files(self) -> tuple[SourceFile, ...]:
        if not self._listed:
            paths = _ls(self.repo, "ls-files", "-z", "--cached", "--others", "--exclude-standard")
            self._paths = tuple(sorted(set(paths)))
            self._hashes = _unchanged_blobs(self.repo)
            self._listed = True
        return super().files()

    def delta_from(self, commit: str) -> Pending:
        """What differs from ``commit`` (a commit id) to this work tree (gitdelta.py), being
        worked out; the files it names can be read from this snapshot."""
        pending = worktree_delta(self.repo, commit, str(self.root))
        return pending.then(lambda delta: self._on_disk.update(delta.on_disk))


def _unchanged_blobs(repo: git.Repo) -> dict[str, str]:
    """Path -> blob of each regular tracked file that ``git diff-files`` (the plumbing: it
    compares without writing the index, and compares the bytes of an entry whose stat data
    cannot tell) finds as staged; not an entry marked assume-unchanged or skip-worktree
    (``ls-files -v`` tags those in other letters), nor an unmerged one."""
    changed = set(_ls(repo, "diff-files", "--name-only", "-z"))
    found = {}
    for entry in _ls(repo, "ls-files", "-s", "-v", "-z"):
        meta, path = entry.split("\t", 1)
        tag, mode, blob, stage = meta.split(" ")
        if tag == "H" and stage == "0" and mode in ("100644", "100755") and path not in changed:
            found[path] = blob
    return found


def renames(repo: git.Repo, base: str, head: str) -> dict[str, str]:
    """Paths renamed between two snapshot specs, old -> new, as ``git diff -M`` finds them.

    Asked of git's plumbing (``diff-tree``, ``diff-index``, ``diff-files``), which compares
    without refreshing the index: porcelain ``git diff`` against the working tree rewrites
    ``.git/index`` even with optional locks off."""
    base, head = effective_spec(repo, base), effective_spec(repo, head)
    if base == EMPTY or head == EMPTY:
        return {}
    options = ["-M", "--name-status", "-z", "--diff-filter=R"]
    if head == WORKTREE and base == INDEX:
        args = ["diff-files", *options]
    elif head == WORKTREE:
        args = ["diff-index", *options, resolve(repo, base)]
    elif head == INDEX:
        args = [
            "diff-index",
            "--cached",
            *options,
            resolve(repo, base) if base != INDEX else "HEAD",
        ]
    elif base in (INDEX, WORKTREE):
        cached = ["--cached"] if base == INDEX else []
        args = ["diff-index", "-R", *cached, *options, resolve(repo, head)]
    else:
        args = ["diff-tree", "-r", *options, resolve(repo, base), resolve(repo, head)]
    fields = _ls(repo, *args)
    pairs: dict[str, str] = {}
    for i in range(0, len(fields) - 2, 3):
        status, old, new = fields[i : i + 3]
        if status.startswith("R"):
            pairs[quote_path(old)] = quote_path(new)
    return pairs


def tags_in_order(repo: git.Repo) -> tuple[str, ...]:
    """The repository's tags in history order (by how many commits lie behind each, then by
    name): the stages of a study subject, oldest first."""
    names = [str(tag) for tag in repo.tags]
    if not names:
        where = repo.working_tree_dir or repo.git_dir
        raise SourceError(f"{where}: no tags to take stages from; give --revisions")
    depth = {name: _count(repo, resolve(repo, name)) for name in names}
    return tuple(sorted(names, key=lambda name: (depth[name], name)))
