"""Macros tree-sitter cannot know, blanked before a second parse (docs/metrics.md, "Macros").

tree-sitter reads the text before preprocessing, so a macro that stands where the grammar
expects syntax (an export macro between ``class`` and the name, a thread-safety annotation
after a declarator, a namespace-opening macro on a line of its own) turns good code into
ERROR nodes, and everything inside them is lost. Only for a file whose first parse has
errors, each such macro is overwritten with spaces (every byte offset and line stays) and
the file parsed again; the parse with fewer errors wins. A macro is recognised by its
place and its spelling (``ALL_CAPS``, as macros are written), or because the configuration
lists it (``[tool.archmetrics.macros]``). Every rule names where it applies: *anywhere*, or
only *between declarations* (outside the function bodies of the first parse), where a
``NAME(args)`` after a ``)`` cannot be a call.
"""

from __future__ import annotations

import bisect
import functools
import re
from collections.abc import Iterable, Iterator

from archmetrics.parsers.c_family_macro_rules import ARGS as _ARGS
from archmetrics.parsers.c_family_macro_rules import MACRO as _MACRO
from archmetrics.parsers.c_family_macro_rules import (
    MacroNames,
    Rule,
    Scan,
    at_line_start,
    rules,
)
from archmetrics.parsers.c_family_text import blank

NO_NAMES = MacroNames()  # no configured macro names

_TYPE_WORDS = re.compile(
    rb"(?<=[(,])(\s*+)((?:(?:unsigned|signed|const|volatile|long|short)\s++)*+(?:bool|char"
    rb"|short|int|long|float|double|void|unsigned|signed|size_t|u?int(?:8|16|32|64)_t))\b"
    rb"(?=\s*+[,)])"
)

_RULES: dict[MacroNames, tuple[Rule, ...]] = {}
_WORD_BYTE = [chr(byte).isalnum() or byte == ord("_") for byte in range(128)] + [True] * 128
_LOOK_AHEAD = 4096  # bytes past a span of ``near`` a rule may read to decide a match in it
_LONGEST_START = 16  # bytes of the longest literal a rule begins with (``static``, ``\n``)
# A literal or comment left open runs to the end of its line (strings) or of the file (raw
# strings, block comments), as a compiler would read on: every byte is scanned once, never
# once per quote or `/*` that follows (a file of 100,000 `/*` took minutes).
_LITERALS = re.compile(
    rb'R"([^()\\ ]{0,16})\((?:[^)]|\)(?!\1"))*+(?:\)\1"|\Z)'
    rb'|"(?:\\.|[^"\\\n])*+(?:"|(?=\n)|\Z)|\'(?:\\.|[^\'\\\n])*+(?:\'|(?=\n)|\Z)'
    rb"|//[^\n]*+|/\*(?:[^*]|\*(?!/))*+(?:\*/|\Z)"
)
_LITERAL_EDGE = re.compile(rb"[\"'/\\\n]")
_EDGE_BYTES = frozenset((b'"', b"'", b"/", b"\\"))
_ENUM_OR_VALUE = re.compile(rb"(?:\benum\b[^;{}]*|=\s*)\{\s*$")
_CONTINUING = frozenset(b",(=|&+-*/?:<[!~%^")


def _standalone(data: bytes, start: int) -> bool:
    """Whether a macro at ``start`` begins a declaration or statement of its own: not an
    enumerator or an operand (``RED,\n GREEN\n}``, ``x = a +\n MAX``)."""
    before = data[max(0, start - 200) : start].rstrip()
    if not before:
        return True
    if before[-1] in _CONTINUING:
        return False
    return not (before.endswith(b"{") and _ENUM_OR_VALUE.search(before))


class _Ranges:
    """Sorted, non-overlapping byte ranges, asked whether they hold an offset."""

    def __init__(self, spans: list[tuple[int, int]]) -> None:
        self._spans = sorted(spans)
        self._starts = [start for start, _ in self._spans]

    @property
    def spans(self) -> list[tuple[int, int]]:
        return self._spans

    def __contains__(self, offset: object) -> bool:
        assert isinstance(offset, int)
        index = bisect.bisect_right(self._starts, offset) - 1
        return index >= 0 and offset < self._spans[index][1]


# A directive and its continuation lines (`#define F(x) \` ... ): tree-sitter reads them
# itself, and an `#if`'s condition is no `if EQ(...)`.
_DIRECTIVE = at_line_start(rb"[ \t]*+\#(?:[^\\\n]++|\\(?:\r?\n|.))*+")


# A file's spans are asked for several times while it is read (the first parse's macros, the
# rereading's, its #if groups), mostly of the same bytes: the last few files' are kept
# (bytes keep their hash, and equal bytes give equal spans).
@functools.lru_cache(maxsize=4)
def directive_spans(data: bytes) -> _Ranges:
    """The byte ranges of ``data``'s preprocessor directives, continuation lines included."""
    after_newline, at_start = _DIRECTIVE
    first = at_start.pattern.match(data)
    spans = [first.span()] if first else []
    return _Ranges(spans + [found.span() for found in after_newline.pattern.finditer(data)])


_BLOCK_COMMENT = re.compile(rb"/\*(?:[^*]|\*(?!/))*+\*/")


