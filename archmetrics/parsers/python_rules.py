"""Python rule tables: which libcst nodes are statements (λ) and how names and literals read.

The tables are data so that the rule table in docs/metrics.md and the code can be compared
row by row. Decision points are handled by the walker (python_walk.py), which needs context.
"""

from __future__ import annotations

import ast
import warnings
from collections.abc import Sequence

import libcst as cst

from archmetrics.facts import Dependency, DependencyKind, Literal, Span

_LAZY_IMPORT = getattr(cst, "LazyImport", None)  # PEP 810, libcst >= 1.9
_LAZY_IMPORT_FROM = getattr(cst, "LazyImportFrom", None)

# Simple statements: every one is a logical line (thesis p. 103), rule-table row -> kind.
SIMPLE_KINDS: dict[type[cst.CSTNode], str] = {
    cst.Assign: "assign",
    cst.AugAssign: "augassign",
    cst.AnnAssign: "annassign",
    cst.Expr: "expr",
    cst.Return: "return",
    cst.Raise: "raise",
    cst.Pass: "pass",
    cst.Break: "break",
    cst.Continue: "continue",
    cst.Del: "del",
    cst.Assert: "assert",
    cst.Global: "global",
    cst.Nonlocal: "nonlocal",
    cst.Import: "import",
    cst.ImportFrom: "from_import",
    cst.TypeAlias: "type_alias",
}
if _LAZY_IMPORT is not None and _LAZY_IMPORT_FROM is not None:
    SIMPLE_KINDS[_LAZY_IMPORT] = "import"
    SIMPLE_KINDS[_LAZY_IMPORT_FROM] = "from_import"

# Compound statements whose header is one logical line. ``If`` is "if" or "elif" by
# position; ``else:`` and ``finally:`` are absent on purpose (they evaluate nothing).
HEADER_KINDS: dict[type[cst.CSTNode], str] = {
    cst.If: "if",
    cst.For: "for",
    cst.While: "while",
    cst.With: "with",
    cst.Try: "try",
    cst.TryStar: "try",
    cst.ExceptHandler: "except",
    cst.ExceptStarHandler: "except",
    cst.Match: "match",
    cst.MatchCase: "case",
    cst.ClassDef: "class",
    cst.FunctionDef: "def",
}

IMPORT_TYPES: tuple[type[cst.CSTNode], ...] = tuple(
    t for t in (cst.Import, cst.ImportFrom, _LAZY_IMPORT, _LAZY_IMPORT_FROM) if t is not None
)


def docstring(body: cst.BaseSuite | Sequence[cst.BaseStatement]) -> cst.Expr | None:
    """The docstring statement of a module/class/function body, as Python defines it.

    The first statement, when it is an expression statement of a plain string (implicit
    concatenation included; not an f-string, not bytes).
    """
    first: cst.CSTNode | None = None
    if isinstance(body, cst.SimpleStatementSuite):
        first = body.body[0] if body.body else None
    else:
        statements: Sequence[cst.CSTNode] = body.body if isinstance(body, cst.BaseSuite) else body
        line = statements[0] if statements else None
        if isinstance(line, cst.SimpleStatementLine) and line.body:
            first = line.body[0]
    if isinstance(first, cst.Expr) and _is_text(first.value):
        return first
    return None


def _is_text(node: cst.BaseExpression) -> bool:
    if isinstance(node, cst.SimpleString):
        return "b" not in node.prefix.lower()
    if isinstance(node, cst.ConcatenatedString):
        return _is_text(node.left) and _is_text(node.right)
    return False


def dotted(node: cst.CSTNode) -> str | None:
    """``a.b.c`` for a Name/Attribute chain, else None (a loop: chains can be long)."""
    names = []
    while isinstance(node, cst.Attribute):
        names.append(node.attr.value)
        node = node.value
    if not isinstance(node, cst.Name):
        return None
    names.append(node.value)
    names.reverse()
    return ".".join(names)


def literal(node: cst.BaseExpression) -> tuple[bool, Literal]:
    """(True, value) for a literal argument: str, int, float, negative number, bool, None."""
    if isinstance(node, cst.SimpleString | cst.ConcatenatedString | cst.FormattedString):
        with warnings.catch_warnings():  # "invalid escape sequence" is the author's business
            warnings.simplefilter("ignore")
            return _literal(node)
    return _literal(node)


def _literal(node: cst.BaseExpression) -> tuple[bool, Literal]:
    try:
        if isinstance(node, cst.SimpleString | cst.ConcatenatedString):
            value = node.evaluated_value
            if isinstance(value, bytes):
                return True, value.decode("latin-1")
            return (value is not None), value
        if isinstance(node, cst.FormattedString):
            return _plain_fstring(node)
        if isinstance(node, cst.Integer | cst.Float):
            return True, node.evaluated_value
        if isinstance(node, cst.UnaryOperation) and isinstance(node.operator, cst.Minus):
            inner = node.expression
            if isinstance(inner, cst.Integer | cst.Float):
                return True, -inner.evaluated_value
        if isinstance(node, cst.Name) and node.value in _CONSTANTS:
            return True, _CONSTANTS[node.value]
    except (ValueError, SyntaxError, MemoryError, RecursionError):
        pass  # a literal Python itself would reject: keep it as text only
    return False, None


_CONSTANTS: dict[str, Literal] = {"True": True, "False": False, "None": None}


def _plain_fstring(node: cst.FormattedString) -> tuple[bool, Literal]:
    """An f-string without placeholders is a constant string."""
    if not all(isinstance(part, cst.FormattedStringText) for part in node.parts):
        return False, None
    start = node.start.replace("f", "").replace("F", "")
    text = "".join(part.value for part in node.parts if isinstance(part, cst.FormattedStringText))
    text = text.replace("{{", "{").replace("}}", "}")
    value = ast.literal_eval(f"{start}{text}{node.end}")
    return isinstance(value, str), value if isinstance(value, str) else None


def dependencies(node: cst.CSTNode, span: Span) -> list[Dependency]:
    """The static dependencies one import statement declares."""
    if isinstance(node, cst.Import) or (_LAZY_IMPORT and isinstance(node, _LAZY_IMPORT)):
        found = []
        for alias in getattr(node, "names", ()):
            target = dotted(alias.name) or ""
            local = _alias(alias) or target.split(".")[0]
            found.append(Dependency(target, DependencyKind.IMPORT, span, bound=(local,)))
        return found
    module = getattr(node, "module", None)
    names = getattr(node, "names", ())
    bound: tuple[str, ...]
    if isinstance(names, cst.ImportStar):
        imported: tuple[str, ...] = ("*",)
        bound = imported
    else:
        imported = tuple(dotted(alias.name) or "" for alias in names)
        bound = tuple(_alias(alias) or name for alias, name in zip(names, imported, strict=True))
    return [
        Dependency(
            (dotted(module) or "") if module is not None else "",
            DependencyKind.IMPORT,
            span,
            level=len(getattr(node, "relative", ())),
            names=imported,
            bound=bound,
        )
    ]


def _alias(alias: cst.ImportAlias) -> str | None:
    """The ``as`` name of an import alias, if it has one."""
    if alias.asname is None or not isinstance(alias.asname.name, cst.Name):
        return None
    return alias.asname.name.value


def is_catch_all(case: cst.MatchCase) -> bool:
    """``case _:`` or ``case name:``: the pattern radon treats as the match's ``else``."""
    pattern = case.pattern
    return isinstance(pattern, cst.MatchAs) and pattern.pattern is None
