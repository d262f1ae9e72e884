"""Python bindings (facts.Binding) from an assignment statement's tokens.

Both readers (``ast``'s and libcst's) produce the same token stream, so both read bindings
here from the tokens of each ``assign`` and ``annassign`` statement: the statement splits at
its top-level ``=`` tokens (not inside brackets, not after a ``lambda``, whose defaults are
part of the value); every part before the last that is one plain name is bound to the last
part, the value (``x = y = 1`` binds both). ``x: int = 1`` binds ``x``; ``self.x = 1`` (or
``cls.x``) binds ``self.x``, a member of the object at hand; ``a, b = f()`` and ``o.x = 1``
give none.
"""

from __future__ import annotations

_OPENERS = frozenset("([{")
_CLOSERS = frozenset(")]}")


def _is_name(token: str) -> bool:
    return token.isidentifier()


def _assignment_cuts(kind: str, tokens: list[str]) -> list[int]:
    """The index of each top-level ``=`` of an ``assign``/``annassign`` statement (none for
    another kind; one for an annotated one; none inside a lambda or brackets)."""
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
    return cuts


def assignment_bindings(kind: str, tokens: list[str]) -> list[tuple[str, str]]:
    """(name, value text) of each plain name an ``assign``/``annassign`` statement binds,
    the value's tokens joined by single spaces as statement texts are."""
    cuts = _assignment_cuts(kind, tokens)
    if not cuts:
        return []
    value = " ".join(tokens[cuts[-1] + 1 :])
    found: list[tuple[str, str]] = []
    start = 0
    for cut in cuts:
        target = tokens[start:cut]
        if kind == "annassign" and len(target) >= 2 and target[1] == ":":
            target = target[:1]
        if value and ((len(target) == 1 and _is_name(target[0])) or _own_member(target)):
            found.append(("".join(target), value))
        start = cut + 1
    return found


def _own_member(tokens: list[str]) -> bool:
    """Whether ``tokens`` are a member of the object or class at hand: ``self.x``, ``cls.x``."""
    return (
        len(tokens) == 3
        and tokens[0] in ("self", "cls")
        and tokens[1] == "."
        and (_is_name(tokens[2]))
    )


def _dotted(tokens: list[str]) -> bool:
    """Whether ``tokens`` are a dotted name: ``x``, ``self.pub``, ``a.b.c``."""
    if len(tokens) % 2 == 0:
        return False
    names, dots = tokens[::2], tokens[1::2]
    return all(map(_is_name, names)) and all(dot == "." for dot in dots)


def assignment_target(kind: str, tokens: list[str]) -> tuple[str, int, int] | None:
    """For an ``assign``/``annassign`` statement whose last target is a dotted name
    (``x``, ``self.pub``): that target's text and the value's token range in ``tokens``
    (``[first, end)``, its outer parentheses and a ``;`` left out); None otherwise."""
    cuts = _assignment_cuts(kind, tokens)
    if not cuts:
        return None
    target = tokens[cuts[-2] + 1 if len(cuts) > 1 else 0 : cuts[-1]]
    if kind == "annassign" and len(target) >= 2:
        colon = target.index(":") if ":" in target else len(target)
        target = target[:colon]
    first, end = cuts[-1] + 1, len(tokens)
    while end > first and tokens[end - 1] == ";":
        end -= 1
    while end - first >= 2 and tokens[first] == "(" and _closes(tokens, first) == end - 1:
        first, end = first + 1, end - 1
    if not _dotted(target) or end <= first:
        return None
    return "".join(target), first, end


def _closes(tokens: list[str], opener: int) -> int:
    """The index of the bracket closing the one at ``opener`` (-1 if none)."""
    depth = 0
    for index in range(opener, len(tokens)):
        if tokens[index] in _OPENERS:
            depth += 1
        elif tokens[index] in _CLOSERS:
            depth -= 1
            if depth == 0:
                return index
    return -1


def accessors_only(tokens: list[str]) -> bool:
    """Whether ``tokens`` (what follows a call in an assigned value) are accessors only:
    ``.value``, ``.get_parameter_value().string_value`` (members, and calls of them without
    arguments)."""
    index = 0
    while index < len(tokens):
        if tokens[index] != "." or index + 1 >= len(tokens) or not _is_name(tokens[index + 1]):
            return False
        index += 2
        if tokens[index : index + 2] == ["(", ")"]:
            index += 2
    return True
