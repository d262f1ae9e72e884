"""Where the tables of a TOML document are written: one pass over its text.

``tomllib`` gives values without lines. This scan reads only what places a table: headers
(``[a.b]``, ``[[a.b]]``) and the keys of key/value lines (``a.b = ...``), skipping values,
strings (all four kinds, multi-line ones included), comments and multi-line arrays. It runs
on text ``tomllib`` accepted, but assumes nothing it does not check: on anything it does not
expect it moves on to the next line, and every step moves forward, so it ends in one pass.

A table's place is its *concrete path*: its keys with the position of each array-of-tables
item (``("rules", 1, "to", 0)`` for the first ``[[rules.to]]`` after the second
``[[rules]]``), as ``tomllib``'s document nests them.
"""

from __future__ import annotations

import re
import tomllib

Concrete = tuple[str | int, ...]

_BARE = re.compile(r"[A-Za-z0-9_-]+")
_BLANK = " \t"


class _Text:
    """The text, a position in it and the line of that position."""

    def __init__(self, source: str) -> None:
        self.source, self.pos, self.line = source, 0, 1

    def peek(self, count: int = 1) -> str:
        return self.source[self.pos : self.pos + count]

    def skip_blank(self) -> None:
        while self.pos < len(self.source) and self.source[self.pos] in _BLANK:
            self.pos += 1

    def next_line(self) -> None:
        """Past the end of the current line."""
        end = self.source.find("\n", self.pos)
        self.pos = len(self.source) if end < 0 else end + 1
        self.line += end >= 0

    def skip_string(self) -> None:
        """Past the string starting here (basic, literal, and their multi-line forms)."""
        quote = self.source[self.pos]
        triple = self.peek(3) == quote * 3
        self.pos += 3 if triple else 1
        while self.pos < len(self.source):
            char = self.source[self.pos]
            if char == "\\" and quote == '"':
                self.line += self.peek(2) == "\\\n"
                self.pos += 2
                continue
            if char == "\n":
                if not triple:
                    return  # not TOML: the line ends the string
                self.line += 1
            if char == quote and (not triple or self.peek(3) == quote * 3):
                self.pos += 3 if triple else 1
                while triple and self.peek() == quote:  # up to two quotes end the content
                    self.pos += 1
                return
            self.pos += 1

    def skip_value(self) -> None:
        """Past a value and the end of its line (arrays may span lines)."""
        depth = 0
        while self.pos < len(self.source):
            char = self.source[self.pos]
            if char in "\"'":
                self.skip_string()
                continue
            if char == "#":
                end = self.source.find("\n", self.pos)
                self.pos = len(self.source) if end < 0 else end
                continue
            if char == "\n":
                self.pos += 1
                self.line += 1
                if depth <= 0:
                    return
                continue
            depth += (char in "[{") - (char in "]}")
            self.pos += 1


def _key(text: _Text) -> str | None:
    """One key (bare, "basic" or 'literal') starting here, or None."""
    char = text.peek()
    if char and char in "\"'":  # ("" is in every string)
        start = text.pos
        text.skip_string()
        try:
            value = tomllib.loads(f"k = {text.source[start : text.pos]}")["k"]
        except (tomllib.TOMLDecodeError, RecursionError):
            return None
        return value if isinstance(value, str) else None
    found = _BARE.match(text.source, text.pos)
    if found is None:
        return None
    text.pos = found.end()
    return found.group()


def _keys(text: _Text, limit: int) -> tuple[str, ...] | None:
    """A dotted key starting here (``a."b.c".d``), or None past ``limit`` keys or if none."""
    keys: list[str] = []
    while len(keys) <= limit:
        text.skip_blank()
        key = _key(text)
        if key is None:
            return None
        keys.append(key)
        text.skip_blank()
        if text.peek() != ".":
            return tuple(keys)
        text.pos += 1
    return None


class _Places:
    """Headers and keys read so far, and the concrete paths they place."""

    def __init__(self) -> None:
        self.lines: dict[Concrete, int] = {}
        self.arrays: dict[Concrete, int] = {}  # arrays of tables: items so far
        self.current: Concrete = ()

    def resolve(self, keys: tuple[str, ...], base: Concrete = ()) -> Concrete:
        """``keys`` from ``base``, each array of tables on the way taken at its last item."""
        concrete = base
        for key in keys:
            concrete = (*concrete, key)
            if concrete in self.arrays:
                concrete = (*concrete, self.arrays[concrete] - 1)
        return concrete

    def header(self, keys: tuple[str, ...], array: bool, line: int) -> None:
        if array:
            parent = self.resolve(keys[:-1])
            items = (*parent, keys[-1])
            self.arrays[items] = self.arrays.get(items, 0) + 1
            self.current = (*items, self.arrays[items] - 1)
        else:
            self.current = self.resolve(keys)
        self.lines.setdefault(self.current, line)

    def key(self, keys: tuple[str, ...], line: int) -> None:
        """A key/value line: the tables its dotted keys make, and the value's own place."""
        concrete = self.current
        for key in keys:
            concrete = (*concrete, key)
            self.lines.setdefault(concrete, line)


def table_lines(source: str, limit: int = 32) -> dict[Concrete, int]:
    """The line each table of ``source`` is written on, by concrete path: headers, and keys
    (a dotted key places the tables it makes; a key places the value it holds, so an inline
    table, or the tables of an array, take the key's line). Keys deeper than ``limit`` and
    anything unexpected are skipped."""
    text, places = _Text(source), _Places()
    while text.pos < len(source):
        text.skip_blank()
        char, line = text.peek(), text.line
        if char in ("\n", "\r", "#", ""):
            text.next_line()
            continue
        if char == "[":
            array = text.peek(2) == "[["
            text.pos += 2 if array else 1
            keys = _keys(text, limit)
            close = "]]" if array else "]"
            if keys is not None and text.peek(len(close)) == close:
                places.header(keys, array, line)
            text.next_line()
            continue
        keys = _keys(text, limit)
        text.skip_blank()
        if keys is None or text.peek() != "=":
            text.next_line()
            continue
        places.key(keys, line)
        text.pos += 1
        text.skip_value()
    return places.lines
