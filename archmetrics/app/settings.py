"""The configuration a measurement runs under: the repository's (or folder's) settings, with
what the caller adds (``exclude`` globs), merged once for the command line and the API."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path

from archmetrics.changeset.gates import GateOrigin
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


def gate_origins(settings: Settings, root: Path) -> tuple[GateOrigin, ...]:
    """Where each configured gate is written: the configuration file, relative to ``root``
    (the repository's top), and the gate's line. None when the settings were not read from
    a file inside ``root``."""
    source = Path(settings.source)
    if not source.is_file():
        return ()
    try:
        path = source.resolve().relative_to(root.resolve()).as_posix()
    except ValueError:
        return ()
    lines = settings.gate_lines or (1,) * len(settings.gates)
    return tuple(
        GateOrigin(gate.strip(), path, line)
        for gate, line in zip(settings.gates, lines, strict=True)
    )
