"""Text that is safe to print: no control characters from the measured repository.

File names, function names and warnings quote the measured code, which in CI is written by a
stranger. An escape sequence in one of them (``\\x1b]...``) would drive the reader's terminal,
and a lone surrogate (an undecodable byte) cannot be written as UTF-8 at all. Every such
character is shown as a backslash escape instead; layout characters (tab, newline, carriage
return) are kept in reports and escaped in one-line messages.
"""

from __future__ import annotations

import re

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
