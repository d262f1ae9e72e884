"""Reviewed functions: the comment ``archmetrics: ignore[vg]`` on a function's first line, or
on the comment lines right above it (Python: its decorators too), exempts that function from
the function thresholds and gates on the fields named (``ignore`` alone: every field).

The parser layer reads it, as it reads every other fact, and records it on the function
(:attr:`~archmetrics.facts.Function.suppressed`); metrics never re-read the text. The
comment changes no number: the function still counts in λ and v_g everywhere, and every
report lists the functions a comment exempted (docs/ci.md, "Reviewed functions").
"""

from __future__ import annotations

import re
from dataclasses import replace

from archmetrics.facts import FileFacts, Function

MARKER = "archmetrics:"
_COMMENT = {"python": ("#",), "c": ("//", "/*"), "cpp": ("//", "/*")}
_IGNORE = re.compile(r"archmetrics:\s*ignore\b(?:\[\s*([a-z_]+(?:\s*,\s*[a-z_]+)*)\s*\])?")
_C_COMMENT_LINE = re.compile(r"^\s*(?://|/\*|\*)")


def _fields(line: str, starts: tuple[str, ...]) -> tuple[str, ...] | None:
    """The fields a marker in a comment of ``line`` names (``*``: every field), or None;
    ``starts``: what opens a comment before it (none needed: the line is all comment)."""
    found = _IGNORE.search(line)
    if found is None or (starts and not any(s in line[: found.start()] for s in starts)):
        return None
    if found.group(1) is None:
        return ("*",)
    return tuple(dict.fromkeys(name.strip() for name in found.group(1).split(",")))


def _above(lines: list[str], start: int, language: str) -> list[str]:
    """The first line of a definition and the comment lines right above it (and, in Python,
    its decorators), nearest first; ``start`` is 1-based."""
    found = [lines[start - 1]] if start <= len(lines) else []
    index = start - 2
    while index >= 0:
        text = lines[index]
        if language == "python":
            stripped = text.lstrip()
            if not stripped.startswith(("#", "@")):
                break
        elif not _C_COMMENT_LINE.match(text):
            break
        found.append(text)
        index -= 1
    return found


def with_suppressions(facts: FileFacts, source: str) -> FileFacts:
    """``facts`` with each function's suppression comment recorded; the facts unchanged
    when the source names none (a substring search decides, in C)."""
    starts = _COMMENT.get(facts.language)
    if starts is None or not facts.functions or MARKER not in source:
        return facts
    lines = source.split("\n")
    functions: list[Function] = []
    for function in facts.functions:
        named: tuple[str, ...] = ()
        for number, line in enumerate(_above(lines, function.span.start, facts.language)):
            # a C comment line above may continue a block comment: it is all comment
            fields = _fields(line, () if number and facts.language != "python" else starts)
            if fields is not None:
                named = fields
                break
        functions.append(function._replace(suppressed=named) if named else function)
    return replace(facts, functions=tuple(functions))
