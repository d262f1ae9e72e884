"""Functions no reader of the source would name: ours (made up) and lizard's (its inventions).

Shared by benchmarks/made_up_functions.py and benchmarks/oracle_c.py. Independent of the
parser's own checks (archmetrics/parsers/c_family_trust.py): the keyword list, the macro
definitions and the spans are read here again, from the source and from lizard.

A function of ours is made up when
  * its name is a C or C++ keyword (``namespace``, ``if``, ``struct``);
  * its head is a call of a macro the file defines whose body is no function head
    (``OP(mtx) {`` after ``#define OP(m) {NAME(#m), CHILD(m)},``; a macro that ends in a
    declarator, ``#define TEST_BEGIN(f) static void f(void)``, makes real functions named
    after it, as lizard and the test frameworks name them; a function declared with a
    type may share its name with a macro of another #if branch);
  * its span covers the start of a function lizard reports that is not a method of a class
    defined inside it (a head tree-sitter lost, swallowed with its body).

A function of lizard's is its invention (left out of "lizard's real functions") when
  * its name is a keyword (``if (l_likely(L)) {`` read as a function named ``if``);
  * it spans the starts of two or more of lizard's or our functions (a macro that made it
    lose its way: it reads on to some later ``}``);
  * it lies inside a multi-line ``#define`` (lizard reads a macro's body as code; the
    function exists only where the macro is used);
  * it lies inside another function lizard reports (``HWY_IF_CONSTEXPR(c) {`` in a body);
  * it is a method of a class defined inside one of our functions (our rule, and lizard's
    own when it sees the function around it: docs/metrics.md, v_g);
  * it is a call inside an expression (an operator or ``return`` before its name: ``k =
    c ? ir_khash(as, key) : 1;`` after lizard closed the function around it too early), or
    its parentheses hold an expression (``HWY_IF_CONSTEXPR(!k) {``);
  * it is one of our functions cut short: the same name, starting in its head, ending
    before it (a brace initializer in ``noexcept(...)`` read as the body);
  * it is a class, a variable's brace initializer or a declaration and a later block
    (an attribute macro after ``struct``, ``x ABSL_GUARDED_BY(mu){...};``, a prototype,
    ``#endif``, then ``enum {``).

Those last three are also no evidence against ours: a function of ours that covers one of
them is not made up for it.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

KEYWORDS = frozenset(
    [
        "alignas",
        "alignof",
        "and",
        "and_eq",
        "asm",
        "auto",
        "bitand",
        "bitor",
        "bool",
        "break",
        "case",
        "catch",
        "char",
        "char8_t",
        "char16_t",
        "char32_t",
        "class",
        "compl",
        "concept",
        "const",
        "consteval",
        "constexpr",
        "constinit",
        "const_cast",
        "continue",
        "co_await",
        "co_return",
        "co_yield",
        "decltype",
        "default",
        "delete",
        "do",
        "double",
        "dynamic_cast",
        "else",
        "enum",
        "explicit",
        "export",
        "extern",
        "false",
        "float",
        "for",
        "friend",
        "goto",
        "if",
        "inline",
        "int",
        "long",
        "mutable",
        "namespace",
        "new",
        "noexcept",
        "not",
        "not_eq",
        "nullptr",
        "or",
        "or_eq",
        "private",
        "protected",
        "public",
        "register",
        "reinterpret_cast",
        "requires",
        "restrict",
        "return",
        "short",
        "signed",
        "sizeof",
        "static",
        "static_assert",
        "static_cast",
        "struct",
        "switch",
        "template",
        "this",
        "thread_local",
        "throw",
        "true",
        "try",
        "typedef",
        "typeid",
        "typename",
        "union",
        "unsigned",
        "using",
        "virtual",
        "void",
        "volatile",
        "wchar_t",
        "while",
        "xor",
        "xor_eq",
        "_Alignas",
        "_Alignof",
        "_Atomic",
        "_Bool",
        "_Generic",
        "_Noreturn",
        "_Static_assert",
        "_Thread_local",
    ]
)
_DEFINE = re.compile(r"^[ \t]*#[ \t]*define[ \t]+(\w+)(\([^)\n]*\))?((?:\\\n|[^\n])*)", re.M)


def keyword(name: str) -> bool:
    """Whether a function's (last) name is a keyword; `operator ...` and `~X` are not."""
    last = name.rsplit("::", 1)[-1].strip()
    return last in KEYWORDS


