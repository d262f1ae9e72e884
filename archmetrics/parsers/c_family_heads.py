"""What a brace opens at file, namespace or class scope, in the token reading
(c_family_tokens.py): a function's body, a namespace, a class, an ``extern "C"`` block, or
a block that holds no function (an initializer, an enum, what cannot be told).

The head is the tokens since the last declaration ended. A function's head has a
parameter list after a name that is no keyword; of several (``DECLARE(x) TEST(A, b) {``,
``void f() LOCKS(mu) {``) the last one named in lower case wins, or the last one if all
are in capitals (a function-defining macro). Nothing here reads a grammar: a head that
fits no rule opens a block the reading skips, so a function is never made up from it.
"""

from __future__ import annotations

from dataclasses import dataclass

# a token: (kind, text, byte offset), as c_family_tokens makes them
Token = tuple[str, bytes, int]

FUNCTION = "function"
NAMESPACE = "namespace"
CLASS = "class"
LINKAGE = "linkage"

#: C and C++ keywords: never a function's name (docs/metrics.md, "Warnings")
KEYWORDS = frozenset(
    b"""alignas alignof and and_eq asm auto bitand bitor bool break case catch char char8_t
    char16_t char32_t class compl concept const consteval constexpr constinit const_cast
    continue co_await co_return co_yield decltype default delete do double dynamic_cast else
    enum explicit export extern false float for friend goto if inline int long mutable
    namespace new noexcept not not_eq nullptr or or_eq private protected public register
    reinterpret_cast requires restrict return short signed sizeof static static_assert
    static_cast struct switch template this thread_local throw true try typedef typeid
    typename union unsigned using virtual void volatile wchar_t while xor xor_eq _Alignas
    _Alignof _Atomic _Bool _Complex _Generic _Imaginary _Noreturn _Static_assert
    _Thread_local __attribute__ __declspec __asm__ __asm _asm __inline __inline__ __restrict
    __restrict__ __typeof__ typeof __extension__ __volatile__""".split()
)
#: words before a parenthesised group that is no parameter list
_NOT_DECLARATORS = KEYWORDS | {b"__attribute", b"_Pragma", b"__pragma", b"__stdcall"}
_STATEMENT_WORDS = frozenset(
    {b"if", b"else", b"for", b"while", b"do", b"switch", b"return", b"case", b"goto",
     b"break", b"continue", b"co_return", b"co_yield"}
)  # fmt: skip
_CLASS_WORDS = frozenset({b"class", b"struct", b"union"})


@dataclass(frozen=True, slots=True)
class Head:
    """What a ``{`` opens: ``kind`` (None: a block that holds no function), the name and
    qualified name of a function, namespace or class, where its head starts, its name."""

    kind: str | None
    name: str = ""
    qualified: str = ""
    start: int = 0
    name_at: int = 0


def _layout(toks: list[Token], head: list[int]) -> tuple[list[int], list[tuple[int, int]]]:
    """The positions in ``head`` outside parentheses and template arguments' brackets, and
    (position of `(`, of its `)`) of each parenthesised group among them, in order. A `<`
    after a word opens template arguments (a head at scope level compares nothing), but
    not after ``operator``."""
    top: list[int] = []
    groups: list[tuple[int, int]] = []
    parens = angles = opened = 0
    for position, index in enumerate(head):
        text = toks[index][1]
        if text == b"(":
            if parens == 0 and angles == 0:
                opened = position
            parens += 1
        elif text == b")":
            if parens:
                parens -= 1
                if parens == 0 and angles == 0:
                    groups.append((opened, position))
        elif parens:
            continue
        elif text == b"<" and position and toks[head[position - 1]][0] == "w":
            angles += toks[head[position - 1]][1] != b"operator"
            if angles == 0:
                top.append(position)
        elif text == b">" and angles:
            angles -= 1
        elif angles == 0:
            top.append(position)
    return top, groups


def _before_angles(toks: list[Token], head: list[int], at: int) -> int:
    """The position of the word before the template arguments that end at ``at`` (a `>`),
    or -1."""
    depth = 0
    while at >= 0:
        text = toks[head[at]][1]
        depth += (text == b">") - (text == b"<")
        if depth == 0:
            return at - 1
        at -= 1
    return -1


