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
import re
from collections.abc import Iterable, Sequence
from dataclasses import dataclass

from archmetrics.parsers.c_family_text import blank

# Every repetition is possessive or atomic: a run of macros (``DECLARE(A) DECLARE(B) ...``)
# that fails to match must fail in one pass, never by trying each way to split it.
# ALL_CAPS, optionally after a library prefix: Py_BEGIN_ALLOW_THREADS, uv_MAYBE_UNUSED
_MACRO = rb"(?:[A-Za-z][a-z0-9]*+_)?+(?=[0-9_]*+[A-Z])[A-Z_][A-Z0-9_]*+"
_ARGS = rb"(?>\s*+\((?:[^()]++|\((?:[^()]++|\([^()]*+\))*+\))*+\))"
_NAME = rb"[A-Za-z_]\w*+"
_BUILTIN = (
    rb"(?:(?:const|volatile|unsigned|signed)\s++)*+(?:void|char|short|int|long|float|double"
    rb"|bool|_Bool|size_t|ssize_t|u?int(?:8|16|32|64|ptr|max)_t|struct|enum|union)\b"
)
_QUALIFIERS = rb"(?:\s*+(?:const|noexcept|override|final|volatile|&&|&|throw\s*\(\s*\)))*+"


@dataclass(frozen=True, slots=True)
class MacroNames:
    """Macros the configuration names: ``attribute`` macros expand to nothing a metric counts
    (export, annotation, alignment macros), ``function`` macros head a function definition
    (``TEST(Suite, Name) { ... }``)."""

    attribute: tuple[str, ...] = ()
    function: tuple[str, ...] = ()


def _attribute(names: Sequence[str]) -> bytes:
    """The macro spelling: ALL_CAPS, or one of ``names``."""
    listed = b"|".join(re.escape(n.encode()) for n in names)
    return rb"(?:" + _MACRO + (rb"|" + listed if listed else b"") + rb")\b"


Rule = tuple[re.Pattern[bytes], bool, bool]
"""(pattern whose matching group is blanked, applies between declarations only, applies before the
first parse: a misreading that gives tree-sitter no error, as a class named after its macro)."""


def _rules(names: MacroNames) -> tuple[Rule, ...]:
    macro = _attribute(names.attribute)
    return (
        # class FOO_EXPORT Name : / {     struct PACKED Name {     class LOCKABLE(x) Name
        # or, in group 2: class Name PROTOBUF_FINAL : Base {       (one pass for both)
        (re.compile(rb"\b(?:class|struct|union)\s++(?:(" + macro + _ARGS + rb"?+)\s++(?="
                    + _NAME + rb"(?:\s*<[^;{}()]*>)?\s*(?:final\b|:(?!:)|\{))|" + _NAME
                    + rb"\s++(?!final\b)(" + macro + _ARGS + rb"?+)(?=\s*(?::(?!:)|\{)))"),
         False, True),
        # a line holding nothing but a macro: RAPIDJSON_NAMESPACE_BEGIN, Q_OBJECT
        (re.compile(rb"(?m)^[ \t]*(" + macro + rb")[ \t]*(?://[^\n]*)?$"), False, False),
        # void Lock() EXCLUSIVE_LOCKS_REQUIRED(mu_);   int f() const OVERRIDE {
        (re.compile(rb"\)" + _QUALIFIERS + rb"\s*+((?>" + macro + _ARGS + rb"?+\s*+)++)"
                    + rb"(?=;|\{|=[^=]|:(?!:)|->|override\b|final\b|const\b|noexcept\b)"),
         True, False),
        # a macro call alone on its line, not heading a body: RAPIDJSON_DIAG_OFF(effc++)
        (re.compile(rb"(?m)^[ \t]*(" + macro + _ARGS + rb")[ \t]*(?://[^\n]*)?$(?!\s*[{:,.=])"),
         True, False),
        # if EQ("a") {   while NOT_DONE(x) {
        (re.compile(rb"\b(?:if|while|switch)\s+(?!constexpr\b)(" + _NAME + rb")(?=\s*\()"), False,
         False),
        # static BROTLI_INLINE void f(   static CYTHON_INLINE int g(   (a built-in type follows)
        (re.compile(rb"\b(?:static|extern|inline)\s++(" + macro + rb")(?=\s++" + _BUILTIN + rb")"),
         True, False),
        # void f(int * BROTLI_RESTRICT self, ...)   (between a `*` and a parameter's name)
        (re.compile(rb"\*\s*+(" + macro + rb")(?=\s++[A-Za-z_]\w*+\s*+[,)\[])"), False, False),
        # ABSL_FLAG(int, name, 0, "help");  a type among a macro call's arguments: the type's
        # words (not blanked: rewritten as one identifier of the same length) in group 1
        (re.compile(rb"(?m)^[ \t]*+" + macro + rb"(" + _ARGS + rb")"), True, False),
    )  # fmt: skip


