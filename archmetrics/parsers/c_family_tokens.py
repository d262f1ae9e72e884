"""A second reading of C and C++: tokens, not a syntax tree (docs/metrics.md, "Warnings").

Where tree-sitter cannot read a region (an ``ERROR``, a token it had to invent, a shape it
reads as something else), facts there would be lost, or made up. This reading follows the
design of lizard's C reader (a state machine over tokens that knows function heads, scopes
and braces, but no grammar): it finds every function definition of a file and the decision
tokens in its body, and where statements and calls begin. It reads the tokens of every
``#if`` branch, but takes the brace structure of each group's first branch, as one
configuration of the preprocessor would. ``c_family_trust`` compares the two readings.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from archmetrics.parsers.c_family_heads import (
    CLASS,
    FUNCTION,
    KEYWORDS,
    NAMESPACE,
    Head,
    classify,
    member_initializer,
    opens_kr,
)

# a token: (kind, text, byte offset); kinds: w word, p directive, q string, n number,
# o operator (a comparison is one: the `>=` of `enable_if_t<sizeof(a) >= 4, T>` closes no
# template arguments and is no initializer's `=`)
Token = tuple[str, bytes, int]

_TOKENS = re.compile(
    rb"(?P<s>//(?:\\\r?\n|[^\n])*+|/\*(?:[^*]|\*(?!/))*+(?:\*/|\Z)|\\\r?\n)"
    rb'|(?P<q>(?:u8|[uUL])?R"(?P<d>[^()\\\s"]{0,16})\((?:[^)]|\)(?!(?P=d)"))*+(?:\)(?P=d)"|\Z)'
    rb"|(?:u8|[uUL])?\"(?:\\.|[^\"\\\n])*+\"?|(?:u8|[uUL])?'(?:\\.|[^'\\\n])*+'?)"
    rb"|(?P<p>^[ \t]*+\#(?:[^\n\\/]++|\\.|/\*(?:[^*]|\*(?!/))*+(?:\*/|\Z)|/)*+)"
    rb"|(?P<w>[A-Za-z_$][\w$]*+)"
    rb"|(?P<n>\.?\d(?:[eEpP][-+]|['\w.])*+)"
    rb"|(?P<o>::|->|&&|\|\||>>=|<<=|[<>=!]=|[^\s\w])",
    re.M | re.S,
)
_DIRECTIVE = re.compile(rb"[ \t]*+\#[ \t]*+(\w*)")
_LONGEST_KR = 1_000  # tokens: a K&R head with its parameters' declarations is shorter
#: directive keywords that are decisions in a body (docs/metrics.md, v_g table)
_DECIDING = frozenset({b"if", b"ifdef", b"ifndef", b"elif", b"elifdef", b"elifndef"})
#: directives that are one statement each (λ table)
_STATEMENT_DIRECTIVES = frozenset(
    {b"define", b"include", b"undef", b"pragma", b"error", b"line", b"import"}
)
_WORD_DECISIONS = {b"if": "if", b"for": "for", b"while": "while", b"case": "case"}
_CPP_WORDS = {b"catch": "catch", b"and": "&&", b"or": "||"}
_NOT_REFERENCE = frozenset({b")", b",", b">", b"...", b"="})
_HEADER_WORDS = frozenset({b"if", b"for", b"switch", b"case", b"default", b"catch", b"while"})
_NOT_CALLED = KEYWORDS | {b"defined", b"__typeof", b"_Pragma", b"__pragma"}  # casts too: int(x)


def tokens(data: bytes, start: int = 0, end: int | None = None) -> list[Token]:
    """The tokens of ``data[start:end]``, comments dropped."""
    return [
        (kind, found.group(), found.start())
        for found in _TOKENS.finditer(data, start, len(data) if end is None else end)
        if (kind := found.lastgroup or "s") != "s"
    ]


@dataclass(slots=True)
class TokenFunction:
    """A function definition as the token reading found it: its head from ``start``, its
    name at ``name_at``, its body from the ``{`` at ``body_start`` to ``end``; each
    decision as (kind, byte offset)."""

    name: str
    qualified: str
    start: int
    name_at: int
    body_start: int
    end: int = -1
    decisions: list[tuple[str, int]] = field(default_factory=list)


@dataclass(slots=True)
class TokenReading:
    """What the token reading found: the functions, and the byte offsets where each
    statement (not a function's head) and call begins (calls: in function bodies)."""

    functions: list[TokenFunction]
    statements: list[int]
    calls: list[int]
    defines_in_blocks: list[int]  # `#define` lines inside an initializer or other block
    unclosed: list[int]  # where a function or head begins whose brackets never close


@dataclass(slots=True)
class _State:
    """Where the reading stands: the scopes open (kind, qualified name), the head read so
    far at a scope's level, the function being read and its brace depth."""

    scopes: list[tuple[str, str, int]]  # (kind, qualified name, first token of its head)
    head: list[int]
    function: TokenFunction | None = None
    depth: int = 0  # braces open in the function body, or in a block skipped at scope level
    parens: int = 0  # parentheses open in the head
    kr: bool = False  # the head is a K&R definition's: its `;`s do not end it
    in_head: bool = False  # the block skipped is part of the head (`a_{1}`, a lambda)

    def copy(self) -> _State:
        """A copy for an #if branch to return to. The head is shared, not copied: a head
        may run over thousands of #if groups (macros without `;`), and a head read in two
        branches is still one head (``int f(int a)`` / ``#else`` / ``int f(long a)``)."""
        return _State(
            list(self.scopes),
            self.head,
            self.function,
            self.depth,
            self.parens,
            self.kr,
            self.in_head,
        )


class _Reader:
    """One pass over a file's tokens (``read``)."""

    def __init__(self, toks: list[Token], cpp: bool) -> None:
        self.toks = toks
        self.words = {**_WORD_DECISIONS, **_CPP_WORDS} if cpp else dict(_WORD_DECISIONS)
        self.state = _State([(NAMESPACE, "", 0)], [])
        self.groups: list[list[_State | None]] = []  # per open #if: [at #if, after branch 1]
        self.found: list[TokenFunction] = []
        self.done: set[int] = set()
        self.statements: list[int] = []
        self.calls: list[int] = []
        self.statement_start = -1
        self.defines_in_blocks: list[int] = []

    def read(self) -> TokenReading:
        toks = self.toks
        for index, (kind, text, at) in enumerate(toks):
            state = self.state
            if kind == "p":
                self._directive(text, at)
            elif state.function is not None:
                self._in_body(index, kind, text, at)
            elif state.depth:  # a block at scope level that is no function: skipped
                state.depth += (text == b"{") - (text == b"}")
                if kind == "w" and text not in _NOT_CALLED and self._called(index):
                    self.calls.append(at)  # a call in an initializer
                if not state.depth and state.in_head:
                    state.head.append(index)
                    state.in_head = False
            else:
                self._at_scope(index, kind, text)
        state = self.state
        unclosed = [state.function.start] if state.function is not None else []
        if state.head and (state.parens or state.depth):  # a head left open: `f( {`
            unclosed.append(self.toks[state.head[0]][2])
        return TokenReading(
            sorted(self.found, key=lambda f: f.start),
            self.statements,
            self.calls,
            self.defines_in_blocks,
            unclosed,
        )

    def _in_body(self, index: int, kind: str, text: bytes, at: int) -> None:
        state = self.state
        function = state.function
        assert function is not None
        if self.statement_start < 0 and text not in (b"{", b"}", b";"):
            self.statement_start = at
        if kind == "w":
            decision = self.words.get(text)
            if decision is not None:
                function.decisions.append((decision, at))
            if text in _HEADER_WORDS and not self._do_while_tail(index, text):
                self.statements.append(at)
                self.statement_start = -1
            elif text not in _NOT_CALLED and self._called(index):
                self.calls.append(at)
            return
        if text == b"{":
            state.depth += 1
            self.statement_start = -1
        elif text == b"}":
            state.depth -= 1
            self.statement_start = -1
            if not state.depth:
                self._end_function(index, function)
        elif text == b";":
            if state.parens == 0 and self.statement_start >= 0:
                self.statements.append(self.statement_start)
            self.statement_start = -1
        elif text == b"(":
            state.parens += 1
        elif text == b")":
            state.parens = max(0, state.parens - 1)
        elif text == b"&&":
            following = self.toks[index + 1][1] if index + 1 < len(self.toks) else b""
            before = self.toks[index - 1][1]
            if following not in _NOT_REFERENCE and before not in (b"auto", b">", b"("):
                function.decisions.append(("&&", at))
        elif text in (b"||", b"?"):
            function.decisions.append((text.decode(), at))
        elif text == b":" and state.parens == 0:  # a label or `case x:` ends there
            self.statement_start = -1

    def _do_while_tail(self, index: int, text: bytes) -> bool:
        """Whether ``while`` at ``index`` ends a do-while (its `;` counts the statement)."""
        return text == b"while" and index > 0 and self.toks[index - 1][1] == b"}"

    def _called(self, index: int) -> bool:
        """Whether the word at ``index`` names a call: a `(` follows, no word (a type, in a
        declaration ``T x(1)``) or ``new`` comes before, and no block after its `)` (a
        macro heading a block, ``vmcase(OP_MOVE) {``, ``FOR_EACH(x) {``, expands to no
        call the tree would see)."""
        toks = self.toks
        if index + 1 >= len(toks) or toks[index + 1][1] != b"(":
            return False
        before = toks[index - 1]
        if before[0] == "w" and before[1] not in (b"return", b"case", b"else", b"do"):
            return False
        depth, at = 0, index + 1
        while at < len(toks) and at < index + 400:
            text = toks[at][1]
            depth += (text == b"(") - (text == b")")
            if depth == 0:
                return at + 1 >= len(toks) or toks[at + 1][1] != b"{"
            at += 1
        return True

    def _end_function(self, index: int, function: TokenFunction) -> None:
        toks = self.toks
        if index + 1 < len(toks) and toks[index + 1][1] == b"catch":
            return  # a function-try-block: its handlers belong to it
        function.end = toks[index][2] + 1
        if id(function) not in self.done:
            self.done.add(id(function))
            self.found.append(function)
        self.state.function = None
        self.state.parens = 0

    def _at_scope(self, index: int, kind: str, text: bytes) -> None:
        state = self.state
        if kind == "o":
            if text == b"(":
                state.parens += 1
            elif text == b")":
                state.parens = max(0, state.parens - 1)
            elif state.parens:
                if text == b"{":  # a block in a head (a lambda as a default argument)
                    state.depth, state.in_head = 1, True
            elif text == b";":
                self._end_declaration(index)
                return
            elif text == b"{":
                if member_initializer(self.toks, state.head):  # `Foo() : a_{1}, b_{2} {`
                    state.depth, state.in_head = 1, True
                else:
                    self._open(index)
                    return
            elif text == b"}":
                state.head, state.kr = [], False
                if len(state.scopes) > 1:
                    kind, _, first = state.scopes.pop()
                    if kind == CLASS:  # `} name;` ends the statement the class head began
                        state.head = [first]
                return
            elif text == b":" and self._access_label(state.head):
                state.head = []
                return
        state.head.append(index)

    def _access_label(self, head: list[int]) -> bool:
        """Whether ``head`` is a class's access label before its `:`: one word (`public`,
        `MY_PRIVATE_UNLESS_TESTED`) or `public slots`."""
        toks = self.toks
        if self.state.scopes[-1][0] != CLASS or not head or toks[head[0]][0] != "w":
            return False
        return len(head) == 1 or (len(head) == 2 and toks[head[1]][1] in (b"slots", b"Q_SLOTS"))

    def _end_declaration(self, index: int) -> None:
        state = self.state
        head = state.head
        if head:
            begins = next(
                (p + 1 for p in range(len(head) - 1, -1, -1) if self.toks[head[p]][1] == b";"), 0
            )  # after a K&R head's earlier declarations
            if begins < len(head):
                self.statements.append(self.toks[head[begins]][2])
        if len(head) > _LONGEST_KR:  # no K&R head is this long: no quadratic walk back
            state.kr = False
        elif state.kr or (len(state.scopes) == 1 and opens_kr(self.toks, head)):
            state.kr = True
            state.head.append(index)
            return
        state.head = []

    def _open(self, index: int) -> None:
        state = self.state
        first = state.head[0] if state.head else index
        head: Head = classify(self.toks, state.head, state.scopes[-1][1])
        state.head, state.kr = [], False
        if head.kind == FUNCTION:
            state.function = TokenFunction(
                head.name, head.qualified, head.start, head.name_at, self.toks[index][2]
            )
            state.depth, state.parens, self.statement_start = 1, 0, -1
        elif head.kind is not None:
            state.scopes.append((head.kind, head.qualified, first))
        else:
            state.depth = 1

    def _directive(self, text: bytes, at: int) -> None:
        keyword = _DIRECTIVE.match(text)
        word = keyword.group(1) if keyword else b""
        state = self.state
        if state.function is not None and word in _DECIDING:
            state.function.decisions.append(("#" + word.decode(), at))
        if word in _STATEMENT_DIRECTIVES:
            self.statements.append(at)
            if word == b"define" and state.function is None and state.depth:
                self.defines_in_blocks.append(at)
        if word in (b"if", b"ifdef", b"ifndef"):
            self.groups.append([state.copy(), None])
        elif word.startswith(b"el") and self.groups:
            group = self.groups[-1]
            if group[1] is None:
                group[1] = state.copy()
            opened = group[0]
            assert opened is not None
            self.state = opened.copy()
        elif word == b"endif" and self.groups:
            first = self.groups.pop()[1]
            if first is not None:
                self.state = first


def read(data: bytes, cpp: bool, windows: list[tuple[int, int]] | None = None) -> TokenReading:
    """The token reading of ``data``, or of each of ``windows`` (sorted, disjoint byte
    ranges that start where the syntax tree stands between declarations). ``cpp``: C++'s
    `catch`, `and`, `or` count. A window whose reading ends inside a body or a head is read
    again to the end of the file: its end was no boundary for the tokens."""
    size = len(data)
    spans = windows if windows is not None else [(0, size)]
    readings: list[TokenReading] = []
    reached = 0
    for start, end in spans:
        start = max(start, reached)
        if start >= end:
            continue
        reading = _Reader(tokens(data, start, end), cpp).read()
        if reading.unclosed and end < size:
            end = size
            reading = _Reader(tokens(data, start, end), cpp).read()
        reached = end
        readings.append(reading)
    return TokenReading(
        [f for r in readings for f in r.functions],
        [at for r in readings for at in r.statements],
        [at for r in readings for at in r.calls],
        [at for r in readings for at in r.defines_in_blocks],
        [at for r in readings for at in r.unclosed],
    )
