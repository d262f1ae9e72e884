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
from collections.abc import Iterable, Iterator, Sequence
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
_LEADING = (
    rb"(?:static|extern|inline|constexpr|consteval|constinit|virtual|explicit|friend|typedef"
    rb"|template|const|volatile|unsigned|signed|void|bool|char|short|int|long|float|double"
    rb"|struct|class|union|enum|auto)\b"
)
_WORD = rb"[^;{}()=\s/]++"  # a word of a declaration's type: no comment, no statement
_STATEMENT = rb"(?:return|else|case|goto|throw|co_return|co_yield|new|delete|sizeof|typename)\b"
_QUALIFIERS = rb"(?:\s*+(?:const|noexcept|override|final|volatile|&&|&|throw\s*\(\s*\)))*+"
# a type, then a declarator's name and its `(`: `Vec128<T, N> operator==(`, `Foo* Make(`
_TEMPLATE_ARGS = rb"<(?:[^<>;{}]++|<(?:[^<>;{}]++|<[^<>;{}]*+>)*+>)*+>"
_NO_STATEMENT = rb"(?!" + _STATEMENT + rb")"
_TYPE = rb"(?:const\s++)?" + _NO_STATEMENT + rb"(?!operator\b)[A-Za-z_][\w:]*+"
_TYPE += rb"(?:\s*+" + _TEMPLATE_ARGS + rb"(?:::[A-Za-z_]\w*+)*+)?"
_DECLARATOR = _NO_STATEMENT + rb"(?:~?[A-Za-z_][\w:]*+(?:\s*+" + _TEMPLATE_ARGS + rb")?"
_DECLARATOR += rb"|operator\s*+(?:\(\s*+\)|[^\s(]++))\s*+\("
_TYPE_THEN_DECLARATOR = _TYPE + rb"(?:\s*+[*&]++\s*+|\s++)" + _DECLARATOR


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


@dataclass(frozen=True, slots=True)
class Scan:
    """A rule's ``pattern`` and the literal it begins with (``start``: a keyword, a bracket,
    a newline). Over a whole file the pattern is searched; in a few small spans, the
    literal is found first and the pattern tried only there (c.f. ``_matches``)."""

    pattern: re.Pattern[bytes]
    start: re.Pattern[bytes]


def _scan(start: bytes, pattern: bytes) -> Scan:
    return Scan(re.compile(pattern), re.compile(start))


@dataclass(frozen=True, slots=True)
class Rule:
    """Where a macro stands that tree-sitter cannot read: ``patterns`` (any of them) match
    it, their last matching group is what is blanked. ``between``: only between
    declarations; ``before``: before the first parse (a misreading that gives tree-sitter
    no error, as a class named after its macro); ``word``: the match must not follow a
    word character; ``alone``: the macro stands alone on its line (not an enumerator or an
    operand, ``_standalone``); ``types``: the group's built-in type words are rewritten as
    one identifier, not blanked.

    Each pattern begins with a literal (a keyword, a bracket, a newline) wherever the rule
    allows: Python's ``re`` then jumps from one occurrence of it to the next instead of
    trying the pattern at every byte, five to ten times faster over a file."""

    patterns: tuple[Scan, ...]
    between: bool = False
    before: bool = False
    word: bool = False
    alone: bool = False
    types: bool = False


def _keywords(words: tuple[bytes, ...], rest: bytes) -> tuple[Scan, ...]:
    """One pattern per keyword (or punctuation), each starting with its literal; a keyword's
    start is checked in code (``Rule.word``): a look-behind would cost the literal start."""
    return tuple(_scan(word, word + rest) for word in words)


def _at_line_start(rest: bytes) -> tuple[Scan, Scan]:
    """``rest`` at the start of a line: after a newline, or at the start of the file."""
    return _scan(rb"\n", rb"\n" + rest), _scan(rb"\A", rb"\A" + rest)


