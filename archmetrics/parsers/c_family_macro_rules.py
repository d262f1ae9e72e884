"""The macro rules of the C/C++ reader (docs/metrics.md, "Macros"): where a macro tree-sitter
cannot know stands (an export macro between ``class`` and the name, an annotation after a
declarator, a namespace-opening macro on its own line) and how it is spelled, as
possessive patterns that c_family_macros.py applies."""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

# Every repetition is possessive or atomic: a run of macros (``DECLARE(A) DECLARE(B) ...``)
# that fails to match must fail in one pass, never by trying each way to split it.
# ALL_CAPS, optionally after a library prefix: Py_BEGIN_ALLOW_THREADS, uv_MAYBE_UNUSED
MACRO = rb"(?:[A-Za-z][a-z0-9]*+_)?+(?=[0-9_]*+[A-Z])[A-Z_][A-Z0-9_]*+"
ARGS = rb"(?>\s*+\((?:[^()]++|\((?:[^()]++|\([^()]*+\))*+\))*+\))"
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
    return rb"(?:" + MACRO + (rb"|" + listed if listed else b"") + rb")\b"


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


def at_line_start(rest: bytes) -> tuple[Scan, Scan]:
    """``rest`` at the start of a line: after a newline, or at the start of the file."""
    return _scan(rb"\n", rb"\n" + rest), _scan(rb"\A", rb"\A" + rest)


