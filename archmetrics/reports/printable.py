"""Text that is safe to print: no control characters from the measured repository.

File names, function names and warnings quote the measured code, which in CI is written by a
stranger. An escape sequence in one of them (``\\x1b]...``) would drive the reader's terminal,
and a lone surrogate (an undecodable byte) cannot be written as UTF-8 at all. Every such
character is shown as a backslash escape instead; layout characters (tab, newline, carriage
return) are kept in reports and escaped in one-line messages.
"""

from __future__ import annotations

import re
from collections.abc import Sequence

_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f\ud800-\udfff]")
_LAYOUT = re.compile(r"[\t\n\r\u2028\u2029]")


def _escape(found: re.Match[str]) -> str:
    code = ord(found.group())
    return f"\\x{code:02x}" if code < 0x100 else f"\\u{code:04x}"


def printable(text: str) -> str:
    """``text`` with every control character but tab, newline and return escaped."""
    return _CONTROL.sub(_escape, text)


def one_line(text: str, limit: int = 2000) -> str:
    """``text`` as one printable line of at most ``limit`` characters."""
    line = _LAYOUT.sub(_escape, printable(text))
    return line if len(line) <= limit else line[: limit - 1] + "…"


SHOWN_WARNINGS = 20
"""Warnings a table or Markdown report lists before it summarises the rest (JSON lists all)."""


def shown_warnings(warnings: Sequence[object], limit: int = SHOWN_WARNINGS) -> list[str]:
    """The first ``limit`` warnings as text, then one line counting the rest and the files
    they are in (a warning's ``path``, when it has one)."""
    files = {getattr(warning, "path", None) for warning in warnings[limit:]} - {None}
    where = f" in {len(files)} files" if files else ""
    return shown_lines(
        warnings, limit, "... and {count} more warnings" + where + " (--format json lists them all)"
    )


def shown_lines(items: Sequence[object], limit: int, more: str) -> list[str]:
    """The first ``limit`` items as text, then ``more`` (its ``{count}``: how many are left
    out) when there are more: what a table, Markdown or stderr lists of a long list."""
    lines = [str(item) for item in items[:limit]]
    if len(items) > limit:
        lines.append(more.format(count=len(items) - limit))
    return lines
