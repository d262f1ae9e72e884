"""Sketches of an architecture as snapshots: a tree with a patch applied or stubs laid over.

Nothing here changes the repository: a patch is applied by ``git apply`` (which runs no
hooks, refuses paths outside the tree and does not write beyond a symbolic link) in a
temporary folder holding only the files it touches; stubs are read from their folder, whose
symbolic links are not followed. Both are then read as one more snapshot.
"""

from __future__ import annotations

import os
import subprocess
import tempfile
from collections.abc import Mapping
from pathlib import Path

from archmetrics.reading import TooLarge, read_regular
from archmetrics.sources.gitenv import READ_ONLY
from archmetrics.sources.snapshot import (
    DirectorySnapshot,
    Sized,
    Snapshot,
    SourceError,
    SourceFile,
    blob_hash,
)

MAX_PATCH_BYTES = 20_000_000
MAX_STUB_FILES = 20_000


class OverlaySnapshot:
    """``base`` with some files replaced or added (bytes) or removed (None)."""

    def __init__(self, base: Snapshot, changes: Mapping[str, bytes | None], label: str) -> None:
        self.base, self.changes, self.label = base, dict(changes), label

    def files(self) -> tuple[SourceFile, ...]:
        kept = [f for f in self.base.files() if f.path not in self.changes]
        added = [SourceFile(p, blob_hash(d)) for p, d in self.changes.items() if d is not None]
        return tuple(sorted(kept + added))

    def read(self, file: SourceFile) -> bytes:
        data = self.changes.get(file.path)
        return data if data is not None else self.base.read(file)

    def size(self, file: SourceFile) -> int | None:
        data = self.changes.get(file.path)
        if data is not None:
            return len(data)
        return self.base.size(file) if isinstance(self.base, Sized) else None


def stubs_overlay(base: Snapshot, folder: Path, label: str) -> OverlaySnapshot:
    """``base`` with every file under ``folder`` laid over it at the same relative path."""
    if not folder.is_dir():
        raise SourceError(f"{folder}: no such folder of stubs")
    stubs = DirectorySnapshot(folder, label=label)
    files = stubs.files()
    if len(files) > MAX_STUB_FILES:
        raise SourceError(f"{folder}: more than {MAX_STUB_FILES} stub files")
    return OverlaySnapshot(base, {f.path: stubs.read(f) for f in files}, label)


def _git_apply(folder: Path, args: list[str], patch: bytes) -> bytes:
    env = {**os.environ, **READ_ONLY, "GIT_CEILING_DIRECTORIES": str(folder.parent)}
    env.pop("GIT_DIR", None)
    env.pop("GIT_WORK_TREE", None)
    done = subprocess.run(
        ["git", "apply", *args, "-"],
        cwd=folder,
        input=patch,
        capture_output=True,
        env=env,
        check=False,
    )
    if done.returncode != 0:
        first = (done.stderr.decode("utf-8", "replace").strip().splitlines() or ["failed"])[0]
        raise SourceError(f"the patch does not apply: {first}")
    return done.stdout


def _touched(numstat: bytes) -> list[str]:
    """Every path ``git apply --numstat -z`` names (both sides of a rename)."""
    fields = numstat.split(b"\0")
    paths: list[str] = []
    i = 0
    while i < len(fields) - 1:
        counts, _, path = fields[i].partition(b"\t")[2].partition(b"\t")
        del counts
        if path:
            paths.append(path.decode("utf-8", "surrogateescape"))
            i += 1
        else:  # a rename: the old and the new path follow in fields of their own
            paths += [f.decode("utf-8", "surrogateescape") for f in fields[i + 1 : i + 3]]
            i += 3
    return paths


def patch_overlay(base: Snapshot, patch_file: Path, label: str) -> OverlaySnapshot:
    """``base`` with the unified diff in ``patch_file`` applied (as ``git apply`` does)."""
    try:
        patch = read_regular(patch_file, MAX_PATCH_BYTES)
    except TooLarge:
        raise SourceError(
            f"{patch_file}: a patch may hold at most {MAX_PATCH_BYTES} bytes"
        ) from None
    except OSError as error:
        raise SourceError(f"{patch_file}: cannot read: {error.strerror or error}") from None
    by_path = {f.path: f for f in base.files()}
    with tempfile.TemporaryDirectory(prefix="archmetrics-sketch-") as scratch:
        folder = Path(scratch) / "tree"
        folder.mkdir()
        touched = _touched(_git_apply(folder, ["--numstat", "-z"], patch))
        for path in touched:
            if path in by_path:
                target = folder / path
                target.parent.mkdir(parents=True, exist_ok=True)
                target.write_bytes(base.read(by_path[path]))
        _git_apply(folder, ["--whitespace=nowarn"], patch)
        changes: dict[str, bytes | None] = {}
        for path in touched:
            target = folder / path
            if target.is_file() and not target.is_symlink():
                changes[path] = target.read_bytes()
            elif path in by_path:
                changes[path] = None
    return OverlaySnapshot(base, changes, label)
