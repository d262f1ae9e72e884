"""Call sites and literals for the ``ast`` reader, read from the token stream.

Each call is taken apart on its tokens, as python_calls.py does on libcst's: the callee runs
from the call's first token to its own ``(``; each argument from one top-level comma to the
next. ``ast`` keeps positional and keyword arguments in separate lists; pairing them with the
comma-separated pieces in source order keeps the arguments in the order they were written.
"""

from __future__ import annotations

import ast
from collections.abc import Callable

from archmetrics.facts import Literal
from archmetrics.parsers.python_lex import Tokens, Unreadable
from archmetrics.parsers.python_shown import Text

EndOf = Callable[[ast.AST], int]  # a node -> the index of the token after it
ArgumentParts = tuple[Text, Literal, bool, str | None]  # text, value, is_literal, keyword
CallParts = tuple[Text, str | None, Text | None, tuple[ArgumentParts, ...]]
"""Callee, name (None: the callee's text), receiver, arguments; texts as token ranges."""


def dotted(node: ast.expr) -> str | None:
    """``a.b.c`` for a Name/Attribute chain, else None (a loop: chains can be long)."""
    if type(node) is ast.Name:
        return node.id
    names = []
    while type(node) is ast.Attribute:
        names.append(node.attr)
        node = node.value
    if type(node) is ast.Name:
        names.append(node.id)
    elif type(node) is ast.Constant and (node.value is None or type(node.value) is bool):
        names.append(str(node.value))  # libcst reads True, False and None as names
    else:
        return None
    names.reverse()
    return ".".join(names)


def call_parts(
    tokens: Tokens,
    node: ast.Call,
    first: int,
    end_of: EndOf,
    value: tuple[int, int] | None,
) -> tuple[CallParts, int, int]:
    """Callee, name, receiver and arguments of the call whose tokens start at ``first``
    (after the call's own parentheses) and whose callee ends before token ``func_end``;
    also the indexes of the call's own ``(`` and ``)``. ``end_of`` gives the token after a
    node; ``value`` is the token range of the receiver expression, for a parenthesized
    callee whose receiver is not a dotted name."""
    text = tokens.text
    func_end = open_ = end_of(node.func)
    while text[open_] == ")":
        open_ += 1
    close = tokens.closing.get(open_)
    if text[open_] != "(" or close is None:
        raise Unreadable(f"no argument list after the callee at line {tokens.starts[first]}")
    func = node.func
    callee: Text = dotted(func) or (first, open_)
    receiver: Text | None = None
    name = None
    if type(func) is ast.Attribute:
        name = func.attr
        receiver = dotted(func.value)
        if receiver is None and open_ == func_end:  # drop "." and the attribute name
            receiver = (first, open_ - 2)
        elif receiver is None and value is not None:
            receiver = value
    arguments = _arguments(tokens, node, open_, close, end_of)
    return (callee, name, receiver, arguments), open_, close


def _arguments(
    tokens: Tokens, node: ast.Call, open_: int, close: int, end_of: EndOf
) -> tuple[ArgumentParts, ...]:
    """The arguments between the call's ``(`` at ``open_`` and ``)`` at ``close``: each runs
    from the comma after the one before (its own parentheses included) to the end of its
    expression and any ``)`` closing around it."""
    written: list[ast.expr | ast.keyword] = [*node.args, *node.keywords]
    if node.keywords and node.args:
        written.sort(key=lambda item: (item.lineno, item.col_offset))
    text = tokens.text
    arguments = []
    first = open_ + 1
    for item in written:
        end = min(end_of(item), close)  # a lone generator's range holds the call's ")"
        while end < close and text[end] == ")":
            end += 1
        if end < close and text[end] != ",":
            raise Unreadable(f"arguments do not line up at line {tokens.starts[open_]}")
        arguments.append(_argument(tokens, item, first, end))
        first = end + 1
    return tuple(arguments)


def _argument(tokens: Tokens, item: ast.expr | ast.keyword, first: int, end: int) -> ArgumentParts:
    if isinstance(item, ast.keyword):
        if item.arg is None:  # **mapping
            return (first, end), None, False, None
        is_literal, value = literal(item.value, tokens.text, first + 2, end)
        return (first + 2, end), value, is_literal, item.arg
    if isinstance(item, ast.Starred):
        return (first, end), None, False, None
    is_literal, value = literal(item, tokens.text, first, end)
    return (first, end), value, is_literal, None


def literal(node: ast.expr, text: list[str], first: int, end: int) -> tuple[bool, Literal]:
    """(True, value) for a literal argument (its tokens: ``text[first:end]``): str, bytes
    (as Latin-1 text), int, float, a negative number, bool, None, an f-string without
    placeholders. A string concatenated with an f-string is not one: libcst evaluates no
    such concatenation."""
    if isinstance(node, ast.Constant):
        value = node.value
        if isinstance(value, str | bool | int | float) or value is None:
            return True, value
        if isinstance(value, bytes):
            return True, value.decode("latin-1")
        return False, None  # complex, Ellipsis
    if isinstance(node, ast.JoinedStr):
        strings = sum(1 for token in text[first:end] if token != "(" and token != ")")
        parts = [
            part.value
            for part in node.values
            if isinstance(part, ast.Constant) and isinstance(part.value, str)
        ]
        if strings == 1 and len(parts) == len(node.values):
            return True, "".join(parts)
        return False, None
    if (
        isinstance(node, ast.UnaryOp)
        and isinstance(node.op, ast.USub)
        and isinstance(node.operand, ast.Constant)
    ):
        number = node.operand.value
        if type(number) is int or type(number) is float:
            return True, -number
    return False, None
