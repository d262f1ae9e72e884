"""The configuration a measurement runs under: the repository's (or folder's) settings, with
what the caller adds (``exclude`` globs), merged once for the command line and the API."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path

from archmetrics.config import Settings, load_settings
from archmetrics.globs import compile_glob


def repo_root(path: Path) -> Path:
    """The top of the git repository holding ``path``, or its folder outside git."""
    from archmetrics.sources.checkout import open_checkout

    return open_checkout(path if path.is_dir() else path.parent).root


def settings_for(path: Path, exclude: Sequence[str] = ()) -> Settings:
    """The settings of the repository or folder holding ``path``, with ``exclude`` after the
    configured globs (each checked now: :class:`~archmetrics.globs.BadPattern`
    names a bad one)."""
    return settings_at(repo_root(path), exclude)


def settings_at(root: Path, exclude: Sequence[str] = ()) -> Settings:
    """The settings of the repository or folder whose top is ``root`` (a command that has
    opened it already knows its top), with ``exclude`` as for :func:`settings_for`."""
    settings = load_settings(root)
    for glob in exclude:
        compile_glob(glob)
    if not exclude:
        return settings
    return dataclasses.replace(settings, exclude=settings.exclude + tuple(exclude))
