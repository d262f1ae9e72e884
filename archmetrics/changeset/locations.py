"""Locations (thesis p. 73: base, new, framework) and the path globs that assign files to them.

Globs are git's gitignore patterns, read by pathspec and matched by RE2 (:mod:`archmetrics.globs`,
the one dialect of locations, excludes, rule packs and ``.gitignore``; docs/metrics.md).
Paths are POSIX, relative to the repository root.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from enum import StrEnum

from archmetrics.globs import BadPattern, compile_glob, glob_matches


class Location(StrEnum):
    """Where an element sits in the integration (thesis p. 73): B, N or F."""

    BASE = "base"
    NEW = "new"
    FRAMEWORK = "framework"


@dataclass(frozen=True, slots=True)
class LocationRule:
    """One ordered rule: files matching ``pattern`` belong to ``location``."""

    location: Location
    pattern: str


@dataclass(frozen=True, slots=True)
class LocationRules:
    """Ordered location globs (first match wins, unmatched paths are base) and exclude globs."""

    rules: tuple[LocationRule, ...] = ()
    exclude: tuple[str, ...] = ()
    exclude_generated: bool = True  # files whose facts say ``generated`` are left out

    def __post_init__(self) -> None:
        for pattern in (*(r.pattern for r in self.rules), *self.exclude):
            compile_glob(pattern)  # fail early, naming the bad glob

    @classmethod
    def from_mapping(
        cls,
        locations: Mapping[str, Iterable[str]],
        exclude: Iterable[str] = (),
        exclude_generated: bool = True,
    ) -> LocationRules:
        """Rules from a manifest-like mapping, e.g. ``{"new": ["wdb/**"], "base": [...]}``.

        The mapping's order is the rule order: every glob of the first location, then of the
        second, and so on. Unknown location names raise :class:`BadPattern`.
        """
        rules: list[LocationRule] = []
        for name, patterns in locations.items():
            try:
                location = Location(name)
            except ValueError:
                known = ", ".join(loc.value for loc in Location)
                raise BadPattern(f"unknown location {name!r} (known: {known})") from None
            rules.extend(LocationRule(location, p) for p in patterns)
        return cls(tuple(rules), tuple(exclude), exclude_generated)

    def location_of(self, path: str) -> Location:
        """The location of the first rule matching ``path``; base when none does."""
        for rule in self.rules:
            if glob_matches(rule.pattern, path):
                return rule.location
        return Location.BASE

    def unmatched(self, paths: Iterable[str]) -> tuple[str, ...]:
        """The location and exclude globs that match none of ``paths`` (a typo, or quotes
        kept around a glob): each is named in a warning, never silently ignored."""
        left = dict.fromkeys((*(r.pattern for r in self.rules), *self.exclude))
        for path in paths:
            if not left:
                break
            for pattern in [p for p in left if glob_matches(p, path)]:
                del left[pattern]
        return tuple(left)

    def is_excluded(self, path: str) -> str | None:
        """Why ``path`` is left out of the measurement (``exclude:<glob>``), or None."""
        for pattern in self.exclude:
            if glob_matches(pattern, path):
                return f"exclude:{pattern}"
        return None
