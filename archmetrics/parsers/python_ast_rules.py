"""Python rule tables for the ``ast`` reader: the ``ast`` node behind each row of the tables in
docs/metrics.md, beside the libcst node python_rules.py names for the same row."""

from __future__ import annotations

import ast
from collections.abc import Iterator

from archmetrics.parsers.python_lex import Tokens

# Simple statements: every one is a logical line (thesis p. 103), rule-table row -> kind.
SIMPLE_KINDS: dict[type[ast.stmt], str] = {
    ast.Assign: "assign",
    ast.AugAssign: "augassign",
    ast.AnnAssign: "annassign",
    ast.Expr: "expr",
    ast.Return: "return",
    ast.Raise: "raise",
    ast.Pass: "pass",
    ast.Break: "break",
    ast.Continue: "continue",
    ast.Delete: "del",
    ast.Assert: "assert",
    ast.Global: "global",
    ast.Nonlocal: "nonlocal",
    ast.Import: "import",
    ast.ImportFrom: "from_import",
}
if hasattr(ast, "TypeAlias"):  # Python 3.12
    SIMPLE_KINDS[ast.TypeAlias] = "type_alias"

COMPREHENSIONS: frozenset[type[ast.expr]] = frozenset(
    {ast.ListComp, ast.SetComp, ast.DictComp, ast.GeneratorExp}
)


def docstring(node: ast.stmt) -> bool:
    """True for a plain-string expression statement: the docstring, when it comes first in a
    module, class or function body (implicit concatenation included; not an f-string, not
    bytes), as Python defines it."""
    return (
        type(node) is ast.Expr
        and type(node.value) is ast.Constant
        and type(node.value.value) is str
    )


def catch_all(cases: list[ast.match_case]) -> ast.match_case | None:
    """The first ``case _:`` or ``case name:`` (guarded or not): radon's ``else`` of a match."""
    for case in cases:
        if type(case.pattern) is ast.MatchAs and case.pattern.pattern is None:
            return case
    return None


# f-strings (and Python 3.14's t-strings): one token each, their fields read on their own.
STRING_TEMPLATES: frozenset[type[ast.expr]] = frozenset(
    getattr(ast, name) for name in ("JoinedStr", "TemplateStr") if hasattr(ast, name)
)
_FIELDS = tuple(
    getattr(ast, name) for name in ("FormattedValue", "Interpolation") if hasattr(ast, name)
)


def replacement_fields(node: ast.expr) -> Iterator[ast.expr]:
    """The expressions of an f-string's replacement fields, those in format specs included."""
    for part in node.values:  # type: ignore[attr-defined]
        if type(part) in _FIELDS:
            yield part.value
            if type(part.format_spec) in STRING_TEMPLATES:
                yield from replacement_fields(part.format_spec)


def statement_text(tokens: Tokens, first: int, end: int, node: ast.stmt | None) -> str:
    """Normalized text of a statement's tokens. libcst writes each dot of a relative import
    on its own (``from . . . import x``); ``tokenize`` reads three dots as one token."""
    if type(node) is ast.ImportFrom and (node.level or 0) >= 3:
        return " ".join(". . ." if token == "..." else token for token in tokens.text[first:end])
    return tokens.joined(first, end)
