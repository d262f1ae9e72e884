"""One glob dialect for every pattern archmetrics reads: git's gitignore patterns.

Location and exclude globs (configuration, manifests, ``--new``, ``--framework``,
``--exclude``), the ``match`` names of rule packs and a plain folder's ``.gitignore`` files are
all read by pathspec's :class:`~pathspec.GitIgnoreSpec` (git's own rules, edge cases
included) and matched by RE2, pathspec's ``re2`` backend. The patterns come from untrusted
input (a repository's configuration and rule packs), and pathspec's regular expressions
backtrack under Python's ``re``: ``*a*a*a*a*b`` took 7 s against a 200-character name, one
more star 148 s. RE2 matches in time linear in the pattern and the path (a 1,000-star glob
against a 100,000-character path: 0.1 s), so no star bound is needed; a glob is at most
:data:`MAX_GLOB_CHARS` long so that compiling it stays small. docs/metrics.md ("Locations and
globs") has the dialect and every difference from the one archmetrics had before.
"""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterable
from functools import lru_cache
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from pathspec import GitIgnoreSpec

MAX_GLOB_CHARS = 1024
"""The longest glob a configuration, manifest, rule pack or command line may give."""


class BadPattern(ValueError):
    """A location, exclude or rule glob that cannot be used; the message names it."""


def _refusal(pattern: str) -> str | None:
    """Why ``pattern`` is refused before pathspec reads it, or None."""
    if not pattern.strip().strip("/"):
        return "empty or only '/'"
    if len(pattern) > MAX_GLOB_CHARS:
        return f"longer than {MAX_GLOB_CHARS} characters"
    if pattern.startswith("!"):
        return "a '!' negation: order the rules instead"
    if pattern.startswith("#"):
        return "'#' starts a comment in gitignore: write \\# for a name that starts with #"
    return None


def gitignore_file(lines: Iterable[str]) -> GitIgnoreSpec:
    """A ``.gitignore`` file's lines as git reads them: a line that cannot be used (a bad
    range, a trailing backslash) is skipped, as git skips it, not the whole file."""
    lines = list(lines)
    try:
        return gitignore_spec(lines)
    except ValueError:
        return gitignore_spec(line for line in lines if _usable(line))


def _usable(line: str) -> bool:
    try:
        gitignore_spec([line])
    except ValueError:
        return False
    return True


def gitignore_spec(lines: Iterable[str]) -> GitIgnoreSpec:
    """Lines of gitignore patterns as git reads them, matched by RE2. Raises ValueError for
    a pattern pathspec or RE2 cannot take."""
    from pathspec import GitIgnoreSpec  # 30 ms to import: only where a glob is compiled
    from re2 import error as re2_error

    with warnings.catch_warnings():  # pathspec compiles with `re` too, which warns on [[
        warnings.simplefilter("ignore", FutureWarning)
        try:
            return GitIgnoreSpec.from_lines(list(lines), backend="re2")
        except (re.error, re2_error) as error:  # a bad range; what RE2 cannot compile
            raise ValueError(str(error)) from None


@lru_cache(maxsize=4096)
def compile_glob(pattern: str) -> GitIgnoreSpec:
    """The matcher of one glob; :class:`BadPattern`, naming the glob, when it cannot be used
    (including every pattern git would silently ignore: ``[z-a]``, an unclosed ``[``)."""
    problem = _refusal(pattern)
    if problem is None:
        try:
            spec = gitignore_spec([pattern])
        except ValueError as error:
            problem = str(error)
        else:
            if spec.patterns and spec.patterns[0].include:
                return spec
            problem = "git would ignore it: a bad range or an unclosed ["
    raise BadPattern(f"unusable glob {pattern!r} ({problem})")


@lru_cache(maxsize=1024)
def compile_globs(patterns: tuple[str, ...]) -> GitIgnoreSpec:
    """One matcher for several globs: a path matches it when it matches any of them."""
    for pattern in patterns:
        compile_glob(pattern)  # each refused by name
    return gitignore_spec(patterns)


def glob_matches(pattern: str, path: str) -> bool:
    """True when ``path`` (POSIX, relative) is matched by ``pattern``: the path itself or a
    folder it is in (``wdb`` and ``wdb/`` match ``wdb/x.py``; ``client/`` never a file)."""
    return compile_glob(pattern).match_file(normalize_path(path))


def normalize_path(path: str) -> str:
    """A repository-relative POSIX path: backslashes become ``/``, ``./`` and ``/`` trimmed."""
    path = path.replace("\\", "/")
    while path.startswith("./"):
        path = path[2:]
    return path.lstrip("/")
