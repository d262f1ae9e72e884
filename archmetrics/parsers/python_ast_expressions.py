"""Expressions for the ``ast`` reader: where nodes sit in the tokens, decision points, calls.

libcst keeps the parentheses around an expression as part of it (``lpar``/``rpar``); ``ast``
leaves them out, so where a conditional expression or a call starts is found by widening
its tokens over them (``Tokens.widen``). Keywords ``ast`` gives no position (a
comprehension's ``for`` and ``if``, an ``and``) are found next to the nodes around them.
Inside an f-string, libcst sees one token; calls and decision points there are read from
their replacement field's own text, with their own lines.
"""

from __future__ import annotations

import ast
from dataclasses import dataclass, field

from archmetrics.facts import CallSite, Span
from archmetrics.parsers.python_ast_calls import call_parts
from archmetrics.parsers.python_ast_rules import (
    COMPREHENSIONS,
    STRING_TEMPLATES,
    replacement_fields,
)
from archmetrics.parsers.python_bindings import accessors_only
from archmetrics.parsers.python_lex import LineOffsets, Tokens, Unreadable
from archmetrics.parsers.python_shown import PendingCall, Shown, call_site, texts_of

# Fields that never hold an expression (names, operators, flags), skipped by the walk.
_LEAF_FIELDS = frozenset(
    {
        *("ctx", "op", "ops", "id", "attr", "arg", "kind", "conversion", "is_async", "str"),
        *("type_comment", "simple", "names", "name", "module", "level", "asname"),
    }
)
_CHILD_FIELDS: dict[type, tuple[str, ...]] = {ast.Constant: (), ast.Name: ()}
_ACTIVE = frozenset({ast.Call, *STRING_TEMPLATES, ast.IfExp, ast.BoolOp, *COMPREHENSIONS})


@dataclass(slots=True)
class Frame:
    """A function being read: its decisions as (file offset, kind, line) and its statements."""

    qualified_name: str
    decisions: list[tuple[int, str, int]] = field(default_factory=list)
    statements: int = 0


