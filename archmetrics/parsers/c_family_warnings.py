"""One warning per region of a C/C++ file whose facts were lost or estimated, saying what
(docs/metrics.md, "Warnings").

A region's warning counts what the token reading (c_family_tokens.py) finds there against
what the facts hold: the functions read from tokens alone, the functions whose decisions
the tokens gave, a shape the tree took for a function that is none, and the statements
and call sites the token reading sees there beyond those the facts counted. A region
where both readings agree gets no warning: a damaged line whose facts were all read (a
function head with a macro the tree stumbled on) lost nothing.
"""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field

from archmetrics.facts import ParseWarning
from archmetrics.parsers.c_family_tokens import TokenReading
from archmetrics.parsers.c_family_trust import Area, Lines

_MAX_WARNINGS = 20
_CAUSE_LINES = 3
_ASM = re.compile(rb"\b(?:_asm|__asm|asm|__asm__)\s*+(?:volatile\s*+)?\{")
_CONDITIONAL = re.compile(rb"(?m)^[ \t]*+\#[ \t]*+(?:if|ifdef|ifndef|elif|else)\b")
_CAUSES = {
    "nested": "a statement read as a function definition (a macro call without its ';'?)",
    "stray": "a block outside any function (a K&R definition or a macro?)",
    "keyword": "a macro read as a function's head",
    "head": "macro calls without their ';' read as a function's head",
    "branch": "an #if branch read apart from the others",
    "braced": "a function's body read as a brace initializer",
}


@dataclass(frozen=True, slots=True)
class Counted:
    """The first lines of what the facts counted, sorted: decisions, statements, calls."""

    decisions: list[int] = field(default_factory=list)
    statements: list[int] = field(default_factory=list)
    calls: list[int] = field(default_factory=list)


def _between(lines: list[int], first: int, last: int) -> int:
    return bisect.bisect_right(lines, last) - bisect.bisect_left(lines, first)


def _plural(count: int, what: str) -> str:
    return f"{count} {what}" if count == 1 else f"{count} {what}s"


def _cause(area: Area, reading: TokenReading, data: bytes) -> str:
    """What the parser could not read in ``area``, in a reader's words."""
    start, end = area.start, area.end
    before = start
    for _ in range(_CAUSE_LINES):  # a cause may stand a few lines before what it broke
        before = max(0, data.rfind(b"\n", 0, max(0, before - 1)))
    if any(before <= at < end for at in reading.defines_in_blocks):
        return "a #define inside an initializer"
    if _ASM.search(data, start, end):
        return "inline assembly"
    for cause in ("keyword", "head", "nested", "stray", "braced", "branch"):
        if cause in area.causes:
            return _CAUSES[cause]
    if _CONDITIONAL.search(data, start, end):
        return "#if branches that split a statement, or a macro"
    first = data[start : min(end, start + 200)].strip().split(b"\n")[0][:40]
    return f"a macro it cannot know? '{first.decode('utf-8', 'replace')}'"


def _losses(
    area: Area, reading: TokenReading, counted: Counted, lines: Lines, seen: Counted
) -> list[str]:
    """What ``area`` lost or estimated, in a reader's words (nothing: no warning);
    ``seen``: the lines of the statements and calls the token reading found."""
    first, last = lines.of(area.start), lines.of(max(area.start, area.end - 1))
    parts: list[str] = []
    if area.added:
        parts.append(f"{_plural(len(area.added), 'function')} read from tokens only, v_g estimated")
    if area.amended:
        more = sum(count for _, count in area.amended)
        names = ", ".join(sorted({name for name, _ in area.amended}))
        parts.append(f"v_g of {names} estimated from tokens (+{more})")
    for tree, name in area.renamed:
        parts.append(f"the head of {name} read as {tree!r}")
    unclosed = [at for at in reading.unclosed if area.start <= at < area.end]
    if unclosed:
        parts.append(f"the brackets from line {lines.of(unclosed[0])} on never close")
    if area.unmeasured:
        parts.append(f"{_plural(area.unmeasured, 'function')} not measured")
    again = {slot.qualified for slot in area.added}
    dropped = [name for name in area.dropped if name not in again]  # others: read again
    if dropped:
        shown = ", ".join(repr(name) for name in dropped[:3])
        parts.append(f"{shown} read as {'a function' if len(dropped) == 1 else 'functions'}"
                     " by mistake, not reported")  # fmt: skip
    statements = _between(seen.statements, first, last) - _between(counted.statements, first, last)
    calls = _between(seen.calls, first, last) - _between(counted.calls, first, last)
    lost = [
        _plural(n, what) for n, what in ((statements, "statement"), (calls, "call site")) if n > 0
    ]
    if lost:
        parts.append(f"about {' and '.join(lost)} not counted")
    return parts


def _lines(offsets: list[int], lines: Lines) -> list[int]:
    return sorted(lines.of(offset) for offset in offsets)


def warnings(
    path: str,
    areas: list[Area],
    reading: TokenReading,
    data: bytes,
    counted: Counted,
    lines: Lines,
) -> tuple[ParseWarning, ...]:
    """One warning per area that lost or estimated facts; at most ``_MAX_WARNINGS``, then
    one that says how many more."""
    problems: list[tuple[int, str]] = []
    seen = Counted([], _lines(reading.statements, lines), _lines(reading.calls, lines))
    for area in areas:
        parts = _losses(area, reading, counted, lines, seen)
        if not parts:
            continue
        first, last = lines.of(area.start), lines.of(max(area.start, area.end - 1))
        where = f"line {first}" if first == last else f"lines {first}-{last}"
        problems.append((first, f"{where}: {'; '.join(parts)} ({_cause(area, reading, data)})"))
    found = [ParseWarning(path, line, message) for line, message in problems[:_MAX_WARNINGS]]
    if len(problems) > _MAX_WARNINGS:
        more = len(problems) - _MAX_WARNINGS
        found.append(
            ParseWarning(path, problems[_MAX_WARNINGS][0], f"... {more} more regions not read")
        )
    return tuple(found)
