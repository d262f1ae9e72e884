"""Snapshots: one version of a tree of files, each file named by its git blob hash."""

from __future__ import annotations

import hashlib
import os
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Protocol, runtime_checkable

from archmetrics.globs import gitignore_file
from archmetrics.reading import read_regular
from archmetrics.sources.paths import quote_path

if TYPE_CHECKING:
    from pathspec import GitIgnoreSpec

EMPTY = "EMPTY"  # the empty tree: a first integration stage has nothing before it
WORKTREE = "WORKTREE"  # the files on disk, committed or not (untracked ones too, unless ignored)
INDEX = "INDEX"  # what is staged

# Folders a folder snapshot does not walk, and why (listed in reports: never skipped silently).
# A folder called ``venv`` is skipped only if it is a virtual environment (it holds
# ``pyvenv.cfg``, or ``conda-meta``), like any other folder that holds one: a package named
# ``venv`` is code (the standard library has one). ``.venv`` is no importable name.
SKIP_DIRS = {
    ".git": "version control",
    ".hg": "version control",
    ".svn": "version control",
    ".venv": "virtual environment",
    "__pycache__": "bytecode cache",
    "node_modules": "npm packages",
    ".tox": "tox environments",
}


class SourceError(Exception):
    """A revision or path that cannot be read; the message is one line for the user."""


@dataclass(frozen=True, slots=True, order=True)
class SourceFile:
    """A file in a snapshot: its path (POSIX, relative to the snapshot's root, quoted as
    :func:`~archmetrics.sources.paths.quote_path` says) and blob hash."""

    path: str
    blob: str


class Snapshot(Protocol):
    """One version of a tree. ``label`` is what reports call it (a revision, WORKTREE ...)."""

    @property
    def label(self) -> str: ...

    def files(self) -> tuple[SourceFile, ...]: ...

    def read(self, file: SourceFile) -> bytes: ...


def resolve_path(path: Path) -> Path:
    """``path`` made absolute with symbolic links resolved; a loop or an unreadable folder
    is a one-line :class:`SourceError`."""
    try:
        return path.resolve()
    except (RuntimeError, OSError) as error:  # 3.11 raises RuntimeError for a link loop
        raise SourceError(f"{path}: cannot resolve: {error}") from error


def blob_hash(data: bytes) -> str:
    """The git blob id of ``data`` (what ``git hash-object`` prints)."""
    digest = hashlib.sha1(b"blob %d\0" % len(data), usedforsecurity=False)
    digest.update(data)
    return digest.hexdigest()


@runtime_checkable
class Sized(Protocol):
    """A snapshot that can tell a file's size without reading it (the files on disk)."""

    def size(self, file: SourceFile) -> int | None: ...


@dataclass(frozen=True, slots=True)
class EmptySnapshot:
    """The empty tree."""

    label: str = EMPTY

    def files(self) -> tuple[SourceFile, ...]:
        return ()

    def read(self, file: SourceFile) -> bytes:
        raise SourceError(f"{file.path}: the empty tree has no files")


class DirectorySnapshot:
    """Files under a directory on disk (outside git, or a working tree read directly)."""

    def __init__(
        self,
        root: Path,
        paths: Iterable[str] | None = None,
        label: str = WORKTREE,
        within: Sequence[str] = (),
    ):
        """``paths``: exactly these files (relative to ``root``); ``within``: only the files
        and folders (relative to ``root``, as on disk) to walk, so that measuring one file
        does not list every file beside it; neither: the whole tree."""
        self.root = root
        self.label = label
        self._paths = tuple(sorted(paths)) if paths is not None else None
        self._within = tuple(sorted(set(within))) if "" not in within else ()
        self._hashes: dict[str, str] = {}
        self._on_disk: dict[str, str] = {}  # quoted name -> the name on disk, where they differ
        self.skipped: dict[str, str] = {}  # folder (relative, ending in /) -> why not walked

    def _walk(self) -> Iterable[str]:
        if self._paths is not None:
            yield from self._paths
            return
        if not self._within:
            yield from _walk_folder(self.root, self.root, self.skipped)
            return
        found: set[str] = set()
        for target in self._within:
            full = self.root / target
            if full.is_dir() and not full.is_symlink():
                found.update(_walk_folder(self.root, full, self.skipped))
            else:
                found.add(target)
        yield from sorted(found, key=_walk_order)

    def files(self) -> tuple[SourceFile, ...]:
        found = []
        for path in self._walk():
            full = self.root / path
            # a path with a known blob is a regular file (git said so): no stat asked
            if path in self._hashes or (full.is_file() and not full.is_symlink()):
                shown = quote_path(path)
                if shown != path:
                    self._on_disk[shown] = path
                found.append(SourceFile(shown, self._hashes.get(path, "")))
        return tuple(found)

    def read(self, file: SourceFile) -> bytes:
        """The file's bytes: a regular file's, never a symbolic link's target, never a FIFO
        or device put there since the tree was listed."""
        try:
            return read_regular(self.root / self._on_disk.get(file.path, file.path), follow=False)
        except OSError as error:
            raise SourceError(f"{file.path}: cannot read: {error.strerror or error}") from error

    def size(self, file: SourceFile) -> int | None:
        """The file's size on disk, None if it cannot be asked (it is read later, and a
        problem is reported then)."""
        try:
            return os.stat(self.root / self._on_disk.get(file.path, file.path)).st_size
        except OSError:
            return None