_ALIAS = re.compile(r"[A-Za-z_][\w:]*")


def macro_names(source: str) -> frozenset[str]:
    """The macros ``source`` defines whose body does not end in a function head after its
    last `;` or `}` (a test macro may define a class, then its method's head); a macro
    without parameters whose body is a (qualified) name is another name for what it names,
    and no such macro."""
    names = set()
    for found in _DEFINE.finditer(source):
        body = found.group(3).replace("\\\n", " ").rstrip(" \t\\")
        if found.group(2) is None and _ALIAS.fullmatch(body.strip()):
            continue  # `#define Buffer mock::Buffer`: another name for a real one
        last = body[max(body.rfind(";"), body.rfind("}")) + 1 :]
        outside = last
        while True:  # a default argument's `=` is no initializer's
            inner = re.sub(r"\([^()]*\)", "", outside)
            if inner == outside:
                break
            outside = inner
        if not (last.rstrip().endswith((")", "const")) and "=" not in outside):
            names.add(found.group(1))
    return frozenset(names)


def define_lines(source: str) -> set[int]:
    """The lines (1-based) of multi-line ``#define``s after their first."""
    inside: set[int] = set()
    continued = False
    for number, line in enumerate(source.splitlines(), 1):
        if continued:
            inside.add(number)
        stripped = line.rstrip()
        starts = re.match(r"[ \t]*#[ \t]*define\b", line) is not None
        continued = stripped.endswith("\\") and (starts or continued)
    return inside


@dataclass(frozen=True, slots=True)
class Ours:
    name: str
    start: int
    end: int
    vg: int
    estimated: bool


@dataclass(frozen=True, slots=True)
class Theirs:
    name: str
    start: int
    end: int
    vg: int


def made_up(
    ours: list[Ours],
    theirs: list[Theirs],
    macros: frozenset[str],
    local_classes: list[tuple[int, int]],
    lines: list[str],
) -> list[tuple[Ours, str]]:
    """Each of ``ours`` that is made up, with why; ``local_classes``: the spans of classes
    defined inside our functions; ``lines``: the source's."""
    found: list[tuple[Ours, str]] = []
    for function in ours:
        last = function.name.rsplit("::", 1)[-1]
        if keyword(function.name):
            found.append((function, "keyword"))
        elif last in macros and _called(lines, function, last):
            found.append((function, "a macro the file defines"))
        else:
            covered = [
                other
                for other in theirs
                if function.start < other.start <= function.end
                and other.end < function.end
                and not any(s <= other.start and other.end <= e for s, e in local_classes)
                and not keyword(other.name)
                and not call_read_as_function(lines, other)
                and not no_function(lines, other)
                and not same_head(lines, function, other)
            ]
            if covered:
                found.append((function, f"covers {covered[0].name} at {covered[0].start}"))
    return found


_OPERATOR_BEFORE = re.compile(r"(?:[-=?(,+/%|^!]|(?<!:):|\breturn)\s*$")
_CHAINED = re.compile(r"\s*->\s*(?!decltype\b)\w+\s*\(")
_CLASS_KEYWORD = re.compile(r"\b(?:struct|union|class|enum)\b")
_EXPRESSION = re.compile(r"!(?!=)|==|->|[A-Za-z_)]\.[A-Za-z_]")


