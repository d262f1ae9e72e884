"""Reading a file the measured repository names: a regular file only, never blocking, and
never more than a limit.

A configuration file, rule pack, plan, patch or source file is named by the repository, so
it may be a FIFO (reading waits for a writer forever), a device (``/dev/zero`` never ends),
a link to ``/dev/stdin``, or far larger than anything it should be. The file is checked
before it is opened (no device is opened at all), opened without blocking, checked again
on the open descriptor (a file swapped meanwhile is caught), and read only up to its limit
(docs/security.md).
"""

from __future__ import annotations

import os
import stat


class NotRegular(OSError):
    """A path that is no regular file (a FIFO, a device, a folder, a socket)."""


class TooLarge(OSError):
    """A regular file larger than the caller's limit: ``size`` bytes."""

    def __init__(self, path: str | os.PathLike[str], size: int, limit: int) -> None:
        super().__init__(f"{path}: {size:,} bytes, more than the {limit:,} allowed")
        self.size = size
        self.limit = limit


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISFIFO, "a FIFO"), (stat.S_ISCHR, "a character device"),
                       (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"),
                       (stat.S_ISDIR, "a folder")):  # fmt: skip
        if test(mode):
            return name
    return "something else"


def _check(path: str | os.PathLike[str], info: os.stat_result, limit: int | None) -> None:
    if not stat.S_ISREG(info.st_mode):
        raise NotRegular(f"{path}: {_kind(info.st_mode)}, not a regular file")
    if limit is not None and info.st_size > limit:
        raise TooLarge(path, info.st_size, limit)


def read_regular(
    path: str | os.PathLike[str], limit: int | None = None, *, follow: bool = True
) -> bytes:
    """The bytes of the regular file at ``path``: :class:`NotRegular` for anything else,
    :class:`TooLarge` when it holds more than ``limit`` bytes (checked before reading, and
    never more than ``limit + 1`` bytes read), OSError when it cannot be read.
    ``follow``: whether a symbolic link as the last part of ``path`` is followed (if not,
    a link is refused by the system as ``ELOOP``)."""
    _check(path, os.stat(path, follow_symlinks=follow), limit)
    flags = os.O_RDONLY | os.O_NONBLOCK | getattr(os, "O_CLOEXEC", 0)
    if not follow:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    descriptor = os.open(path, flags)
    try:
        _check(path, os.fstat(descriptor), limit)
        with os.fdopen(descriptor, "rb", closefd=False) as stream:
            data = stream.read() if limit is None else stream.read(limit + 1)
    finally:
        os.close(descriptor)
    if limit is not None and len(data) > limit:  # it grew while being read
        raise TooLarge(path, len(data), limit)
    return data
