"""A small, safe expression language for router rules (no ``eval``).

Expressions use Python syntax but only these forms are accepted: literals (numbers,
'strings', true/false/null), field names and dotted paths (``goal.x``), indexing with a
literal (``points[0]``), arithmetic (+ - * / // %), comparisons (== != < <= > >= in, not in),
``and``/``or``/``not``, ``a if cond else b``, list/dict literals and the functions abs, min,
max, round, len, str, int, float, bool, lower, upper. Names starting with ``_`` are message
attributes: ``_service``, ``_operation``, ``_topic``. Anything else is refused when the rule
is loaded, not when a message arrives.
"""

from __future__ import annotations

import ast
import operator
from collections.abc import Callable, Mapping
from typing import Any

Scope = Mapping[str, Any]


class ExprError(ValueError):
    """An expression is not allowed, or cannot be evaluated on this message."""


MAX_REPEAT = 10_000  # "ab" * n and [x] * n are capped so a rule cannot exhaust memory


def _multiply(left: Any, right: Any) -> Any:
    for seq, count in ((left, right), (right, left)):
        if isinstance(seq, str | list) and isinstance(count, int) and count > MAX_REPEAT:
            raise ExprError(f"repetition by {count} exceeds {MAX_REPEAT}")
    return left * right


_BINARY: dict[type[ast.operator], Callable[[Any, Any], Any]] = {
    ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: _multiply,
    ast.Div: operator.truediv, ast.FloorDiv: operator.floordiv, ast.Mod: operator.mod,
}
_COMPARE: dict[type[ast.cmpop], Callable[[Any, Any], Any]] = {
    ast.Eq: operator.eq, ast.NotEq: operator.ne, ast.Lt: operator.lt, ast.LtE: operator.le,
    ast.Gt: operator.gt, ast.GtE: operator.ge, ast.In: lambda a, b: a in b,
    ast.NotIn: lambda a, b: a not in b,
}
_FUNCTIONS: dict[str, Callable[..., Any]] = {
    "abs": abs, "min": min, "max": max, "round": round, "len": len, "str": str, "int": int,
    "float": float, "bool": bool, "lower": lambda s: str(s).lower(),
    "upper": lambda s: str(s).upper(),
}
_LITERAL_NAMES = {"true": True, "false": False, "null": None, "True": True, "False": False,
                  "None": None}


def _check(node: ast.AST) -> None:
    """Refuse every construct outside the whitelist."""
    allowed = (ast.Expression, ast.Constant, ast.Name, ast.Attribute, ast.Subscript, ast.BinOp,
               ast.UnaryOp, ast.BoolOp, ast.Compare, ast.IfExp, ast.Call, ast.List, ast.Tuple,
               ast.Dict, ast.Load, ast.And, ast.Or, ast.Not, ast.USub, ast.UAdd,
               *_BINARY, *_COMPARE)
    for child in ast.walk(node):
        if not isinstance(child, allowed):
            raise ExprError(f"{type(child).__name__} is not allowed in rule expressions")
        if isinstance(child, ast.Call) and not (
                isinstance(child.func, ast.Name) and child.func.id in _FUNCTIONS
                and not child.keywords):
            raise ExprError("only abs, min, max, round, len, str, int, float, bool, lower, "
                            "upper may be called, without keywords")
        if isinstance(child, ast.Attribute) and child.attr.startswith("_"):
            raise ExprError(f"attribute {child.attr!r} is not allowed")
        if isinstance(child, ast.Subscript) and not isinstance(child.slice, ast.Constant):
            raise ExprError("indexes must be literals")
        if isinstance(child, ast.Constant) and not isinstance(
                child.value, str | int | float | bool | type(None)):
            raise ExprError(f"literal {child.value!r} is not allowed")


def _field(value: Any, key: Any, text: str) -> Any:
    try:
        return value[key]
    except (KeyError, IndexError, TypeError):
        raise ExprError(f"no field {key!r} in {text!r}") from None


class Expression:
    """A compiled expression; ``evaluate(scope)`` reads fields from ``scope`` only."""

    def __init__(self, text: str) -> None:
        self.text = text
        try:
            tree = ast.parse(text.strip(), mode="eval")
        except SyntaxError as exc:
            raise ExprError(f"bad expression {text!r}: {exc.msg}") from None
        _check(tree)
        self._tree = tree.body

    def evaluate(self, scope: Scope) -> Any:
        """The value of the expression on ``scope``; ExprError if a field is missing."""
        try:
            return self._eval(self._tree, scope)
        except ExprError:
            raise
        except (ArithmeticError, TypeError, ValueError) as exc:
            raise ExprError(f"{self.text!r}: {type(exc).__name__}: {exc}") from None

    def _eval(self, node: ast.expr, scope: Scope) -> Any:
        ev = self._eval
        if isinstance(node, ast.Constant):
            return node.value
        if isinstance(node, ast.Name):
            if node.id in scope:
                return scope[node.id]
            if node.id in _LITERAL_NAMES:
                return _LITERAL_NAMES[node.id]
            raise ExprError(f"no field {node.id!r} in {self.text!r}")
        if isinstance(node, ast.Attribute):
            return _field(ev(node.value, scope), node.attr, self.text)
        if isinstance(node, ast.Subscript):
            assert isinstance(node.slice, ast.Constant)
            return _field(ev(node.value, scope), node.slice.value, self.text)
        if isinstance(node, ast.BinOp):
            return _BINARY[type(node.op)](ev(node.left, scope), ev(node.right, scope))
        if isinstance(node, ast.UnaryOp):
            value = ev(node.operand, scope)
            return not value if isinstance(node.op, ast.Not) else (
                -value if isinstance(node.op, ast.USub) else +value)
        if isinstance(node, ast.BoolOp):
            return self._bool(node, scope)
        if isinstance(node, ast.Compare):
            left = ev(node.left, scope)
            for op, right_node in zip(node.ops, node.comparators, strict=True):
                right = ev(right_node, scope)
                if not _COMPARE[type(op)](left, right):
                    return False
                left = right
            return True
        if isinstance(node, ast.IfExp):
            return ev(node.body if ev(node.test, scope) else node.orelse, scope)
        if isinstance(node, ast.Call):
            assert isinstance(node.func, ast.Name)
            return _FUNCTIONS[node.func.id](*(ev(a, scope) for a in node.args))
        if isinstance(node, ast.List | ast.Tuple):
            return [ev(e, scope) for e in node.elts]
        if isinstance(node, ast.Dict):
            return {ev(k, scope) if k is not None else None: ev(v, scope)
                    for k, v in zip(node.keys, node.values, strict=True)}
        raise ExprError(f"cannot evaluate {type(node).__name__}")

    def _bool(self, node: ast.BoolOp, scope: Scope) -> Any:
        value: Any = None
        for operand in node.values:
            value = self._eval(operand, scope)
            if isinstance(node.op, ast.And) and not value:
                return value
            if isinstance(node.op, ast.Or) and value:
                return value
        return value
