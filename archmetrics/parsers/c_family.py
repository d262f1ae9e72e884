"""C and C++ facts: one tree-sitter walker, parametrised by the node tables in ``c_tables``.

A single query per language captures every node we need in one pass on the C side;
Python then touches only those nodes (statements, decisions, calls, comments), never the
tokens in between. Statement rules follow thesis page 103; decisions follow lizard.
"""

from __future__ import annotations

import re

from archmetrics.facts import (
    FileFacts,
    Language,
    ParseWarning,
    Severity,
)
from archmetrics.parsers.c_family_facts import Composite, facts
from archmetrics.parsers.c_family_grammar import (
    Grammar,
    grammar,
)
from archmetrics.parsers.c_family_macros import blank_macros, directive_comments
from archmetrics.parsers.c_family_reading import Reading
from archmetrics.parsers.c_family_regions import damaged, joined
from archmetrics.parsers.c_family_spellings import branches, nearby
from archmetrics.parsers.c_family_text import blank_spans
from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits, not_measured

__all__ = ["Grammar", "grammar", "hide_extern_c_guards", "parse"]


def parse(
    path: str,
    source: str,
    language: Language,
    limits: ParseLimits = DEFAULT_LIMITS,
    second_reading: bool = True,
) -> FileFacts:
    """Facts for one C or C++ file. Never raises: what cannot be read becomes a warning.
    ``second_reading=False``: the syntax tree's facts alone, no token reading where it
    cannot be trusted and no warnings (benchmarks/oracle_c.py measures warnings by it)."""
    try:
        return _parse(path, source, language, limits, second_reading)
    except Exception as error:  # a bug here must not stop a whole repository's measurement
        message = f"C/C++ parser failed ({type(error).__name__}: {error}); file not measured"
        return FileFacts(
            path,
            str(language),
            parsed=False,
            warnings=(ParseWarning(path, 1, message, Severity.ERROR),),
        )


_CPLUSPLUS = rb"#[ \t]*if(?:def[ \t]+__cplusplus|[ \t]+defined[ \t(]*__cplusplus[ \t)]*)[^\n]*\n"
_EXTERN_C_GUARD = re.compile(
    rb"(" + _CPLUSPLUS + rb")([ \t]*(?:extern[ \t]+\"C\"[ \t]*)?[{}][ \t]*"
    rb"(?:/\*(?:[^*\n]|\*(?!/))*\*/[ \t]*|//[^\n]*)?)(?=\n[ \t]*#[ \t]*endif)"
)


def hide_extern_c_guards(data: bytes) -> bytes:
    """Blank the ``extern "C" {`` and ``}`` lines that sit alone inside ``#ifdef __cplusplus``
    (with a comment after them or not: ``}  /* extern "C" */``).

    The idiom opens a brace in one preprocessor branch and closes it in another, which no
    grammar of the unpreprocessed text can follow (tree-sitter reports a missing ``#endif``).
    Those lines count 0 anyway (an ``extern "C"`` block is not a statement); blanking them with
    spaces keeps every byte offset and line number.
    """
    return _EXTERN_C_GUARD.sub(lambda m: m.group(1) + b" " * len(m.group(2)), data)


def _parse(
    path: str, source: str, language: Language, limits: ParseLimits, second_reading: bool
) -> FileFacts:
    if "\r" in source:  # a compiler reads \r\n and a lone \r as newlines, and so do we: the
        # macro rules read lines as ending in \n (a CRLF checkout of a file read otherwise
        # than its LF blob; docs/metrics.md, "Line endings")
        source = source.replace("\r\n", "\n").replace("\r", "\n")
    built = grammar(language)
    data = hide_extern_c_guards(source.encode("utf-8", "surrogatepass"))
    first = blank_macros(data, names=limits.c_macros, first=True)
    hidden = directive_comments(data)
    if hidden:  # comments that end a continued #define for tree-sitter
        first = blank_spans(first, hidden)
    reading = Reading.of(built, first, limits, damage_only=True)
    if isinstance(reading, str):
        return not_measured(path, str(language), 1, reading)
    damaged = reading.root.has_error  # (a macro called without its `;` is damage)
    if damaged:
        reading = _recover(built, reading, limits)
        if isinstance(reading, str):
            return not_measured(path, str(language), 1, reading)
    composite = branches(built, reading, limits) if reading.root.has_error else None
    reading_used = composite or Composite(reading.root, reading.found, reading.standalone())
    reading_used.hidden_comments = hidden
    return facts(
        path, language, built, reading_used, data, limits.c_macros, second_reading, damaged
    )


def _recover(built: Grammar, reading: Reading, limits: ParseLimits) -> Reading | str:
    """The first parse had errors: parse again with the macros tree-sitter cannot know
    blanked (c_family_macros.py), first only those near the damage, then (if damage is
    left) all of them, and keep whichever parse lost least. Blanking only near the damage
    keeps a macro-like word that was read well elsewhere (a return type ``PVOID`` alone on
    its line above a function's name). The depth limit is checked on the reading kept
    (the query walks it; the rereadings are judged without one)."""
    bodies = reading.bodies()
    damage = damaged(reading.found, reading.data, root=reading.root)
    near = nearby(reading.data, damage)
    best, tried = reading, {reading.data}
    for spans in (joined(near), None):
        if spans is None and not _widespread(best):
            break
        blanked = blank_macros(reading.data, bodies, limits.c_macros, near=spans)
        if blanked in tried:
            continue
        tried.add(blanked)
        other = Reading.of(built, blanked, limits, reading, damage_only=True)
        if not isinstance(other, str) and other.damage < best.damage:
            best = other
    completed = best.completed(built, limits)
    if isinstance(completed, str) and best is not reading:  # too deep: the first reading
        return reading.completed(built, limits)
    return completed


_FAR_LINES = 10  # a damaged region this long may come from a macro far from it


def _widespread(reading: Reading) -> bool:
    """Whether a damaged region of ``reading`` spans more than ``_FAR_LINES`` lines: a
    macro that breaks a file's structure (``ABSL_NAMESPACE_BEGIN`` before a class) damages
    what follows it, so its cause may lie outside the lines near the damage; a macro that
    breaks one declaration damages only that, near it."""
    data = reading.data
    return any(
        data.count(b"\n", s, e) > _FAR_LINES
        for s, e in damaged(reading.found, data, root=reading.root)
    )
