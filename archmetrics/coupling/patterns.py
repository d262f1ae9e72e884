"""Rule-pack regular expressions, checked before they are compiled and matched with a time
bound.

A rule pack can come from the measured repository (``rule-packs`` in its configuration), so
its ``endpoint.pattern`` is untrusted twice over:

- **Compiling** it costs memory in proportion to its counted repetitions: the ``regex``
  engine writes ``a{30000000}`` out 30 million times (8 GB for that 13-byte pattern). So a
  pattern is checked first (:func:`check_pattern`): at most :data:`MAX_PATTERN_CHARS`
  characters, every count of ``{m,n}`` at most :data:`MAX_REPEAT`, groups nested at most
  :data:`MAX_NESTING` deep, and its *weight* — its length times the product of every count
  in it, an upper bound of how many pattern items the compiled form holds, however they
  nest — at most :data:`MAX_WEIGHT`. A ``{`` that is not such a count (the engine's fuzzy
  matching, ``{e<=1}``) must be written ``\\{``. Compiled forms are kept in a cache of at
  most :data:`CACHE_WEIGHT` in all (and not in the engine's own cache), so the memory of
  patterns is bounded per pattern and per run (docs/security.md).
- **Matching** it can backtrack for hours (``(a|aa)+$`` against a long literal in Python's
  ``re``). Patterns are compiled with the ``regex`` engine (the syntax of ``re``,
  lookarounds included, as the shipped packs need) and every search is given
  :data:`PATTERN_SECONDS`. A pattern that runs out of time is reported on the link site
  and is not tried again in this run: the site's endpoint is unknown, and the scan goes on.
"""

from __future__ import annotations

import re
from collections import OrderedDict

import regex

PATTERN_SECONDS = 0.1
"""The longest one search of one endpoint pattern may take."""

MAX_PATTERN_CHARS = 1000
MAX_REPEAT = 1000
MAX_NESTING = 100
MAX_WEIGHT = 20_000
"""A pattern's length times the product of its counts: ``a{1000}`` weighs 7,000; the
heaviest compiled form this allows took about 20 MB (tests/coupling/test_pattern_memory.py
compiles the heaviest shapes under a memory limit)."""
CACHE_WEIGHT = 200_000
"""The compiled patterns kept for reuse weigh at most this much together."""

PatternError = regex.error

_slow: set[str] = set()  # patterns that ran out of time once: not tried again
_COUNT = re.compile(r"\{([0-9]*)(?:(,)([0-9]*))?\}")
_BRACED_ESCAPES = frozenset("pPNx")  # \p{L}, \N{name}, \x{263a}: braces that are no count


class SlowPattern(Exception):
    """A pattern that did not finish within :data:`PATTERN_SECONDS`."""

    def __init__(self, pattern: str):
        super().__init__(
            f"endpoint pattern {pattern!r} gave up after {PATTERN_SECONDS:g} s "
            "(catastrophic backtracking?); not tried again in this run"
        )


def _escape_end(pattern: str, at: int) -> int:
    """Where the escape starting at ``at`` (a backslash) ends."""
    if pattern[at + 1 : at + 2] in _BRACED_ESCAPES and pattern[at + 2 : at + 3] == "{":
        close = pattern.find("}", at + 3)
        return len(pattern) if close < 0 else close + 1
    return at + 2


def _class_end(pattern: str, at: int) -> int:
    """Where the character class opening at ``at`` ends, never later than the engine's end:
    a first ``]`` is a member, the next unescaped one closes it."""
    i = at + 1
    if pattern[i : i + 1] == "^":
        i += 1
    if pattern[i : i + 1] == "]":
        i += 1
    while i < len(pattern):
        if pattern[i] == "\\":
            i = _escape_end(pattern, i)
        elif pattern[i] == "]":
            return i + 1
        else:
            i += 1
    return len(pattern)


def _count(pattern: str, at: int) -> tuple[int, int]:
    """The largest number of the count ``{m,n}`` at ``at`` and where it ends; PatternError
    for a brace that is no count, or a count over :data:`MAX_REPEAT`."""
    found = _COUNT.match(pattern, at)
    if found is None or not (found.group(1) or found.group(3)):
        raise PatternError(
            f"a '{{' at position {at} is not a repetition count {{m,n}} (fuzzy matching is "
            "not allowed; write \\{ for a brace)"
        )
    numbers = [int(n) for n in (found.group(1), found.group(3)) if n]
    if max(numbers) > MAX_REPEAT:
        raise PatternError(f"a repetition count over {MAX_REPEAT} at position {at}")
    return max(numbers), found.end()


def pattern_weight(pattern: str) -> int:
    """The weight :func:`check_pattern` bounds: length times the product of the counts."""
    product, depth, i = 1, 0, 0
    while i < len(pattern):
        char = pattern[i]
        if char == "\\":
            i = _escape_end(pattern, i)
            continue
        if char == "[":
            i = _class_end(pattern, i)
            continue
        if char == "{":
            largest, i = _count(pattern, i)
            product *= max(1, largest)
            if product > MAX_WEIGHT:  # no need to multiply further
                break
            continue
        if char == "(":
            depth += 1
            if depth > MAX_NESTING:
                raise PatternError(f"groups nested more than {MAX_NESTING} deep")
        elif char == ")":
            depth = max(0, depth - 1)
        i += 1
    return len(pattern) * product


def check_pattern(pattern: str) -> int:
    """``pattern``'s weight, after checking it may be compiled (PatternError if not)."""
    if len(pattern) > MAX_PATTERN_CHARS:
        raise PatternError(f"longer than {MAX_PATTERN_CHARS} characters")
    weight = pattern_weight(pattern)
    if weight > MAX_WEIGHT:
        raise PatternError(
            f"its counted repetitions are too large (length x counts = {weight:,} > "
            f"{MAX_WEIGHT:,})"
        )
    return weight


_compiled: OrderedDict[str, tuple[regex.Pattern[str], int]] = OrderedDict()
_cached_weight = 0


def compile_pattern(pattern: str) -> regex.Pattern[str]:
    """``pattern`` checked and compiled (PatternError when it is refused or is no regular
    expression); kept for reuse while the kept ones weigh at most :data:`CACHE_WEIGHT`."""
    global _cached_weight
    known = _compiled.get(pattern)
    if known is not None:
        _compiled.move_to_end(pattern)
        return known[0]
    weight = check_pattern(pattern)
    try:
        compiled = regex.compile(pattern, cache_pattern=False)
    except RecursionError:
        raise PatternError("nested too deeply") from None
    _compiled[pattern] = (compiled, weight)
    _cached_weight += weight
    while _cached_weight > CACHE_WEIGHT and len(_compiled) > 1:
        _cached_weight -= _compiled.popitem(last=False)[1][1]
    return compiled


def search(pattern: str, text: str) -> regex.Match[str] | None:
    """The first match of ``pattern`` in ``text``; :class:`SlowPattern` if it takes too long."""
    if pattern in _slow:
        raise SlowPattern(pattern)
    try:
        return compile_pattern(pattern).search(text, timeout=PATTERN_SECONDS)
    except TimeoutError:
        _slow.add(pattern)
        raise SlowPattern(pattern) from None