def _walk_folder(root: Path, folder: Path, skipped: dict[str, str]) -> Iterator[str]:
    """The files under ``folder`` (relative to ``root``), in walk order, skipping the folders
    no one measures (version control, virtual environments, caches) and what the folder's
    ``.gitignore`` files ignore, as git would; each skipped folder or file is recorded in
    ``skipped`` with the reason."""
    ignores = _Ignores(root)
    for current, dirs, names in os.walk(folder):
        rel = Path(current).relative_to(root)
        kept = []
        for name in sorted(dirs):
            path = (rel / name).as_posix()
            reason = _skip_reason(Path(current) / name, name)
            if reason is None and ignores.ignored(path, directory=True):
                reason = ignores.reason
            if reason is None:
                kept.append(name)
            else:
                skipped[quote_path(path) + "/"] = reason
        dirs[:] = kept
        for name in sorted(names):
            path = (rel / name).as_posix()
            if ignores.ignored(path, directory=False):
                skipped[quote_path(path)] = ignores.reason
            else:
                yield path


_GITIGNORE_BYTES = 1 << 20  # a .gitignore read, at most (the folder is not trusted)
_GITIGNORE_LINES = 10_000


class _Ignores:
    """The ``.gitignore`` files of a plain folder, read as git reads them: each applies to
    the paths below its own folder, a deeper file's decision wins over a shallower one's,
    and within a file the last matching pattern wins (``!`` re-includes). Read with
    pathspec's gitignore rules; a file too large, unreadable or with a pattern pathspec
    refuses counts as absent."""

    reason = "ignored by .gitignore"

    def __init__(self, root: Path) -> None:
        self.root = root
        self._specs: dict[str, GitIgnoreSpec | None] = {}

    def _spec(self, folder: str) -> GitIgnoreSpec | None:
        if folder not in self._specs:
            self._specs[folder] = _read_gitignore(self.root / folder / ".gitignore")
        return self._specs[folder]

    def ignored(self, path: str, directory: bool) -> bool:
        parts = path.split("/")
        decision: bool | None = None
        for depth in range(len(parts)):
            spec = self._spec("/".join(parts[:depth]))
            if spec is not None:
                below = "/".join(parts[depth:]) + ("/" if directory else "")
                found = spec.check_file(below).include
                decision = decision if found is None else found
        return bool(decision)


def _read_gitignore(path: Path) -> GitIgnoreSpec | None:
    try:
        data = read_regular(path, _GITIGNORE_BYTES, follow=False)
        lines = data.decode("utf-8", "surrogateescape").splitlines()[:_GITIGNORE_LINES]
        return gitignore_file(lines)  # matched by RE2: a hostile pattern cannot backtrack
    except (OSError, ValueError):
        return None


def _skip_reason(path: Path, name: str) -> str | None:
    """Why the folder ``path`` is not walked, or None."""
    if name in SKIP_DIRS:
        return SKIP_DIRS[name]
    if name.endswith(".egg-info"):
        return "package metadata"
    if (path / "pyvenv.cfg").is_file():
        return "virtual environment (pyvenv.cfg)"
    if (path / "conda-meta").is_dir():
        return "conda environment (conda-meta)"
    return None


def _walk_order(path: str) -> list[tuple[int, str]]:
    """Where ``_walk_folder`` of the whole tree puts ``path``: a folder's files before its
    subfolders, each in name order."""
    *folders, name = path.split("/")
    return [(1, folder) for folder in folders] + [(0, name)]