def directive_comments(data: bytes) -> list[tuple[int, int]]:
    r"""The block comments inside a directive continued over lines (``do { /* c */ \``):
    tree-sitter ends the directive at such a comment and reads the rest of its body as
    code, so they are blanked before the first parse (their lines stay, and are blanked
    from SLOC as every comment is)."""
    if b"\\\n" not in data or b"/*" not in data:
        return []
    found: list[tuple[int, int]] = []
    ranges = directive_spans(data)
    for start, end in ranges.spans:
        if data.find(b"\\\n", start, end) >= 0 and data.find(b"/*", start, end) >= 0:
            found.extend(m.span() for m in _BLOCK_COMMENT.finditer(data, start, end))
    return found


@functools.lru_cache(maxsize=4)
def literal_spans(data: bytes) -> _Ranges:
    """The byte ranges of ``data``'s string and character literals and comments."""
    return _Ranges([found.span() for found in _LITERALS.finditer(data)])


def _matches(scan: Scan, data: bytes, spans: list[tuple[int, int]]) -> Iterator[re.Match[bytes]]:
    """The matches of ``scan`` that start inside one of ``spans``, each as ``finditer``
    would find it when searching from the span's start (a match may read up to
    ``_LOOK_AHEAD`` bytes past the span's end). In a short span, the literal each begins
    with is found first, so only the span's own bytes are searched, not the bytes after."""
    size = len(data)
    for start, end in spans:
        limit = min(size, end + _LOOK_AHEAD)
        if end - start > _LOOK_AHEAD:  # a long span: searched, the look-ahead costs little
            for found in scan.pattern.finditer(data, start, limit):
                if found.start() >= end:
                    break
                yield found
            continue
        resume = start
        for candidate in scan.start.finditer(data, start, min(size, end + _LONGEST_START)):
            at = candidate.start()
            if at >= end:
                break
            if at < resume:
                continue
            matched = scan.pattern.match(data, at, limit)
            if matched is not None:
                resume = matched.end()
                yield matched


def blank_macros(
    data: bytes,
    bodies: Iterable[tuple[int, int]] = (),
    names: MacroNames = NO_NAMES,
    first: bool = False,
    near: Iterable[tuple[int, int]] | None = None,
) -> bytes:
    """``data`` with the macros the rules recognise overwritten by spaces. ``bodies``: the
    byte ranges of function bodies (rules marked *between declarations* skip them);
    ``first``: only the rules that run before the first parse; ``near``: if given, only
    the macros that start inside these byte ranges (disjoint) are blanked."""
    chosen = _RULES.get(names)
    if chosen is None:
        chosen = _RULES.setdefault(names, rules(names))
    spans = None if near is None else list(near)
    hits = [
        (rule, found)
        for rule in chosen
        if rule.before or not first
        for scan in rule.patterns
        for found in (scan.pattern.finditer(data) if spans is None else _matches(scan, data, spans))
        if not (rule.word and found.start() and _WORD_BYTE[data[found.start() - 1]])
    ]
    if not hits:
        return data
    in_body = _Ranges(list(bodies))
    wanted = _Ranges(spans) if spans is not None else None
    literal: _Ranges | None = None
    directive = directive_spans(data)
    out = bytearray(data)
    for rule, found in hits:
        start, end = found.span(found.lastindex or 1)  # the group that matched
        if rule.between and start in in_body:
            continue
        if wanted is not None and start not in wanted:
            continue
        # blanks inside a comment or a literal change no parse, unless they reach its edge:
        # only a group holding a quote, a slash, a backslash or a line end, or touching one
        # of the first three, is checked (touching: the `*` of a `/*` or a `*/`, the `R` of
        # a raw string); a line end before or after a group is no edge of what it is in
        if (
            _LITERAL_EDGE.search(data, start, end) is not None
            or data[start - 1 : start] in _EDGE_BYTES
            or data[end : end + 1] in _EDGE_BYTES
        ):
            literal = literal_spans(data) if literal is None else literal
            if start in literal:
                continue
        begins = found.start() + (data[found.start() : found.start() + 1] == b"\n")
        if start in directive or begins in directive:  # where the match or its group starts
            continue
        if rule.alone and not _standalone(data, start):
            continue
        if rule.types:
            out[start:end] = _TYPE_WORDS.sub(
                lambda m: m[1] + b"_" * len(m[2]), bytes(out[start:end])
            )
            continue
        blank(out, start, end)
    return bytes(out)


# A macro called alone on its line between declarations: group 1 its name, group 2 its
# argument list (PLUGINLIB_EXPORT_CLASS(a::B, c::D), RCLCPP_COMPONENTS_REGISTER_NODE(x::Y))
_MACRO_CALL = re.compile(
    rb"(?:\A|\n)[ \t]*+(" + _MACRO + rb")(" + _ARGS + rb")[ \t]*+;?[ \t]*+(?://[^\n]*+)?(?=\n|\Z)"
    rb"(?!\s*[{:,.=])"
)


def macro_calls(data: bytes, bodies: Iterable[tuple[int, int]]) -> list[tuple[int, int, int]]:
    """Macros called alone on their line between declarations, outside function ``bodies``,
    directives, comments and literals: (where the name starts, where the argument list
    starts, where it ends). tree-sitter reads such a call without its ``;`` as damage, and
    the macro rules above blank it; these are the calls it was (facts.CallSite)."""
    in_body = _Ranges(list(bodies))
    directive = directive_spans(data)
    literal: _Ranges | None = None
    found = []
    for match in _MACRO_CALL.finditer(data):
        start = match.start(1)
        if start in in_body or start in directive:
            continue
        literal = literal_spans(data) if literal is None else literal
        if start in literal:
            continue
        found.append((start, match.start(2), match.end(2)))
    return found