def _capitals(name: bytes) -> bool:
    return name.upper() == name and any(65 <= c <= 90 for c in name)


def _name(toks: list[Token], head: list[int], opened: int) -> tuple[str, int, str] | None:
    """(name, its position in ``head``, its qualifier) of the declarator whose parameter
    list opens at position ``opened``, or None if no name stands before it."""
    at = opened - 1
    operator = _operator(toks, head, at)
    if operator is not None:
        at, name = operator
    elif at >= 0 and toks[head[at]][1] == b">":  # `f<int>(`: a specialization's name
        at = _before_angles(toks, head, at)
    if at < 0:
        return None
    kind, word, _ = toks[head[at]]
    if operator is None:
        name = word
        if kind != "w" or word in _NOT_DECLARATORS:
            return None
    if at and toks[head[at - 1]][1] == b"~":
        name, at = b"~" + word, at - 1
    qualifier: list[bytes] = []
    while at >= 2 and toks[head[at - 1]][1] == b"::" and toks[head[at - 2]][0] == "w":
        qualifier.insert(0, toks[head[at - 2]][1])
        at -= 2
    return name.decode("utf-8", "replace"), at, "::".join(q.decode() for q in qualifier)


def _operator(toks: list[Token], head: list[int], at: int) -> tuple[int, bytes] | None:
    """(position of ``operator``, the name) if the tokens up to ``at`` end an operator's
    name: `operator()`, `operator==`, `operator new`, `operator bool`, `operator T<U>`."""
    for position in range(at, max(-1, at - 12), -1):
        text = toks[head[position]][1]
        if text == b"operator":
            name = b"operator" + b"".join(
                (b" " if toks[head[p]][0] == "w" else b"") + toks[head[p]][1]
                for p in range(position + 1, at + 1)
            )
            return position, name
        if text in (b"(", b";", b"{", b"}") and position < at - 1:
            return None
    return None


def _initializer_list(
    toks: list[Token], head: list[int], top: list[int], groups: list[tuple[int, int]]
) -> int:
    """Where a constructor's initializer list starts in ``head``: its first `:` outside
    brackets after a parameter list (``Foo(int a) : a_(a)``, ``Foo(bool b) NOEXCEPT :
    data_()``), or the head's end."""
    if not groups:
        return len(head)
    first = groups[0][1]
    return next((p for p in top if p > first and toks[head[p]][1] == b":"), len(head))


def _wrapped(toks: list[Token], head: list[int], opened: int, closed: int) -> int | None:
    """The position of the name a wrapper macro's argument declares, if the group from
    ``opened`` to ``closed`` holds a function's head: ``HEAP_EXPORT(void heap_init(struct
    heap* h))``, ``UV_UNUSED(static void f(uv_loop_t* loop))`` (a type before the name, no
    comma outside the inner parameter list)."""
    if toks[head[closed - 1]][1] != b")":
        return None
    depth, inner = 0, -1
    for position in range(closed - 1, opened, -1):
        text = toks[head[position]][1]
        depth += (text == b")") - (text == b"(")
        if depth == 0:
            inner = position
            break
    name = inner - 1
    if name <= opened + 1 or toks[head[name]][0] != "w" or toks[head[name]][1] in KEYWORDS:
        return None
    before = [toks[head[p]] for p in range(opened + 1, name)]
    if any(text == b"," for _, text, _ in before) or not any(k == "w" for k, _, _ in before):
        return None
    return name


def _declarator(toks: list[Token], head: list[int]) -> tuple[str, int, str] | None:
    """The function's name, position and qualifier, if ``head`` is a function's."""
    top, groups = _layout(toks, head)
    colon = _initializer_list(toks, head, top, groups)
    named = [
        (found, (opened, closed))
        for opened, closed in groups
        if opened < colon and (found := _name(toks, head, opened)) is not None
    ]
    if not named:
        return None
    lower = [item for item in named if not _capitals(item[0][0].encode())]
    chosen, group = (lower or named)[-1]
    if not lower:  # a wrapper macro around a declaration: the name it declares
        inner = _wrapped(toks, head, *group)
        if inner is not None:
            return toks[head[inner]][1].decode("utf-8", "replace"), inner, ""
    return chosen