class ExpressionReader:
    """Positions and expressions of one file; the statement walk builds on it."""

    def __init__(self, source: str):
        self.source = source
        self.offset = LineOffsets(source)
        self.tokens = Tokens(source)
        self.tokens.texts = Shown(self.tokens.text, precise=True)
        self.funcs: list[Frame] = []  # enclosing functions: statements and calls go to [-1]
        self.calls: list[tuple[tuple[int, int], CallSite | PendingCall]] = []
        # assigned values: their first token -> (the target, the token after the value)
        self.assigned: dict[int, tuple[str, int]] = {}

    # -- positions --------------------------------------------------------------------------
    def first(self, node: ast.AST, tokens: Tokens | None = None) -> int:
        """Index of the token a node starts at."""
        tokens = self.tokens if tokens is None else tokens
        line, column = node.lineno, node.col_offset  # type: ignore[attr-defined]
        index = tokens.at(self.offset(line, column))
        if index < 0:
            raise Unreadable(f"no token where a node starts, line {line}")
        return index

    def end(self, node: ast.AST, tokens: Tokens | None = None) -> int:
        """Index of the token after a node."""
        tokens = self.tokens if tokens is None else tokens
        line, column = node.end_lineno, node.end_col_offset  # type: ignore[attr-defined]
        return tokens.after(self.offset(line, column))

    def span(self, first: int, end: int, tokens: Tokens | None = None) -> Span:
        """Lines of tokens ``first:end``."""
        tokens = self.tokens if tokens is None else tokens
        start = tokens.starts[first]
        return Span(start, max(start, tokens.ends[end - 1]))

    def owner(self) -> str | None:
        """Qualified name of the innermost enclosing function (Statement/CallSite.function)."""
        return self.funcs[-1].qualified_name if self.funcs else None

    # -- decision points and calls ----------------------------------------------------------
    def decide(
        self, target: Frame | None, kind: str, index: int, tokens: Tokens | None = None
    ) -> None:
        """A decision point at token ``index`` (of the file, or of an f-string's field)."""
        if target is not None:
            tokens = self.tokens if tokens is None else tokens
            position = tokens.base + tokens.offsets[index]
            target.decisions.append((position, kind, tokens.starts[index]))

    def expressions(
        self, roots: list[ast.AST | None], target: Frame | None, tokens: Tokens | None = None
    ) -> None:
        """Calls (always) and decision points (for ``target``) in and under these nodes."""
        tokens = self.tokens if tokens is None else tokens
        stack = list(roots)
        children = _CHILD_FIELDS
        while stack:
            node = stack.pop()
            if not isinstance(node, ast.AST):
                continue  # an absent child (None), or a field the walk does not know
            kind = type(node)
            if kind in _ACTIVE:
                if kind in STRING_TEMPLATES:
                    for value in replacement_fields(node):  # type: ignore[arg-type]
                        self.expressions([value], target, self.field_tokens(value))
                    continue
                if kind is ast.Call:
                    self.call(node, tokens)  # type: ignore[arg-type]
                elif target is not None:
                    self.decisions(node, target, tokens)
            names = children.get(kind)
            if names is None:
                names = children[kind] = tuple(n for n in node._fields if n not in _LEAF_FIELDS)
            for name in names:
                value = getattr(node, name)
                if type(value) is list:
                    stack.extend(value)
                else:
                    stack.append(value)

    def decisions(self, node: ast.AST, target: Frame, tokens: Tokens) -> None:
        """The decision points of a conditional expression, a boolean operation or a
        comprehension, each at the token that makes it one."""
        kind = type(node)
        if kind is ast.IfExp:
            first, _ = tokens.widen(self.first(node, tokens), self.end(node, tokens))
            self.decide(target, "ifexp", first, tokens)
        elif kind is ast.BoolOp:
            word = "and" if type(node.op) is ast.And else "or"  # type: ignore[attr-defined]
            for value in node.values[:-1]:  # type: ignore[attr-defined]
                index = self.end(value, tokens)
                while tokens.text[index] != word:
                    index += 1
                self.decide(target, word, index, tokens)
        else:
            for generator in node.generators:  # type: ignore[attr-defined]
                index = tokens.before(self.first(generator.target, tokens), "for")
                self.decide(target, "comp_for", index - generator.is_async, tokens)
                for condition in generator.ifs:
                    where = tokens.before(self.first(condition, tokens), "if")
                    self.decide(target, "comp_if", where, tokens)

    def call(self, node: ast.Call, tokens: Tokens) -> None:
        first = self.first(node, tokens)
        value = None
        func = node.func
        if type(func) is ast.Attribute:
            value = tokens.widen(self.first(func.value, tokens), self.end(func.value, tokens))
        parts, open_, close = call_parts(tokens, node, first, lambda n: self.end(n, tokens), value)
        callee, name, receiver, arguments = parts
        span = self.span(*tokens.widen(first, close + 1), tokens=tokens)
        texts = texts_of(tokens)
        order = (tokens.base + tokens.offsets[first], -(tokens.base + tokens.offsets[close]))
        function = self.owner()
        target = None
        if tokens is self.tokens and first in self.assigned:
            name_, stop = self.assigned[first]
            if close + 1 == stop or accessors_only(tokens.text[close + 1 : stop]):
                target = name_
        if texts.note_call(first, open_, close + 1):  # long: its texts wait for all calls
            made = PendingCall(texts, callee, name, receiver, span, arguments, function, target)
            self.calls.append((order, made))
        else:
            site = call_site(texts, callee, name, receiver, span, arguments, function, target)
            self.calls.append((order, site))

    def field_tokens(self, value: ast.expr) -> Tokens:
        """Tokens of an f-string replacement field's expression, read on their own."""
        start = self.offset(value.lineno, value.col_offset)
        stop = self.offset(value.end_lineno or value.lineno, value.end_col_offset or 0)
        source = self.source
        while True:  # the parentheses around the expression are its own
            before, after = start - 1, stop
            while source[before].isspace():
                before -= 1
            while source[after].isspace():
                after += 1
            if source[before] != "(" or source[after] != ")":
                break
            start, stop = before, after + 1
        line = self.offset.line_of(start)
        tokens = Tokens(f"({source[start:stop]})", base=start - 1, first_line=line)
        tokens.closing.pop(0, None)  # the wrapping parentheses are not the expression's
        return tokens
