"""Rule-pack regular expressions, matched with a time bound.

A rule pack can come from the measured repository (``rule-packs`` in its configuration), so
its ``endpoint.pattern`` is untrusted: ``(a|aa)+$`` against a long literal backtracks for
hours in Python's ``re``. Patterns are compiled with the ``regex`` engine (the syntax of
``re``, lookarounds included, as the shipped packs need) and every search is given
:data:`PATTERN_SECONDS`. A pattern that runs out of time is reported on the link site and
is not tried again in this run: the site's endpoint is unknown, and the scan goes on
(docs/security.md).
"""

from __future__ import annotations

from functools import lru_cache

import regex

PATTERN_SECONDS = 0.1
"""The longest one search of one endpoint pattern may take."""

PatternError = regex.error

_slow: set[str] = set()  # patterns that ran out of time once: not tried again


class SlowPattern(Exception):
    """A pattern that did not finish within :data:`PATTERN_SECONDS`."""

    def __init__(self, pattern: str):
        super().__init__(
            f"endpoint pattern {pattern!r} gave up after {PATTERN_SECONDS:g} s "
            "(catastrophic backtracking?); not tried again in this run"
        )


@lru_cache(maxsize=1024)
def compile_pattern(pattern: str) -> regex.Pattern[str]:
    """``pattern`` compiled (``regex.error`` when it is not a regular expression)."""
    return regex.compile(pattern)


def search(pattern: str, text: str) -> regex.Match[str] | None:
    """The first match of ``pattern`` in ``text``; :class:`SlowPattern` if it takes too long."""
    if pattern in _slow:
        raise SlowPattern(pattern)
    try:
        return compile_pattern(pattern).search(text, timeout=PATTERN_SECONDS)
    except TimeoutError:
        _slow.add(pattern)
        raise SlowPattern(pattern) from None
