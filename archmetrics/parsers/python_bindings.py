"""Python bindings (facts.Binding) from an assignment statement's tokens.

Both readers (``ast``'s and libcst's) produce the same token stream, so both read bindings
here from the tokens of each ``assign`` and ``annassign`` statement: the statement splits at
its top-level ``=`` tokens (not inside brackets, not after a ``lambda``, whose defaults are
part of the value); every part before the last that is one plain name is bound to the last
part, the value (``x = y = 1`` binds both). ``x: int = 1`` binds ``x``; ``a, b = f()`` and
``self.x = 1`` bind no plain name and give none.
"""

from __future__ import annotations

_OPENERS = frozenset("([{")
_CLOSERS = frozenset(")]}")


def _is_name(token: str) -> bool:
    return token.isidentifier()


def assignment_bindings(kind: str, tokens: list[str]) -> list[tuple[str, str]]:
    """(name, value text) of each plain name an ``assign``/``annassign`` statement binds,
    the value's tokens joined by single spaces as statement texts are."""
    if kind not in ("assign", "annassign"):
        return []
    cuts: list[int] = []
    depth = 0
    for index, token in enumerate(tokens):
        if token in _OPENERS:
            depth += 1
        elif token in _CLOSERS:
            depth -= 1
        elif depth == 0 and token == "lambda":
            break
        elif depth == 0 and token == "=":
            cuts.append(index)
            if kind == "annassign":
                break
    if not cuts:
        return []
    value = " ".join(tokens[cuts[-1] + 1 :])
    found: list[tuple[str, str]] = []
    start = 0
    for cut in cuts:
        target = tokens[start:cut]
        if kind == "annassign" and len(target) >= 2 and target[1] == ":":
            target = target[:1]
        if len(target) == 1 and _is_name(target[0]) and value:
            found.append((target[0], value))
        start = cut + 1
    return found
