"""File names as reports show them: git's escapes for the names that need them.

A file name is bytes. Python reads an undecodable byte as a lone surrogate, which no UTF-8
output can hold, and a name may hold a newline, an escape sequence or other control
characters that would break a table or a terminal. Such a name is escaped as git escapes
it (``core.quotePath``), without git's surrounding double quotes, so its ending still names
its language: a backslash is ``\\\\``, the C escapes (``\\n``, ``\\t`` ...) stand for
themselves, and any other control character, and each byte that is not part of UTF-8, is a
backslash and three octal digits. Since every backslash is escaped, two names never look
alike. Every other name, non-ASCII letters included, is shown as it is. The escaped form is
what facts, reports and JSON carry; the bytes on disk are read through the snapshot that
escaped them (docs/security.md).
"""

from __future__ import annotations

import re

_NEEDS_QUOTING = re.compile(r"[\x00-\x1f\x7f-\x9f\\\udc80-\udcff\u2028\u2029]")
_C_ESCAPES = {"\a": "\\a", "\b": "\\b", "\t": "\\t", "\n": "\\n", "\v": "\\v", "\f": "\\f",
              "\r": "\\r", "\\": "\\\\"}  # fmt: skip


def _escape(char: str) -> str:
    if char in _C_ESCAPES:
        return _C_ESCAPES[char]
    return "".join(f"\\{byte:03o}" for byte in char.encode("utf-8", "surrogateescape"))


def quote_path(path: str) -> str:
    """``path`` as reports show it: unchanged, or escaped when it needs to be."""
    if not _NEEDS_QUOTING.search(path):
        return path
    return _NEEDS_QUOTING.sub(lambda found: _escape(found.group()), path)
