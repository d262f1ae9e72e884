"""Names in C and C++ trees: qualified function and class names, call sites, arguments."""

from __future__ import annotations

import re
from collections.abc import Iterable

from tree_sitter import Node

from archmetrics.facts import Argument, CallSite, Literal, Span
from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_text import compact, literal, normal, string_value
from archmetrics.parsers.text import collapse

_DECLARATOR_WRAPPERS = frozenset(
    {
        "pointer_declarator",
        "reference_declarator",
        "parenthesized_declarator",
        "attributed_declarator",
    }
)
_STRINGS = frozenset({"string_literal", "raw_string_literal"})
_CALLEE = re.compile(r"(.*)(\.|->|::)(~?[A-Za-z_$][\w$]*)\Z", re.DOTALL)
_TEMPLATE_ARGUMENTS = re.compile(r"<[^<>()]*>")
_LONGEST_NAME = 120
_SPACE_OR_COMMENT = re.compile(rb"\s|/[/*]")


def text(node: Node, data: bytes) -> bytes:
    """The bytes of ``node``."""
    return data[node.start_byte : node.end_byte]


def in_order(nodes: Iterable[Node]) -> list[Node]:
    """Nodes in document order, the outer of two that start together first.

    Sorting on the start alone is not enough: tree-sitter's query cursor returns captures
    that start at the same byte (``f(a)(b)`` and ``f(a)``, an ERROR inside an ERROR) in an
    order that varies with what the process parsed before, and facts must not.
    """
    return sorted(nodes, key=lambda n: (n.start_byte, -n.end_byte, n.type))


def span(node: Node) -> Span:
    """The lines ``node`` covers; a node ending with its line's newline ends on that line."""
    end = node.end_point
    last = end.row + 1 if end.column else max(end.row, node.start_point.row + 1)
    return Span(node.start_point.row + 1, last)


def class_name(node: Node, data: bytes) -> str | None:
    """A struct/class/union's name, or its typedef name when anonymous (`typedef struct {} T`)."""
    name = node.child_by_field_name("name")
    if name is not None:
        return compact(text(name, data))
    parent = node.parent
    if parent is not None and parent.type == "type_definition":
        declarator = parent.child_by_field_name("declarator")
        if declarator is not None:
            return compact(text(declarator, data))
    return None


def scopes(node: Node, data: bytes) -> list[str]:
    """Names of the namespaces and classes around ``node``, outermost first."""
    names: list[str] = []
    parent = node.parent
    while parent is not None:
        if parent.type == c_tables.NAMESPACE:
            name = parent.child_by_field_name("name")
            if name is not None:
                names.append(compact(text(name, data)))
        elif parent.type in c_tables.CLASSES:
            name_text = class_name(parent, data)
            if name_text:
                names.append(name_text)
        parent = parent.parent
    names.reverse()
    return names


def _name_text(node: Node, data: bytes) -> str:
    kind = node.type
    if kind == "qualified_identifier":
        scope = node.child_by_field_name("scope")
        name = node.child_by_field_name("name")
        prefix = compact(text(scope, data)) if scope is not None else ""
        return prefix + "::" + (_name_text(name, data) if name is not None else "")
    if kind == "operator_cast":
        target = node.child_by_field_name("type")
        return "operator " + (compact(text(target, data)) if target is not None else "")
    if kind in ("template_function", "template_method"):
        name = node.child_by_field_name("name")
        if name is not None:
            return _name_text(name, data)
    return compact(text(node, data))[:_LONGEST_NAME]


def function_name(function: Node, data: bytes) -> tuple[str, str]:
    """(name, qualified name) of a function definition: `f`, `ns::Class::f`."""
    declarator = function.child_by_field_name("declarator")
    node = declarator
    while node is not None and node.type in _DECLARATOR_WRAPPERS:
        inner = node.child_by_field_name("declarator")
        if inner is None and node.named_child_count:
            inner = node.named_child(node.named_child_count - 1)
        node = inner
    if node is not None and node.type == "function_declarator":
        node = node.child_by_field_name("declarator")
    elif declarator is not None and declarator.type == "parenthesized_declarator":
        node = function.child_by_field_name("type")  # `NAME(args) {`: a macro-made function
    own = _name_text(node, data) if node is not None else "(anonymous)"
    qualified = "::".join([*scopes(function, data), own.lstrip(":")])
    return own.rsplit("::", 1)[-1], qualified


def _argument(node: Node, data: bytes) -> Argument:
    raw = data[node.start_byte : node.end_byte]
    kind = node.type
    if kind == "identifier":
        return Argument(raw.decode("utf-8", "replace"))
    if _SPACE_OR_COMMENT.search(raw) is None:
        shown = raw.decode("utf-8", "replace")
    else:
        shown = normal(raw) if b"/" in raw else collapse(raw.decode("utf-8", "replace"))
    value: Literal = None
    is_literal = False
    if kind == "concatenated_string":
        parts = [child for child in node.named_children if child.type != "comment"]
        if parts and all(child.type in _STRINGS for child in parts):
            values = [string_value(text(child, data)) for child in parts]
            is_literal = all(part is not None for part in values)
            value = "".join(part or "" for part in values) if is_literal else None
    elif kind == "unary_expression" and raw.startswith(b"-"):
        operand = node.child_by_field_name("argument")
        if operand is not None and operand.type == "number_literal":
            is_literal, number = literal("number_literal", text(operand, data))
            value = -number if isinstance(number, int | float) else None
    else:
        is_literal, value = literal(kind, raw)
    return Argument(shown, value, is_literal)


def callee(node: Node | None, data: bytes) -> str:
    """The called expression's text, template arguments dropped: `Ice::checkedCast`."""
    if node is None:
        return ""
    if node.type == "identifier":
        return data[node.start_byte : node.end_byte].decode("utf-8", "replace")
    written = compact(text(node, data))
    if "<" in written and node.type != "parenthesized_expression":
        previous = ""
        while previous != written and "<" in written:
            previous, written = written, _TEMPLATE_ARGUMENTS.sub("", written)
    return written


def call_site(node: Node, data: bytes, function: str | None) -> CallSite:
    """One call_expression as a CallSite with its arguments' literal values."""
    function_node = node.child_by_field_name("function")
    called = callee(function_node, data)
    receiver: str | None = None
    name = called
    if function_node is not None and function_node.type != "identifier":
        match = _CALLEE.match(called)
        if match:
            receiver, name = match.group(1), match.group(3)
    arguments = node.child_by_field_name("arguments")
    values: tuple[Argument, ...] = ()
    if arguments is not None:
        values = tuple(
            _argument(child, data) for child in arguments.named_children if child.type != "comment"
        )
    return CallSite(called, name, receiver or None, span(node), values, function)