def classify(toks: list[Token], head: list[int], scope: str) -> Head:
    """What the ``{`` after ``head`` (token indices) opens; ``scope``: the qualified name of
    the namespace or class around it."""
    if not head:
        return Head(None)
    top, _ = _layout(toks, head)
    words = [toks[head[p]][1] for p in top]
    start = toks[head[0]][2]
    if b"namespace" in words:
        at = words.index(b"namespace")
        name = "::".join(w.decode() for w in words[at + 1 :] if w not in (b"::", b"inline"))
        return Head(NAMESPACE, name, _join(scope, name), start)
    if words[0] == b"extern" and len(head) == 2 and toks[head[1]][0] == "q":
        return Head(LINKAGE, "", scope, start)
    assigned = b"=" in words and b"operator" not in words
    if assigned or b"enum" in words or any(w in _STATEMENT_WORDS for w in words):
        return Head(None)
    classed = [p for p in top if toks[head[p]][1] in _CLASS_WORDS]
    member = _declarator(toks, head[classed[-1] :]) if classed else None
    if classed and (member is None or _capitals(member[0].encode())):
        name = _class_name(toks, [head[p] for p in top if p > classed[-1]])
        return Head(CLASS, name, _join(scope, name), start)
    found = _declarator(toks, head)
    if found is None:
        return Head(None)
    name, at, qualifier = found
    qualified = _join(_join(scope, qualifier), name)
    begins = toks[head[_declaration_start(toks, head, at)]][2]
    return Head(FUNCTION, name, qualified, begins, toks[head[at]][2])


def _declaration_start(toks: list[Token], head: list[int], at: int) -> int:
    """Where the declaration whose name is at position ``at`` begins: back over words,
    `*`, `&`, `::`, attributes' brackets and template arguments, to the head's start or a
    token that ends something else (the `)` of a macro call before it)."""
    position = at
    while position > 0:
        kind, text, _ = toks[head[position - 1]]
        if kind == "w" or text in (b"*", b"&", b"&&", b"::", b"~", b"[", b"]"):
            position -= 1
        elif text == b">" and (before := _before_angles(toks, head, position - 1)) >= 0:
            position = before + 1
            if position and toks[head[position - 1]][0] == "w":
                position -= 1
        else:
            break
    return position


def _class_name(toks: list[Token], after: list[int]) -> str:
    """A class's name: the last word before its base clause's `:` (not `final`)."""
    name = ""
    for index in after:
        kind, text, _ = toks[index]
        if text == b":":
            break
        if (kind == "w" and text not in (b"final", b"alignas") and not _capitals(text)) or (
            kind == "w" and not name and text != b"final"
        ):
            name = text.decode("utf-8", "replace")
    return name


def _join(scope: str, name: str) -> str:
    return f"{scope}::{name}" if scope and name else scope or name


def opens_kr(toks: list[Token], head: list[int]) -> bool:
    """Whether ``head``, ended by a `;`, is a K&R definition's name and parameter names
    followed by the first parameter's declaration: ``char *f(a, b) int a;``."""
    _, groups = _layout(toks, head)
    if not groups:
        return False
    opened, closed = groups[-1]
    inside = [toks[head[p]] for p in range(opened + 1, closed)]
    declaration = [toks[head[p]] for p in range(closed + 1, len(head))]
    return (
        bool(inside)
        and all(kind == "w" or text == b"," for kind, text, _ in inside)
        and bool(declaration)
        and declaration[0][0] == "w"
        and all(kind == "w" or text in (b"*", b",", b"[", b"]") for kind, text, _ in declaration)
        and (found := _name(toks, head, opened)) is not None
        and not _capitals(found[0].encode())
    )


def member_initializer(toks: list[Token], head: list[int]) -> bool:
    """Whether a `{` after ``head`` is a member's brace initializer in a constructor's
    initializer list (``Foo() : a_{1}, b_{2} {``): a word or `>` before it, and a `:` after
    the head's parameter list."""
    if not head or (toks[head[-1]][0] != "w" and toks[head[-1]][1] != b">"):
        return False
    top, _ = _layout(toks, head)
    return any(toks[head[p]][1] == b":" and p and toks[head[p - 1]][1] == b")" for p in top)