def same_head(lines: list[str], function: Ours, other: Theirs) -> bool:
    """Whether lizard's ``other`` is ``function`` cut short: the same name, starting in its
    head (before the line of its first `{`) and ending before it (lizard took a brace
    initializer in a ``noexcept(...)`` or ``decltype(...)`` for the body, or closed it at
    a `}` of one #if branch)."""
    short = other.name.rsplit("::", 1)[-1].replace(" ", "")  # lizard: `operator ( )`
    if function.name.rsplit("::", 1)[-1].replace(" ", "") != short or not (
        function.start <= other.start and other.end < function.end
    ):
        return False
    first = next(
        (n for n in range(function.start, function.end + 1) if "{" in lines[n - 1]),
        function.end,
    )
    return other.start <= first


def call_read_as_function(lines: list[str], other: Theirs) -> bool:
    """Whether lizard's function ``other`` is a call inside an expression, not a definition:
    an operator or ``return`` stands before its name on its line (``khash = isk ?
    ir_khash(as, irkey) : 1;`` after lizard closed the function around it too early), or
    its parentheses hold an expression no parameter list holds (``HWY_IF_CONSTEXPR(!k) {``:
    `!`, `==`, `->`, a member)."""
    if not 0 < other.start <= len(lines):
        return False
    short = other.name.rsplit("::", 1)[-1]
    text = lines[other.start - 1]
    at = text.find(short + "(")
    if at < 0:
        at = text.find(short)
    if at < 0:
        return False
    if _OPERATOR_BEFORE.search(text[:at]):
        return True
    rest = "\n".join(lines[other.start - 1 : other.start + 4])[at + len(short) :]
    depth, inside = 0, []
    for char in rest.lstrip():
        depth += (char == "(") - (char == ")")
        inside.append(char)
        if depth == 0:
            break
    after = rest.lstrip()[len(inside) :]
    return bool(_EXPRESSION.search("".join(inside)) or _CHAINED.match(after))


def no_function(lines: list[str], other: Theirs) -> bool:
    """Whether lizard's function ``other`` is a class, a variable's brace initializer or a
    declaration followed by some block: its name is an attribute macro (in capitals, or
    ``__attribute__``) after ``struct``/``union``/``class``/``enum`` (``struct
    ABSL_DEPRECATED("...") Breakdown {``, ``typedef union __attribute__((packed)) U {``) or
    whose braces close with ``};`` (``Tracker state_ ABSL_GUARDED_BY(mu_){"name", READY};``),
    or a `;` ends its head before a class keyword and the `{` (``void ev_walk(...)
    EV_NOEXCEPT;`` / ``#endif`` / ``enum {``), or its `{` stands inside its head's
    parentheses (``static auto check(seq<I...>) -> decltype(all(seq<I...>{}, ...));``, a
    declaration)."""
    if not 0 < other.start <= len(lines):
        return False
    short = other.name.rsplit("::", 1)[-1]
    text = lines[other.start - 1]
    at = text.find(short)
    if at < 0:
        return False
    macro = short.startswith("__") or (short.upper() == short and any(c.isalpha() for c in short))
    if macro and _CLASS_KEYWORD.search(text[:at]):
        return True
    body = "\n".join(lines[other.start - 1 : other.end])[at:]
    if macro and re.search(r"\}\s*;\s*(?://.*)?$", body.rstrip()):
        return True
    head = body.split("{", 1)[0]
    depth = 0
    for index, char in enumerate(head):
        depth += (char == "(") - (char == ")")
        if char == ";" and depth == 0:
            return bool(_CLASS_KEYWORD.search(head[index:] + "{"))
    return depth > 0 and "{" in body  # `auto f() -> decltype(g(seq<I>{}))`: a declaration


def _called(lines: list[str], function: Ours, name: str) -> bool:
    """Whether ``function``'s head is a call of ``name`` (``OP(mtx) {``): no type before it,
    as in a real function that shares a macro's name in another #if branch (``static void
    LUAI_TRY (lua_State *L, ...) {`` beside ``#define LUAI_TRY(L,c,f,ud) ...``)."""
    head = " ".join(lines[function.start - 1 : function.end]).split("(", 1)[0]
    return head.strip() == name


