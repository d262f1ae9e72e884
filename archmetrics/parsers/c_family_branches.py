"""Preprocessor conditionals read without their directives, where the file as written does
not parse (docs/metrics.md, "Macros and #if").

tree-sitter parses the text before preprocessing and wants every ``#if`` branch to hold
whole declarations or statements. Real code splits one statement between branches
(``#ifdef _WIN32 / if (s == INVALID_SOCKET) / #else / if (s < 0) / #endif / { ... }``), and
then everything from there to the end of the file may become one ERROR node. This module
builds *spellings* of a file: the same bytes with every conditional directive line
overwritten by spaces (every offset and line stays), and either every branch kept, as
written (``ALL``), or in each ``#if`` group only its k-th branch kept (the others blanked
too). c_family.py parses the spellings and, per damaged region of the file as written,
takes the spelling that reads that region with the least damage.

The directives a spelling blanks still count where lizard counts them (``#if``, ``#ifdef``,
``#elif``... in a function body are decisions): ``Spelling.decisions`` gives them from the
text. Only the groups near the damage are blanked (``Conditionals.near``), so tree-sitter
reparses only around it.
"""

from __future__ import annotations

import bisect
import itertools
import re
from collections.abc import Iterable
from dataclasses import dataclass

from archmetrics.parsers.c_family_macros import literal_spans
from archmetrics.parsers.c_family_text import blank

_DIRECTIVE = re.compile(rb"(?m)^[ \t]*#[ \t]*(ifdef|ifndef|if|elifdef|elifndef|elif|else|endif)\b")
_OPENS = frozenset({"if", "ifdef", "ifndef"})
_MIDDLE = frozenset({"elif", "elifdef", "elifndef", "else"})
DECIDING = frozenset({"if", "ifdef", "ifndef", "elif", "elifdef", "elifndef"})

ALL = -1
"""The spelling that keeps every branch as written and blanks only the directive lines."""


@dataclass(frozen=True, slots=True)
class Directive:
    """A conditional directive line: ``start`` is its ``#``; ``end`` the end of its line and
    continuation lines (comments on them are kept when it is blanked)."""

    start: int
    end: int
    keyword: str
    line: int  # 1-based


@dataclass(frozen=True, slots=True)
class Group:
    """One ``#if`` ... ``#endif`` group: its directives in order, the last an ``#endif``.
    Branch i is the text between directive i and directive i + 1."""

    directives: tuple[Directive, ...]

    @property
    def branches(self) -> int:
        return len(self.directives) - 1


_COMMENT = re.compile(rb"//[^\n]*|/\*(?:[^*]|\*(?!/))*\*/")


def _directive_end(data: bytes, start: int) -> int:
    """Where the directive at ``start`` ends: the end of its line and continuation lines,
    or the start of a block comment that runs past them. Each line is looked at once."""
    line = start
    while True:
        newline = data.find(b"\n", line)
        if newline < 0:
            return len(data)
        opened = data.rfind(b"/*", line, newline)
        if opened >= 0 and data.find(b"*/", opened + 2, newline) < 0:
            return opened
        last = newline - 1 if newline > line and data[newline - 1] == 13 else newline  # \r
        if last <= line or data[last - 1] != 92:  # no `\` before the line's end
            return newline
        line = newline + 1


class Conditionals:
    """The ``#if`` groups of a file, outside comments and string literals. Groups that are
    never closed, and stray ``#else``/``#endif`` lines, are left as they are."""

    def __init__(self, data: bytes) -> None:
        self.data = data
        literals = literal_spans(data)
        groups: list[Group] = []
        stack: list[list[Directive]] = []
        line, last = 1, 0
        ended = 0  # where the last directive (and its continuation lines) ended
        for found in _DIRECTIVE.finditer(data):
            start = found.start()
            if start < ended or start in literals:
                continue
            line += data.count(b"\n", last, start)
            last = start
            hash_at = data.index(b"#", start)
            keyword = found.group(1).decode()
            directive = Directive(hash_at, _directive_end(data, hash_at), keyword, line)
            ended = directive.end
            if keyword in _OPENS:
                stack.append([directive])
            elif stack and keyword in _MIDDLE:
                stack[-1].append(directive)
            elif stack and keyword == "endif":
                opened = stack.pop()
                opened.append(directive)
                groups.append(Group(tuple(opened)))
        self.groups = tuple(sorted(groups, key=lambda g: g.directives[0].start))

    def near(self, spans: list[tuple[int, int]] | None) -> list[Group]:
        """The groups with a directive in one of ``spans`` (all of them for None)."""
        if spans is None:
            return list(self.groups)
        return self.near_in(self.groups, spans)

    @staticmethod
    def near_in(groups: Iterable[Group], spans: list[tuple[int, int]]) -> list[Group]:
        """Of ``groups``, those with a directive in one of ``spans``."""
        ordered = sorted(spans)
        starts = [start for start, _ in ordered]
        reach = list(itertools.accumulate((end for _, end in ordered), max))

        def inside(offset: int) -> bool:
            index = bisect.bisect_right(starts, offset) - 1
            return index >= 0 and offset < reach[index]

        return [g for g in groups if any(inside(d.start) for d in g.directives)]

    def spelling(
        self, branch: int, groups: list[Group], only: list[Group] | None = None
    ) -> Spelling:
        """The file with the directive lines of ``groups`` blanked and, unless ``branch``
        is ``ALL``, in each of them (or of those also in ``only``) every branch but the
        ``branch``-th blanked too (a group with fewer keeps its last)."""
        out = bytearray(self.data)
        set_aside: list[tuple[int, int]] = []
        reduced = set(groups if only is None else only)
        for group in groups:
            directives = group.directives
            for directive in directives:
                _blank_code(out, directive.start, directive.end)
            if branch == ALL or group not in reduced:
                continue
            keep = min(branch, group.branches - 1)
            for index in range(group.branches):
                if index != keep:
                    start, end = directives[index].end, directives[index + 1].start
                    blank(out, start, end)
                    set_aside.append((start, end))
        decisions = [
            (directive.start, "#" + directive.keyword, directive.line)
            for group in groups
            for directive in group.directives
            if directive.keyword in DECIDING
        ]
        return Spelling(bytes(out), set_aside, sorted(decisions))


@dataclass(frozen=True, slots=True)
class Spelling:
    """A file's bytes with some #if directives (and branches) blanked: ``set_aside``, the
    branches blanked; ``decisions``, (offset, kind, line) of each blanked directive that
    is a decision where lizard counts one (``#if``, ``#ifdef``, ``#elif``...)."""

    data: bytes
    set_aside: list[tuple[int, int]]
    decisions: list[tuple[int, str, int]]


def _blank_code(out: bytearray, start: int, end: int) -> None:
    """Blank ``[start, end)`` but the comments in it."""
    at = start
    for comment in _COMMENT.finditer(out, start, end):
        blank(out, at, comment.start())
        at = comment.end()
    blank(out, at, end)