def _rules(names: MacroNames) -> tuple[Rule, ...]:
    macro = _attribute(names.attribute)
    line_end = rb"[ \t]*+(?://[^\n]*+)?(?=\n|\Z)"
    return (
        # class FOO_EXPORT Name : / {     struct PACKED Name {     class LOCKABLE(x) Name
        # class LOCKABLE WARN_UNUSED Name {   (the name is the last word before `:` `{`)
        # or, in group 2: class Name PROTOBUF_FINAL : Base {       (one pass for both)
        Rule(_keywords((b"class", b"struct", b"union"), rb"\s++(?:((?:(?>" + macro + _ARGS
                       + rb"?+)\s++)+)(?=" + _NAME
                       + rb"(?:\s*<[^;{}()]*>)?\s*(?:final\b|:(?!:)|\{))|" + _NAME
                       + rb"\s++(?!final\b)(" + macro + _ARGS
                       + rb"?+)(?=\s*(?::(?!:)|\{)))"), before=True, word=True),
        # a line holding nothing but a macro: RAPIDJSON_NAMESPACE_BEGIN, Q_OBJECT; before the
        # first parse where a declaration's keyword follows (tree-sitter would read the
        # macro as the type of what follows: ABSL_NAMESPACE_BEGIN / class Notification {)
        Rule(_at_line_start(rb"[ \t]*+(" + macro + rb")" + line_end + rb"(?=(?:\s*+//[^\n]*+)*+"
                            rb"\s*+(?:class|struct|union|namespace|template|typedef|extern|using"
                            rb"|enum)\b)"), alone=True, before=True),
        # a line holding nothing but a macro: RAPIDJSON_NAMESPACE_BEGIN, Q_OBJECT
        Rule(_at_line_start(rb"[ \t]*+(" + macro + rb")" + line_end), alone=True),
        # void Lock() EXCLUSIVE_LOCKS_REQUIRED(mu_);   int f() const OVERRIDE {
        Rule((_scan(rb"\)", rb"\)" + _QUALIFIERS + rb"\s*+((?>" + macro + _ARGS + rb"?+\s*+)++)"
                         + rb"(?=;|\{|=[^=]|:(?!:)|->|override\b|final\b|const\b|noexcept\b)"),),
             between=True),
        # a macro call alone on its line, not heading a body: RAPIDJSON_DIAG_OFF(effc++)
        Rule(_at_line_start(rb"[ \t]*+(" + macro + _ARGS + rb")" + line_end
                            + rb"(?!\s*[{:,.=])"), between=True, alone=True),
        # in a body, a macro call alone on its line that the next line does not continue:
        # OP(Py_LT, lt) in a switch (a statement macro, its `;` inside)
        Rule(_at_line_start(rb"[ \t]*+(" + macro + _ARGS + rb")" + line_end
                            + rb"(?!\s*+(?:[{:,.=+\-*/%&|^?<>)\]]|\Z))"), alone=True),
        # if EQ("a") {   while NOT_DONE(x) {
        Rule(_keywords((b"if", b"while", b"switch"), rb"\s+(?!constexpr\b)(" + _NAME
                       + rb")(?=\s*\()"), word=True),
        # static BROTLI_INLINE void f(   static CYTHON_INLINE int g(   (a built-in type follows)
        Rule(_keywords((b"static", b"extern", b"inline"), rb"\s++(" + macro + rb")(?=\s++"
                       + _BUILTIN + rb")"), between=True, word=True),
        # void f(int * BROTLI_RESTRICT self, FUNC& HWY_RESTRICT g)   const T* const
        # HWY_RESTRICT p)   T* HWY_RESTRICT pos = x;   (after a `*` or `&`: no expression
        # has a word after an operand there, so before the first parse)
        Rule(_keywords((rb"\*", b"&"), rb"\s*+(?:(?:const|volatile)\s++)*+(" + macro
                       + rb")(?=\s++[A-Za-z_]\w*+\s*+[,)\[=;])"), before=True),
        # ABSL_CONST_INIT static T x;   ABSL_MUST_USE_RESULT inline int f(   (macros heading
        # a declaration, before a keyword that begins one)
        Rule(_at_line_start(rb"[ \t]*+((?>" + macro + _ARGS + rb"?+[ \t]++)++)(?=" + _LEADING
                            + rb")"), between=True),
        # HWY_API Vec128<T, N> operator==(   NPY_NO_EXPORT PyObject *f(   (macros heading a
        # declaration, before a type and a declarator: two types side by side are no C; the
        # run gives back its last word if that is the type: HWY_API T GetLane(
        # static HWY_INLINE HWY_MAYBE_UNUSED bool f(   (after keywords, before keywords too;
        # template NPY_NO_EXPORT int f<T>(   an explicit instantiation)
        Rule(_at_line_start(rb"[ \t]*+(?:(?:static|inline|extern|constexpr|virtual|explicit"
                            rb"|friend|template)[ \t]++)*+((?>" + macro + _ARGS
                            + rb"?+[ \t]++)+)(?=(?:" + _LEADING + rb"\s++)*"
                            + _TYPE_THEN_DECLARATOR + rb")"),
             before=True),
        # template <class D, HWY_IF_LANES_D(D, 1)>   (macros as template parameters, the list
        # closed at the end of its line or before a declaration's keyword, or a `typename`
        # parameter next)
        Rule((_scan(b",", rb"(,\s*+" + macro + _ARGS + rb"(?>\s*+,\s*+" + macro + _ARGS
                       + rb")*+)(?=\s*+(?:>[ \t]*+(?:\n|//|/\*|(?:class|struct|union|using|static"
                       rb"|inline|constexpr|friend|typename)\b)|,\s*+(?:typename|class)\b))"),),
             before=True),
        # POCKETFFT_NOINLINE fftblue(size_t n) : n(n) {   (macros before a constructor, a
        # definition without a return type; known by its initializer list or `= default`:
        # before `{`, the macro could be the return type, `BOOL Check(int x) {`)
        Rule(_at_line_start(rb"[ \t]*+(?:(?:inline|constexpr|explicit)[ \t]++)*+((?>" + macro
                            + _ARGS + rb"?+[ \t]++)+)(?=~?" + _NAME + _ARGS + _QUALIFIERS
                            + rb"\s*+(?::(?!:)|=\s*+(?:default|delete)\b))"), between=True),
        # bool done_ ABSL_GUARDED_BY(mu_) = false;    (a macro call after a declared name;
        # the type and the name on one line, read a word at a time)
        Rule(_at_line_start(rb"[ \t]*+(?>" + _WORD + rb"[ \t]++)*?" + _WORD
                            + rb"(?<=[\w>*&])[ \t]++(?!" + _LEADING + rb"|" + _STATEMENT
                            + rb")[A-Za-z_]\w*+\s++(" + macro + _ARGS
                            + rb"(?>\s*+" + macro + _ARGS + rb")*+)(?=\s*+(?:;|=[^=]))"),
             between=True),
        # [&]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { ... }   (after a lambda's parameters)
        Rule((_scan(rb"\]", rb"\]\s*+" + _ARGS + _QUALIFIERS + rb"\s*+((?>" + macro + _ARGS
                         + rb"?+\s*+)++)(?=\{|->|mutable\b|noexcept\b)"),)),
        # ABSL_FLAG(int, name, 0, "help");  a type among a macro call's arguments: the type's
        # words (not blanked: rewritten as one identifier of the same length) in group 1;
        # in a body too: ASSERT_HEX(unsigned short, 2badU);
        Rule(_at_line_start(rb"[ \t]*+" + macro + rb"(" + _ARGS + rb")"), types=True),
        # EXPECT_EQ(WS WS WS, f(x))   (string macros side by side, no literal among them:
        # all but the first blanked, the argument stays one expression; a word against a
        # quote is the literal's prefix, g(MY_R R"(x)"), not a macro)
        Rule(_keywords((rb"\(", b","), rb"\s*+" + macro + rb"((?:\s++" + macro
                       + rb")++)(?=\s*+[,)]|\s++\")")),
        # for (; const char* p = next(s); ...)   (a declaration as a `for` condition, which
        # tree-sitter-cpp's grammar lacks: its type blanked, an assignment is left)
        Rule(_keywords((b"for",), rb"\s*+\(\s*+;\s*+((?:const\s++)?[A-Za-z_][\w:]*+(?:\s*+[*&]++"
                                  rb"\s*+|\s++))(?=[A-Za-z_]\w*+\s*+=[^=])"), word=True),
        # ABSL_INTERNAL_TRY {   (a macro alone before a block: a `try` or a scope, say)
        Rule(_at_line_start(rb"[ \t]*+(" + macro + rb")[ \t]*+(?=\{)")),
        # template <class T, EnableIf<(N <= 1)>* = nullptr>   void f(Foo* = nullptr)   (an
        # unnamed pointer or reference parameter with a default, which tree-sitter-cpp's
        # grammar lacks: the `*` or `&` blanked, a parameter of the pointee's type is left;
        # `* =` with a blank between is no operator, `*=` is)
        Rule((_scan(rb"\*", rb"(\*[*&]*+)(?=[ \t]++=[^=])"),
              _scan(b"&", rb"(&[*&]*+)(?=[ \t]++=[^=])")), before=True),
        # const __vector unsigned char k = {...};   (a compiler's keyword, reserved `__`
        # spelling, before a built-in type: AltiVec's `__vector`)
        Rule((_scan(b"__", rb"(__[A-Za-z]\w*+)(?=\s++(?:__[A-Za-z]\w*+\s++)*+" + _BUILTIN
                    + rb")"),), word=True),
    )  # fmt: skip


# A built-in type that is a whole argument: after `(` or `,`, before `,` or `)`, so never a
# part of one: `int[2]`, `int&`, `<int>` or `sizeof(long) * 2` inside an argument stay as
# written; `sizeof(int)` becomes `sizeof(___)`, which reads alike.
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
_DIRECTIVE = _at_line_start(rb"[ \t]*+\#(?:[^\\\n]++|\\(?:\r?\n|.))*+")


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
    names: MacroNames = MacroNames(),
    first: bool = False,
    near: Iterable[tuple[int, int]] | None = None,
) -> bytes:
    """``data`` with the macros the rules recognise overwritten by spaces. ``bodies``: the
    byte ranges of function bodies (rules marked *between declarations* skip them);
    ``first``: only the rules that run before the first parse; ``near``: if given, only
    the macros that start inside these byte ranges (disjoint) are blanked."""
    rules = _RULES.get(names)
    if rules is None:
        rules = _RULES.setdefault(names, _rules(names))
    spans = None if near is None else list(near)
    hits = [
        (rule, found)
        for rule in rules
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
