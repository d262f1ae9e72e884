"""Call sites: callee, receiver and arguments of one ``Call``, read from the token stream.

The call's own parentheses are found by position: a call's tokens are its ``lpar``s, the
callee, ``(``, the arguments, ``)`` and its ``rpar``s, and each argument's first token is
known from the walk. Only inside an f-string, where tokens are glued, is text regenerated.
"""

from __future__ import annotations

import libcst as cst

from archmetrics.facts import Literal
from archmetrics.parsers import python_rules as rules
from archmetrics.parsers.python_shown import Text
from archmetrics.parsers.python_tokens import TokenState, shown_text

ArgumentParts = tuple[Text, Literal, bool, str | None]  # text, value, is_literal, keyword
CallParts = tuple[Text, Text | None, tuple[ArgumentParts, ...]]  # callee, receiver, arguments


def from_tokens(
    state: TokenState, node: cst.Call, first: int, end: int, starts: list[int]
) -> tuple[Text, Text | None, tuple[ArgumentParts, ...], int, int]:
    """Callee, receiver and arguments of a call spanning tokens ``first:end``, texts as
    token ranges, and the indexes of the call's own ``(`` and ``)``.

    ``starts`` holds the first token index of each argument.
    """
    close = end - len(node.rpar) - 1  # the call's own ")"
    open_ = (starts[0] if starts else close) - 1  # the call's own "("
    func = node.func
    own = first + len(node.lpar)
    callee: Text = rules.dotted(func) or (own, open_)
    receiver: Text | None = None
    if isinstance(func, cst.Attribute):
        receiver = rules.dotted(func.value)
        if receiver is None and not func.lpar:  # drop "." and the attribute name
            receiver = (own, open_ - 2)
        elif receiver is None:  # `(f().b)(x)`: the receiver inside the callee's parentheses
            receiver = (own + len(func.lpar), open_ - len(func.rpar) - 2)
    ends = [*starts[1:], close] if starts else []
    arguments = tuple(
        _argument(state, arg, a, b) for arg, a, b in zip(node.args, starts, ends, strict=True)
    )
    return callee, receiver, arguments, open_, close


def _argument(state: TokenState, arg: cst.Arg, first: int, end: int) -> ArgumentParts:
    if end > first and state.toks[end - 1] == ",":
        end -= 1
    if arg.keyword is not None:
        first += 2  # keyword and "="
    is_literal, value = rules.literal(arg.value) if not arg.star else (False, None)
    keyword = arg.keyword.value if arg.keyword is not None else None
    return (first, end), value, is_literal, keyword


def from_nodes(node: cst.Call) -> CallParts:
    """Callee, receiver and arguments of a call whose tokens cannot be sliced (inside an
    f-string): each text regenerated on its own."""
    func = node.func
    callee = rules.dotted(func) or shown_text(func)
    receiver = None
    if isinstance(func, cst.Attribute):
        receiver = rules.dotted(func.value) or shown_text(func.value)
    arguments = []
    for arg in node.args:
        text = shown_text(arg.value, arg.star)
        is_literal, value = rules.literal(arg.value) if not arg.star else (False, None)
        keyword = arg.keyword.value if arg.keyword is not None else None
        arguments.append((text, value, is_literal, keyword))
    return callee, receiver, tuple(arguments)
