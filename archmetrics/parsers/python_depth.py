"""How deeply Python source nests, read from its tokens alone, before any parser runs.

A parser recurses once per level of the tree it builds, so the depth bounds what it costs:
libcst's native parser takes 1-8 KB of C stack per level (a segmentation fault past the end
of the stack, not an exception) and time and memory that grow with the square of the depth.
Counted here, without building a tree (docs/metrics.md, "Limits"):

* each open bracket is a level (``brackets`` counts these alone, the limit CPython's own
  tokenizer enforces);
* each operator of a chain is a level, since ``a + b + c`` nests one node per ``+``: the
  binary, comparison, boolean and unary operators, ``.``, ``if`` (of a conditional
  expression), ``lambda``, ``await``, ``yield``, ``:=``, a call's or subscript's bracket, and
  each replacement field of an f-string; a comma starts a new item at the same level;
* each ``elif`` of a chain is a level for the statements after it (the tree keeps an
  ``elif`` as an ``if`` inside the ``else`` of the one before).

The result is an upper bound of the depth of the tree either reader builds (``ast`` or
libcst), close to it for the chains and nests that make trees deep.
"""

from __future__ import annotations

from typing import NamedTuple

from archmetrics.parsers.python_lex import LEXEME, NOT_OPERANDS

_OPENERS = frozenset("([{")
_CLOSERS = frozenset(")]}")
_OPERATORS = frozenset(
    {
        *(".", "+", "-", "*", "/", "//", "%", "**", "@", "<<", ">>", "&", "|", "^", "~"),
        *("<", ">", "<=", ">=", "==", "!=", ":="),
        *("in", "is", "not", "and", "or", "if", "lambda", "await", "yield"),
    }
)


class Nesting(NamedTuple):
    """The deepest level the source reaches (see the module's docstring), the deepest
    bracket nesting alone, the deepest level within one statement (``depth`` without the
    ``elif`` levels), the most ``elif`` levels a statement sits under, and the line of the
    statement that goes deepest."""

    depth: int
    brackets: int
    expression: int = 0
    elifs: int = 0
    line: int = 1


def nesting(source: str) -> Nesting:
    """How deeply ``source`` nests; any text is accepted (what is not a token is skipped)."""
    frames: list[tuple[int, int, int]] = []  # the enclosing items' (ops, inner, best)
    ops = inner = best = 0  # the current item: its operators, its deepest bracket, and
    # the deepest earlier item at its level
    chains: list[list[int]] = []  # open if-statements: [column, elifs so far]
    base = deepest = brackets = expression = elifs = 0
    start = where = 0  # where the current statement and the deepest one start
    previous = ""
    for match in LEXEME.finditer(source):
        blanks, token = match.group(1, 2)
        if not frames and (not previous or _logical_newline(blanks) or previous == ";"):
            level = max(best, ops + inner + 1)
            expression, elifs = max(expression, level), max(elifs, base)
            if base + level > deepest:
                deepest, where = base + level, start
            ops = inner = best = 0
            if not token:
                break
            start = match.start(2)
            base = _statement(chains, _column(source, start), token)
        if token in _OPENERS:
            if _after_operand(previous):
                ops += 1  # a call or a subscript nests the expression before it
            frames.append((ops, inner, best))
            ops = inner = best = 0
            brackets = max(brackets, len(frames))
        elif token in _CLOSERS:
            if frames:
                level = max(best, ops + inner + 1)
                ops, inner, best = frames.pop()
                inner = max(inner, level)
        elif token == ",":
            best = max(best, ops + inner + 1)
            ops = inner = 0
        elif token in _OPERATORS:
            ops += 1
        elif token[-1:] in ("'", '"') and "f" in token[: token.find(token[-1])].lower():
            ops += token.count("{")  # an f-string: its replacement fields nest
        previous = token
    while frames:  # brackets left open at the end
        level = max(best, ops + inner + 1)
        ops, inner, best = frames.pop()
        inner = max(inner, level)
    level = max(best, ops + inner + 1)
    expression, elifs = max(expression, level), max(elifs, base)
    if base + level > deepest:
        deepest, where = base + level, start
    return Nesting(deepest, brackets, expression, elifs, source.count("\n", 0, where) + 1)


def _logical_newline(blanks: str) -> bool:
    """True when the blanks before a token end a logical line (a newline not escaped)."""
    return "\n" in blanks and "\n" in blanks.replace("\\\n", "")


def _column(source: str, offset: int) -> int:
    return offset - source.rfind("\n", 0, offset) - 1


def _statement(chains: list[list[int]], column: int, token: str) -> int:
    """A statement starts with ``token`` at ``column``: the if-chains still open around it
    and their ``elif`` count, the levels it sits under."""
    while chains and chains[-1][0] > column:
        chains.pop()
    if chains and chains[-1][0] == column and token == "elif":
        chains[-1][1] += 1
    elif not (chains and chains[-1][0] == column and token == "else"):
        while chains and chains[-1][0] >= column:
            chains.pop()
        if token == "if":
            chains.append([column, 0])
    return sum(elifs for _, elifs in chains)


def _after_operand(previous: str) -> bool:
    """True when a bracket after ``previous`` opens a call's arguments or a subscript."""
    if not previous:
        return False
    if previous in _CLOSERS:
        return True
    head = previous[0]
    return (head.isalnum() or head in "_'\"" or not head.isascii()) and (
        previous not in NOT_OPERANDS
    )