def rules(names: MacroNames) -> tuple[Rule, ...]:
    macro = _attribute(names.attribute)
    line_end = rb"[ \t]*+(?://[^\n]*+)?(?=\n|\Z)"
    return (
        # class FOO_EXPORT Name : / {     struct PACKED Name {     class LOCKABLE(x) Name
        # class LOCKABLE WARN_UNUSED Name {   (the name is the last word before `:` `{`)
        # or, in group 2: class Name PROTOBUF_FINAL : Base {       (one pass for both)
        Rule(_keywords((b"class", b"struct", b"union"), rb"\s++(?:((?:(?>" + macro + ARGS
                       + rb"?+)\s++)+)(?=" + _NAME
                       + rb"(?:\s*<[^;{}()]*>)?\s*(?:final\b|:(?!:)|\{))|" + _NAME
                       + rb"\s++(?!final\b)(" + macro + ARGS
                       + rb"?+)(?=\s*(?::(?!:)|\{)))"), before=True, word=True),
        # a line holding nothing but a macro: RAPIDJSON_NAMESPACE_BEGIN, Q_OBJECT; before the
        # first parse where a declaration's keyword follows (tree-sitter would read the
        # macro as the type of what follows: ABSL_NAMESPACE_BEGIN / class Notification {)
        Rule(at_line_start(rb"[ \t]*+(" + macro + rb")" + line_end + rb"(?=(?:\s*+//[^\n]*+)*+"
                            rb"\s*+(?:class|struct|union|namespace|template|typedef|extern|using"
                            rb"|enum)\b)"), alone=True, before=True),
        # a line holding nothing but a macro: RAPIDJSON_NAMESPACE_BEGIN, Q_OBJECT
        Rule(at_line_start(rb"[ \t]*+(" + macro + rb")" + line_end), alone=True),
        # void Lock() EXCLUSIVE_LOCKS_REQUIRED(mu_);   int f() const OVERRIDE {
        Rule((_scan(rb"\)", rb"\)" + _QUALIFIERS + rb"\s*+((?>" + macro + ARGS + rb"?+\s*+)++)"
                         + rb"(?=;|\{|=[^=]|:(?!:)|->|override\b|final\b|const\b|noexcept\b)"),),
             between=True),
        # a macro call alone on its line, not heading a body: RAPIDJSON_DIAG_OFF(effc++)
        Rule(at_line_start(rb"[ \t]*+(" + macro + ARGS + rb")" + line_end
                            + rb"(?!\s*[{:,.=])"), between=True, alone=True),
        # in a body, a macro call alone on its line that the next line does not continue:
        # OP(Py_LT, lt) in a switch (a statement macro, its `;` inside)
        Rule(at_line_start(rb"[ \t]*+(" + macro + ARGS + rb")" + line_end
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
        Rule(at_line_start(rb"[ \t]*+((?>" + macro + ARGS + rb"?+[ \t]++)++)(?=" + _LEADING
                            + rb")"), between=True),
        # HWY_API Vec128<T, N> operator==(   NPY_NO_EXPORT PyObject *f(   (macros heading a
        # declaration, before a type and a declarator: two types side by side are no C; the
        # run gives back its last word if that is the type: HWY_API T GetLane(
        # static HWY_INLINE HWY_MAYBE_UNUSED bool f(   (after keywords, before keywords too;
        # template NPY_NO_EXPORT int f<T>(   an explicit instantiation)
        Rule(at_line_start(rb"[ \t]*+(?:(?:static|inline|extern|constexpr|virtual|explicit"
                            rb"|friend|template)[ \t]++)*+((?>" + macro + ARGS
                            + rb"?+[ \t]++)+)(?=(?:" + _LEADING + rb"\s++)*"
                            + _TYPE_THEN_DECLARATOR + rb")"),
             before=True),
        # template <class D, HWY_IF_LANES_D(D, 1)>   (macros as template parameters, the list
        # closed at the end of its line or before a declaration's keyword, or a `typename`
        # parameter next)
        Rule((_scan(b",", rb"(,\s*+" + macro + ARGS + rb"(?>\s*+,\s*+" + macro + ARGS
                       + rb")*+)(?=\s*+(?:>[ \t]*+(?:\n|//|/\*|(?:class|struct|union|using|static"
                       rb"|inline|constexpr|friend|typename)\b)|,\s*+(?:typename|class)\b))"),),
             before=True),
        # POCKETFFT_NOINLINE fftblue(size_t n) : n(n) {   (macros before a constructor, a
        # definition without a return type; known by its initializer list or `= default`:
        # before `{`, the macro could be the return type, `BOOL Check(int x) {`)
        Rule(at_line_start(rb"[ \t]*+(?:(?:inline|constexpr|explicit)[ \t]++)*+((?>" + macro
                            + ARGS + rb"?+[ \t]++)+)(?=~?" + _NAME + ARGS + _QUALIFIERS
                            + rb"\s*+(?::(?!:)|=\s*+(?:default|delete)\b))"), between=True),
        # bool done_ ABSL_GUARDED_BY(mu_) = false;    (a macro call after a declared name;
        # the type and the name on one line, read a word at a time)
        Rule(at_line_start(rb"[ \t]*+(?>" + _WORD + rb"[ \t]++)*?" + _WORD
                            + rb"(?<=[\w>*&])[ \t]++(?!" + _LEADING + rb"|" + _STATEMENT
                            + rb")[A-Za-z_]\w*+\s++(" + macro + ARGS
                            + rb"(?>\s*+" + macro + ARGS + rb")*+)(?=\s*+(?:;|=[^=]))"),
             between=True),
        # [&]() ABSL_EXCLUSIVE_LOCKS_REQUIRED(mu_) { ... }   (after a lambda's parameters)
        Rule((_scan(rb"\]", rb"\]\s*+" + ARGS + _QUALIFIERS + rb"\s*+((?>" + macro + ARGS
                         + rb"?+\s*+)++)(?=\{|->|mutable\b|noexcept\b)"),)),
        # ABSL_FLAG(int, name, 0, "help");  a type among a macro call's arguments: the type's
        # words (not blanked: rewritten as one identifier of the same length) in group 1;
        # in a body too: ASSERT_HEX(unsigned short, 2badU);
        Rule(at_line_start(rb"[ \t]*+" + macro + rb"(" + ARGS + rb")"), types=True),
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
        Rule(at_line_start(rb"[ \t]*+(" + macro + rb")[ \t]*+(?=\{)")),
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
