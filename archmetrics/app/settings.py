"""The configuration a measurement runs under: the repository's (or folder's) settings, with
what the caller adds (``exclude`` globs) and what the caller allows (limits raised above
their defaults), merged once for the command line and the API."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from archmetrics.changeset.gates import GateOrigin
from archmetrics.config import (
    CONFIG_FILES,
    MAX_CONFIG_BYTES,
    ConfigError,
    LimitSettings,
    Settings,
    load_settings,
    parse_toml,
    read_document,
    settings_from_document,
)
from archmetrics.globs import compile_glob
from archmetrics.sources.checkout import Checkout
from archmetrics.sources.snapshot import WORKTREE

_DEFAULT_LIMITS = LimitSettings()


def repo_root(path: Path) -> Path:
    """The top of the git repository holding ``path``, or its folder outside git."""
    from archmetrics.sources.checkout import open_checkout

    return open_checkout(path if path.is_dir() else path.parent).root


def settings_for(
    path: Path, exclude: Sequence[str] = (), allow_raised_limits: bool = False
) -> Settings:
    """The settings of the repository or folder holding ``path``, with ``exclude`` after the
    configured globs (each checked now: :class:`~archmetrics.globs.BadPattern`
    names a bad one) and its limits as :func:`within_defaults` allows."""
    return settings_at(repo_root(path), exclude, allow_raised_limits)


def settings_at(
    root: Path, exclude: Sequence[str] = (), allow_raised_limits: bool = False
) -> Settings:
    """The settings of the repository or folder whose top is ``root`` (a command that has
    opened it already knows its top), with ``exclude`` as for :func:`settings_for`."""
    return merged(load_settings(root), exclude, allow_raised_limits)


def settings_of(
    checkout: Checkout,
    spec: str | None,
    exclude: Sequence[str] = (),
    allow_raised_limits: bool = False,
) -> Settings:
    """The configuration of the snapshot ``spec`` names, merged as :func:`merged` says: a
    revision's (or the index's) from its own ``archmetrics.toml`` / ``pyproject.toml``
    blobs, its rule packs read from there too (``revision``); the files on disk for None
    or WORKTREE; none (the defaults) for EMPTY or a revision without one."""
    if spec is None or spec == WORKTREE or checkout.repo is None:
        return merged(load_settings(checkout.root), exclude, allow_raised_limits)
    found = Settings(source=f"{spec} (no configuration)", revision=spec)
    for name in CONFIG_FILES:
        data = checkout.file_at(spec, name, MAX_CONFIG_BYTES)
        if data is None:
            continue
        source = f"{spec}:{name}"
        text = data.decode("utf-8", "replace")
        settings = settings_from_document(parse_toml(data, source), name, source, text)
        if settings is not None:
            found = dataclasses.replace(settings, revision=spec)
            break
    return merged(found, exclude, allow_raised_limits)


def settings_from_file(
    path: Path, exclude: Sequence[str] = (), allow_raised_limits: bool = False
) -> Settings:
    """The configuration in the file ``path`` the runner names (``--config-from FILE``): a
    ``pyproject.toml`` by that name (its ``[tool.archmetrics]``), else an
    ``archmetrics.toml``; its rule packs are read from the files on disk."""
    source = str(path)
    document, text = read_document(path)
    name = "pyproject.toml" if path.name == "pyproject.toml" else "archmetrics.toml"
    settings = settings_from_document(document, name, source, text)
    if settings is None:
        raise ConfigError(f"{source}: no [tool.archmetrics] table")
    return merged(settings, exclude, allow_raised_limits)


def merged(
    settings: Settings, exclude: Sequence[str] = (), allow_raised_limits: bool = False
) -> Settings:
    """``settings`` (from wherever they were read) with the caller's ``exclude`` globs and
    its limits as :func:`within_defaults` allows."""
    for glob in exclude:
        compile_glob(glob)
    if exclude:
        settings = dataclasses.replace(settings, exclude=settings.exclude + tuple(exclude))
    return settings if allow_raised_limits else within_defaults(settings)


def within_defaults(settings: Settings) -> Settings:
    """``settings`` with every limit the configuration raised above its default put back to
    the default, each one named in ``notices``: the repository is not trusted to make its
    own run costlier than the defaults (``--allow-raised-limits`` lets it, up to the
    ceilings of config.py; docs/security.md)."""
    changed: dict[str, Any] = {}
    notices = []
    for field in dataclasses.fields(LimitSettings):
        value, default = getattr(settings.limits, field.name), getattr(_DEFAULT_LIMITS, field.name)
        if value > default:
            changed[field.name] = default
            key = field.name.replace("_", "-")
            notices.append(
                f"{settings.source}: limits.{key} = {value:g} is above the default {default:g};"
                " the default applies (--allow-raised-limits lets the configuration raise it)"
            )
    if not changed:
        return settings
    limits = dataclasses.replace(settings.limits, **changed)
    return dataclasses.replace(settings, limits=limits, notices=settings.notices + tuple(notices))


def gate_origins(settings: Settings, root: Path) -> tuple[GateOrigin, ...]:
    """Where each configured gate is written: the configuration file, relative to ``root``
    (the repository's top), and the gate's line. None when the settings were not read from
    a file inside ``root``."""
    source = Path(settings.source)
    if settings.revision is not None:  # read from the revision's blob ``REV:NAME``
        path = settings.source.rpartition(":")[2]
    elif not source.is_file():
        return ()
    else:
        try:
            path = source.resolve().relative_to(root.resolve()).as_posix()
        except ValueError:
            return ()
    lines = settings.gate_lines or (1,) * len(settings.gates)
    return tuple(
        GateOrigin(gate.strip(), path, line)
        for gate, line in zip(settings.gates, lines, strict=True)
    )
