"""Paths named on the command line, followed only as far as the repository holding them.

The runner names a path (``scan src``, ``-C repo``, ``estimate plan.toml``, ``-o out.md``);
the repository decides what its parts are. A committed ``src -> $HOME`` would make
``scan src`` measure the home folder and publish its file and function names, and a
committed ``report.md -> ~/.bashrc`` would make ``-o report.md`` write there. So each
symbolic link met on the way to a path must lead to a place inside the repository that holds
the link (the innermost folder above it holding ``.git``; outside git, the folder archmetrics
runs in, when the link lies in it). A ``..`` the runner wrote is the runner's word and is
followed as the system follows it. (docs/security.md)
"""

from __future__ import annotations

import os
import stat
from pathlib import Path

from archmetrics.sources.snapshot import SourceError


def _within(path: str, top: str) -> bool:
    return path == top or path.startswith(top.rstrip(os.sep) + os.sep)


def _holding_repository(folder: str, cwd: str) -> str | None:
    """The innermost folder at or above the real folder ``folder`` that holds ``.git``;
    else ``cwd`` (real) if ``folder`` lies in it; else None."""
    current = folder
    while True:
        if os.path.lexists(os.path.join(current, ".git")):
            return current
        parent = os.path.dirname(current)
        if parent == current:
            return cwd if _within(folder, cwd) else None
        current = parent


def confined(path: Path, *, must_exist: bool = False) -> Path:
    """``path`` with every symbolic link on it followed, after checking that each one leads
    to a place inside the repository holding it; a one-line :class:`SourceError` names the
    first that leads out. ``must_exist``: a missing part is an error too (else the rest of
    the path is taken as written)."""
    cwd = os.path.realpath(os.getcwd())
    current = os.sep if path.is_absolute() else cwd
    parts = list(path.parts[1:] if path.is_absolute() else path.parts)
    for depth, part in enumerate(parts):
        if part == "..":
            current = os.path.dirname(current)
            continue
        candidate = os.path.join(current, part)
        if not os.path.islink(candidate):
            if not os.path.lexists(candidate):
                if must_exist:
                    raise SourceError(f"{path}: no such file or directory")
                return Path(os.path.join(candidate, *parts[depth + 1 :]))
            current = candidate
            continue
        top = _holding_repository(current, cwd)
        if top is None:  # the runner's own link (/dev/stdin, a folder of theirs)
            current = os.path.realpath(candidate)
            continue
        target = os.path.realpath(candidate)
        if _within(target, top):
            try:
                target = os.path.realpath(candidate, strict=True)
            except OSError as error:  # a loop, a dangling link
                raise SourceError(f"{path}: cannot resolve {candidate}: {error.strerror}") from None
        if not _within(target, top):
            raise SourceError(
                f"{path}: {candidate} is a symbolic link leading out of {top} (to {target});"
                " not followed"
            )
        current = target
    return Path(current)


def write_confined(path: Path, data: bytes) -> None:
    """Write ``data`` to the file ``path`` (created or replaced), its folder reached as
    :func:`confined` allows. Inside a repository the file itself must not be a symbolic
    link (a committed ``report.md -> .git/config`` is not written through) nor anything but
    a regular file; outside one it is the runner's (``-o /dev/stdout``). OSError as the
    system gives it; SourceError for a path refused."""
    folder = confined(path.parent, must_exist=True)
    target = folder / path.name
    inside = _holding_repository(str(folder), os.path.realpath(os.getcwd())) is not None
    if inside and os.path.islink(target):
        raise SourceError(f"{path}: a symbolic link inside the repository; not written through")
    flags = os.O_WRONLY | os.O_CREAT | getattr(os, "O_CLOEXEC", 0)
    if inside:
        flags |= os.O_NONBLOCK | getattr(os, "O_NOFOLLOW", 0)
    descriptor = os.open(target, flags, 0o666)
    try:
        if inside and not stat.S_ISREG(os.fstat(descriptor).st_mode):
            raise SourceError(f"{path}: not a regular file; not written")
        if stat.S_ISREG(os.fstat(descriptor).st_mode):
            os.ftruncate(descriptor, 0)
        with os.fdopen(descriptor, "wb", closefd=False) as stream:
            stream.write(data)
    finally:
        os.close(descriptor)
