"""Locations (thesis p. 73: base, new, framework) and the path globs that assign files to them.

Glob semantics are gitignore-like (documented in docs/metrics.md, tested in
tests/changeset/test_locations.py). Paths are POSIX, relative to the repository root.

* ``*`` matches any run of characters except ``/``; ``?`` one character except ``/``;
  ``[abc]``/``[!abc]`` a character class; ``\\x`` the literal ``x``.
* A pattern with no ``/`` except a trailing one matches at any depth (``*.py`` matches
  ``a/b/c.py``); a pattern with a ``/`` at the start or in the middle is anchored at the root
  (``src/*.c`` does not match ``lib/src/a.c``); a leading ``/`` only anchors.
* ``**/`` at the start or ``/**/`` in the middle match zero or more directories; a trailing
  ``/**`` matches everything inside; any other ``**`` is a plain ``*``.
* A pattern that matches a directory matches every file below it (``wdb`` and ``wdb/`` match
  ``wdb/x.py``); a trailing ``/`` matches directories only, never a file of that name.
* Matching is case-sensitive; negation (``!``) is not supported: order the rules instead.
"""

from __future__ import annotations

import functools
import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from enum import StrEnum


class Location(StrEnum):
    """Where an element sits in the integration (thesis p. 73): B, N or F."""

    BASE = "base"
    NEW = "new"
    FRAMEWORK = "framework"


class BadPattern(ValueError):
    """A location or exclude glob that cannot be used; the message names it."""


def _class(pattern: str, start: int) -> tuple[str, int] | None:
    """Translate the ``[...]`` class opening at ``start``; None when it never closes."""
    i = start + 1
    negate = i < len(pattern) and pattern[i] in "!^"
    if negate:
        i += 1
    if i < len(pattern) and pattern[i] == "]":
        i += 1  # a leading ] is a literal member
    end = pattern.find("]", i)
    if end < 0:
        return None
    body = pattern[start + 1 + negate : end].replace("/", "")
    body = body.replace("\\", "\\\\").replace("[", "\\[").replace("]", "\\]")
    return ("[^/" if negate else "[") + body + "]", end + 1


def _pieces(segment: str) -> list[str | None]:
    """One path component of a glob as regex pieces, with None for each run of ``*``."""
    out: list[str | None] = []
    i = 0
    while i < len(segment):
        char = segment[i]
        if char == "*":
            if not out or out[-1] is not None:
                out.append(None)
        elif char == "?":
            out.append("[^/]")
        elif char == "[" and (translated := _class(segment, i)) is not None:
            out.append(translated[0])
            i = translated[1] - 1
        elif char == "\\" and i + 1 < len(segment):
            i += 1
            out.append(re.escape(segment[i]))
        else:
            out.append(re.escape(char))
        i += 1
    return out


def _segment(segment: str) -> str:
    """Regex for one path component of a glob (``*``, ``?``, classes, escapes).

    As :func:`fnmatch.translate` does, a ``*`` followed by more text and another ``*`` takes
    the leftmost match of that text atomically (``(?>[^/]*?text)``): the next ``*`` can absorb
    whatever a later match would have skipped, so nothing is lost, and a glob with many stars
    is matched in time linear in their number instead of backtracking through every split."""
    pieces = _pieces(segment)
    stars = [i for i, piece in enumerate(pieces) if piece is None]
    out: list[str] = []
    for i, piece in enumerate(pieces):
        if piece is not None:
            continue
        following = "".join(p for p in pieces[i + 1 : _next(stars, i, len(pieces))] if p)
        out.append(f"(?>[^/]*?{following})" if i != stars[-1] else "[^/]*" + following)
    head = "".join(p for p in pieces[: stars[0] if stars else len(pieces)] if p)
    return head + "".join(out)


def _next(stars: list[int], star: int, end: int) -> int:
    later = [s for s in stars if s > star]
    return later[0] if later else end


@functools.lru_cache(maxsize=1024)
def compile_glob(pattern: str) -> re.Pattern[str]:
    """The regex a gitignore-like glob stands for, matched against whole relative paths.

    Directories work like stars: the segments between two ``**`` are matched at their
    leftmost place atomically (see :func:`_segment`), so no glob backtracks exponentially."""
    if not pattern.strip("/") or pattern.startswith("!"):
        raise BadPattern(f"unusable glob {pattern!r} (empty, '/' or a '!' negation)")
    directory_only = pattern.endswith("/")
    body = pattern.rstrip("/")
    segments = body.lstrip("/").split("/")
    if "/" not in body:
        segments = ["**", *segments]
    segments = [s for i, s in enumerate(segments) if s != "**" or segments[i - 1 : i] != ["**"]]
    blocks: list[list[str]] = [[]]  # the segments before the first ** and between any two
    for segment in segments:
        if segment == "**":
            blocks.append([])
        else:
            blocks[-1].append(_segment(segment))
    regex = _blocks(blocks)
    if segments[-1] == "**":
        tail = ""
    elif directory_only:
        tail = "/.+"
    else:
        tail = "(?:/.+)?"
    try:
        return re.compile(regex + tail)
    except re.error as error:
        raise BadPattern(f"unusable glob {pattern!r} ({error})") from None


def _blocks(blocks: list[list[str]]) -> str:
    """Regex for segment blocks separated by ``**`` (``blocks[0]`` is before the first)."""
    parts = ["/".join(blocks[0]) + ("/" if blocks[0] and len(blocks) > 1 else "")]
    for index, block in enumerate(blocks[1:], start=1):
        last = index == len(blocks) - 1
        if last and not block:  # a trailing **: everything inside
            parts.append(".+")
        elif last:
            parts.append("(?:[^/]+/)*" + "/".join(block))
        else:
            parts.append("(?>(?:[^/]+/)*?" + "".join(f"{b}/" for b in block) + ")")
    return "".join(parts)


def glob_matches(pattern: str, path: str) -> bool:
    """True when ``path`` (POSIX, relative) is matched by the gitignore-like ``pattern``."""
    return compile_glob(pattern).fullmatch(normalize_path(path)) is not None


def normalize_path(path: str) -> str:
    """A repository-relative POSIX path: backslashes become ``/``, ``./`` and ``/`` trimmed."""
    path = path.replace("\\", "/")
    while path.startswith("./"):
        path = path[2:]
    return path.lstrip("/")


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

    def is_excluded(self, path: str) -> str | None:
        """Why ``path`` is left out of the measurement (``exclude:<glob>``), or None."""
        for pattern in self.exclude:
            if glob_matches(pattern, path):
                return f"exclude:{pattern}"
        return None