_LINE_RULES = frozenset({1, 3})  # the rules for a macro alone on its line
_TYPE_RULES = frozenset({7})  # the rule that rewrites types among a call's arguments
_TYPE_WORDS = re.compile(
    rb"\b(?:(?:unsigned|signed|const|volatile|long|short)\s++)*+(?:bool|char|short|int|long"
    rb"|float|double|void|unsigned|signed|size_t|u?int(?:8|16|32|64)_t)\b(?!\s*+\()"
)

_RULES: dict[MacroNames, tuple[Rule, ...]] = {}
# A literal or comment left open runs to the end of its line (strings) or of the file (raw
# strings, block comments), as a compiler would read on: every byte is scanned once, never
# once per quote or `/*` that follows (a file of 100,000 `/*` took minutes).
_LITERALS = re.compile(
    rb'R"([^()\\ ]{0,16})\((?:[^)]|\)(?!\1"))*+(?:\)\1"|\Z)'
    rb'|"(?:\\.|[^"\\\n])*+(?:"|(?=\n)|\Z)|\'(?:\\.|[^\'\\\n])*+(?:\'|(?=\n)|\Z)'
    rb"|//[^\n]*+|/\*(?:[^*]|\*(?!/))*+(?:\*/|\Z)"
)
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

    def __contains__(self, offset: object) -> bool:
        assert isinstance(offset, int)
        index = bisect.bisect_right(self._starts, offset) - 1
        return index >= 0 and offset < self._spans[index][1]


def literal_spans(data: bytes) -> _Ranges:
    """The byte ranges of ``data``'s string and character literals and comments."""
    return _Ranges([found.span() for found in _LITERALS.finditer(data)])


def blank_macros(
    data: bytes,
    bodies: Iterable[tuple[int, int]] = (),
    names: MacroNames = MacroNames(),
    first: bool = False,
) -> bytes:
    """``data`` with the macros the rules recognise overwritten by spaces. ``bodies``: the
    byte ranges of function bodies (rules marked *between declarations* skip them);
    ``first``: only the rules that run before the first parse."""
    rules = _RULES.get(names)
    if rules is None:
        rules = _RULES.setdefault(names, _rules(names))
    hits = [
        (number, found, between)
        for number, (pattern, between, before) in enumerate(rules)
        if before or not first
        for found in pattern.finditer(data)
    ]
    if not hits:
        return data
    in_body = _Ranges(list(bodies))
    literal = literal_spans(data)
    out = bytearray(data)
    for number, found, between in hits:
        start, end = found.span(found.lastindex or 1)  # the group that matched
        if start in literal or (between and start in in_body):
            continue
        if number in _LINE_RULES and not _standalone(data, found.start()):
            continue
        if number in _TYPE_RULES:
            out[start:end] = _TYPE_WORDS.sub(lambda m: b"_" * len(m[0]), bytes(out[start:end]))
            continue
        blank(out, start, end)
    return bytes(out)
