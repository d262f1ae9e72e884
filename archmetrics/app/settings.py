"""The configuration a measurement runs under: the repository's (or folder's) settings, with
what the caller adds (``exclude`` globs) and what the caller allows (limits raised above
their defaults), merged once for the command line and the API."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from archmetrics.config import LimitSettings, Settings, load_settings
from archmetrics.globs import compile_glob

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