def invention(
    other: Theirs,
    theirs: list[Theirs],
    ours: list[Ours],
    defines: set[int],
    local_classes: list[tuple[int, int]],
    lines: list[str] | None = None,
) -> str | None:
    """The class of lizard's invention ``other`` is, or None for a real function."""
    if keyword(other.name):
        return "keyword"
    # the classes read from the text only for a function none of ours matches (a
    # constructor lizard names after its last member initializer, `: data_(rhs.data_) {`,
    # is a real one both report)
    matched = any(f.end == other.end and f.start <= other.start for f in ours)
    if lines is not None and not matched and call_read_as_function(lines, other):
        return "a call read as a function"
    if lines is not None and any(same_head(lines, f, other) for f in ours):
        return "the same function cut short"
    if lines is not None and not matched and no_function(lines, other):
        return "a class, an initializer or a declaration read as a function"
    if other.start in defines:
        return "inside a #define"
    inner = {f.start for f in theirs if other.start < f.start and f.end <= other.end}
    inner |= {f.start for f in ours if other.start < f.start and f.end <= other.end}
    if len(inner) >= 2:
        return "spans other functions"
    if any(f.start < other.start and other.end <= f.end for f in theirs if f is not other):
        return "inside another of its functions"
    if any(s <= other.start and other.end <= e for s, e in local_classes):
        return "method of a class inside a function"
    return None


_KEYWORDS_NOT_CALLED = KEYWORDS | {"defined", "__attribute__", "__declspec", "typeof"}
_HEADERS = frozenset({"if", "for", "switch", "case", "default", "catch", "while"})
_DIRECTIVE_STATEMENTS = re.compile(r"#\s*(?:define|include|undef|pragma|error|line|import)\b")


def recount(source: str, first: int, last: int) -> tuple[int, int]:
    """(statements, calls) that begin or end on lines ``first``..``last``, counted again
    on lizard's tokens, independently of the parser: a statement per `;` outside
    parentheses, per statement keyword (``if``, ``case``...; a do-while's ``while`` aside)
    and per counted directive (``#define``, ``#include``...); a call per word before a
    `(` that is no keyword, has no word before it (a declaration ``T x(1)``) and heads no
    block (``FOR_EACH(x) {``)."""
    from lizard_languages.clike import CLikeReader

    tokens: list[tuple[str, int]] = []
    line = 1
    for token in CLikeReader.generate_tokens(source):
        if not token.isspace() and not token.startswith(("//", "/*")):
            tokens.append((token, line))
        line += token.count("\n")
    statements = calls = depth = 0
    for index, (token, at) in enumerate(tokens):
        depth += (token == "(") - (token == ")")
        if not first <= at <= last:
            continue
        before = tokens[index - 1][0] if index else ""
        if _statement(token, before, depth):
            statements += 1
        elif _a_call(tokens, index, before):
            calls += 1
    return statements, calls


def _statement(token: str, before: str, depth: int) -> bool:
    if token == ";":
        return depth <= 0
    if token in _HEADERS:
        return not (token == "while" and before == "}")
    return token.startswith("#") and _DIRECTIVE_STATEMENTS.match(token) is not None


def _a_call(tokens: list[tuple[str, int]], index: int, before: str) -> bool:
    token = tokens[index][0]
    if not (token[:1].isalpha() or token[:1] == "_") or token in _KEYWORDS_NOT_CALLED:
        return False
    if index + 1 >= len(tokens) or tokens[index + 1][0] != "(":
        return False
    if (before[:1].isalnum() or before[:1] == "_") and before not in ("return", "case", "else"):
        return False
    depth = 0
    for after in range(index + 1, min(len(tokens), index + 400)):
        depth += (tokens[after][0] == "(") - (tokens[after][0] == ")")
        if depth == 0:
            return after + 1 >= len(tokens) or tokens[after + 1][0] != "{"
    return True
