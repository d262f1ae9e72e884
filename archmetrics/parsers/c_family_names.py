"""Names in C and C++ trees: qualified function and class names (call sites:
c_family_calls.py).

Nothing here walks up the tree: in tree-sitter a node's parent is found by descending from
the root again, so a walk up from each of n nested nodes costs n² steps (a 19 KB file of
classes nested in methods took 32 s). What encloses a node is found by position instead.
"""

from __future__ import annotations

import operator
from collections.abc import Iterable

from tree_sitter import Node

from archmetrics.facts import Span
from archmetrics.parsers import shown
from archmetrics.parsers.c_family_text import compact

_DECLARATOR_WRAPPERS = frozenset(
    {
        "pointer_declarator",
        "reference_declarator",
        "parenthesized_declarator",
        "attributed_declarator",
    }
)
_LONGEST_NAME = 120


def text(node: Node, data: bytes) -> bytes:
    """The bytes of ``node``."""
    return data[node.start_byte : node.end_byte]


def in_order(nodes: Iterable[Node]) -> list[Node]:
    """Nodes in document order, the outer of two that start together first.

    Sorting on the start alone is not enough: tree-sitter's query cursor returns captures
    that start at the same byte (``f(a)(b)`` and ``f(a)``, an ERROR inside an ERROR) in an
    order that varies with what the process parsed before, and facts must not.
    """
    nodes = list(nodes)
    starts = [node.start_byte for node in nodes]
    if all(map(operator.lt, starts, starts[1:])):  # the query's captures come in order, and
        return nodes  # none start together (checked in one pass in C): nothing to move
    if len(set(starts)) < len(starts):  # two start together: the full key (rare, dearer)
        return sorted(nodes, key=lambda n: (n.start_byte, -n.end_byte, n.type))
    order = sorted(range(len(nodes)), key=starts.__getitem__)
    return [nodes[index] for index in order]


def span(node: Node) -> Span:
    """The lines ``node`` covers; a node ending with its line's newline ends on that line."""
    end = node.end_point
    last = end.row + 1 if end.column else max(end.row, node.start_point.row + 1)
    return Span(node.start_point.row + 1, last)


def typedef_names(statements: Iterable[Node], data: bytes) -> dict[tuple[int, int], str]:
    """The name each `typedef` gives its type, by the type's bytes: what names an anonymous
    class (`typedef struct {} T`) without a step up from the class to its parent."""
    names: dict[tuple[int, int], str] = {}
    for node in statements:
        if node.type != "type_definition":
            continue
        kind = node.child_by_field_name("type")
        declarator = node.child_by_field_name("declarator")
        if kind is not None and declarator is not None:
            names[(kind.start_byte, kind.end_byte)] = compact(text(declarator, data))
    return names


def class_name(node: Node, data: bytes, typedefs: dict[tuple[int, int], str]) -> str | None:
    """A struct/class/union's name, or its typedef name when anonymous (`typedef struct {} T`)."""
    name = node.child_by_field_name("name")
    if name is not None:
        return compact(text(name, data))
    return typedefs.get((node.start_byte, node.end_byte))


class Scopes:
    """The named namespaces and classes of a file, to qualify what they enclose.

    Found by position, in one sweep over the scopes and the nodes to qualify, both in
    document order. A qualified prefix longer than ``shown.LIMIT`` keeps its last
    ``shown.LIMIT`` characters after ``shown.CUT``: n nested classes would otherwise name
    n²/2 scopes between them."""

    def __init__(
        self,
        namespaces: list[Node],
        classes: list[Node],
        data: bytes,
        typedefs: dict[tuple[int, int], str],
    ) -> None:
        self.class_names: dict[int, str | None] = {}  # by node id
        named: list[tuple[int, int, str]] = []
        for node in namespaces:
            name = node.child_by_field_name("name")
            if name is not None:
                named.append((node.start_byte, node.end_byte, compact(text(name, data))))
        for node in classes:
            class_text = self.class_names[node.id] = class_name(node, data, typedefs)
            if class_text:
                named.append((node.start_byte, node.end_byte, class_text))
        named.sort(key=lambda scope: (scope[0], -scope[1]))
        self._named = named

    def prefixes(self, ordered: list[Node]) -> dict[int, str]:
        """For each node (by id; ``ordered`` as ``in_order`` puts them), the qualified name
        of the scopes around it ("" if none)."""
        named = self._named
        found: dict[int, str] = {}
        open_: list[tuple[int, str]] = []  # (end, qualified name) of the scopes around
        index = 0
        for node in ordered:
            start, end = node.start_byte, node.end_byte
            while index < len(named) and (named[index][0], -named[index][1]) < (start, -end):
                scope_start, scope_end, name = named[index]
                index += 1
                while open_ and open_[-1][0] <= scope_start:
                    open_.pop()
                outer = open_[-1][1] + "::" if open_ else ""
                open_.append((scope_end, _tail(outer + name)))
            while open_ and open_[-1][0] <= start:
                open_.pop()
            found[node.id] = open_[-1][1] if open_ else ""
        return found

    def prefix_at(self, offset: int) -> str:
        """The qualified name of the named scopes around byte ``offset`` ("" if none)."""
        return _tail("::".join(name for start, end, name in self._named if start < offset < end))


def _tail(qualified: str) -> str:
    if len(qualified) <= shown.LIMIT:
        return qualified
    return shown.CUT + qualified[-shown.LIMIT :]


def _name_text(node: Node, data: bytes) -> str:
    """A declarator's name: `ns::Class::f`, `operator int`; a loop along `::`."""
    prefix: list[str] = []
    while True:
        kind = node.type
        if kind == "qualified_identifier":
            scope = node.child_by_field_name("scope")
            name = node.child_by_field_name("name")
            prefix.append((compact(text(scope, data)) if scope is not None else "") + "::")
            if name is None:
                return "".join(prefix)
            node = name
            continue
        if kind == "operator_cast":
            target = node.child_by_field_name("type")
            own = "operator " + (compact(text(target, data)) if target is not None else "")
            return "".join(prefix) + own
        if kind in ("template_function", "template_method"):
            name = node.child_by_field_name("name")
            if name is not None:
                node = name
                continue
        return "".join(prefix) + compact(text(node, data))[:_LONGEST_NAME]


_PARAMETER_WRAPPERS = _DECLARATOR_WRAPPERS | {"array_declarator", "function_declarator"}


def _wrapped(declarator: Node, data: bytes) -> Node | None:
    """The function declarator a wrapper macro's argument holds, when ``declarator`` (a
    function declarator) is such a macro's call: `HEAP_EXPORT(void heap_init(struct heap*
    h))`, `UV_UNUSED(static void f(uv_loop_t* loop))` (a name in capitals, one parameter
    that declares a function). The function is that one, as the code names it."""
    name = declarator.child_by_field_name("declarator")
    listed = declarator.child_by_field_name("parameters")
    if name is None or listed is None or listed.named_child_count != 1:
        return None
    word = text(name, data)
    if name.type != "identifier" or word.upper() != word or word.lower() == word:
        return None  # (not in capitals, or no letter at all)
    parameter = listed.named_child(0)
    inner = parameter.child_by_field_name("declarator") if parameter is not None else None
    while inner is not None and inner.type in _DECLARATOR_WRAPPERS:
        inner = inner.child_by_field_name("declarator")
    return inner if inner is not None and inner.type == "function_declarator" else None


def _function_declarator(function: Node, data: bytes) -> Node | None:
    """A function definition's function declarator (a wrapper macro's argument's, if it is
    one), or None."""
    node = function.child_by_field_name("declarator")
    while node is not None and node.type in _DECLARATOR_WRAPPERS:
        inner = node.child_by_field_name("declarator")
        if inner is None and node.named_child_count:
            inner = node.named_child(node.named_child_count - 1)
        node = inner
    if node is None or node.type != "function_declarator":
        return None
    return _wrapped(node, data) or node


def function_parameters(function: Node, data: bytes) -> tuple[str, ...]:
    """The parameter names of a function definition, in order: `(const char *port, int
    n)` gives `port`, `n`; a function pointer `void (*cb)(int)` gives `cb`; `(void)`, `...`
    and unnamed parameters give nothing."""
    node = _function_declarator(function, data)
    if node is None:
        return ()
    listed = node.child_by_field_name("parameters")
    names: list[str] = []
    for parameter in listed.named_children if listed is not None else ():
        declarator = parameter.child_by_field_name("declarator")
        for _ in range(64):  # nested declarators, never this deep in real code
            if declarator is None or declarator.type not in _PARAMETER_WRAPPERS:
                break
            inner = declarator.child_by_field_name("declarator")
            if inner is None and declarator.named_child_count:
                inner = declarator.named_child(declarator.named_child_count - 1)
            declarator = inner
        if declarator is not None and declarator.type == "identifier":
            names.append(compact(text(declarator, data)))
    return tuple(names)


def function_name(function: Node, data: bytes, prefix: str) -> tuple[str, str]:
    """(name, qualified name) of a function definition: `f`, `ns::Class::f` (``prefix``:
    the scopes around it, `ns::Class`)."""
    declarator = function.child_by_field_name("declarator")
    node = declarator
    while node is not None and node.type in _DECLARATOR_WRAPPERS:
        inner = node.child_by_field_name("declarator")
        if inner is None and node.named_child_count:
            inner = node.named_child(node.named_child_count - 1)
        node = inner
    if node is not None and node.type == "function_declarator":
        node = (_wrapped(node, data) or node).child_by_field_name("declarator")
    elif declarator is not None and declarator.type == "parenthesized_declarator":
        node = function.child_by_field_name("type")  # `NAME(args) {`: a macro-made function
    own = _name_text(node, data) if node is not None else "(anonymous)"
    qualified = f"{prefix}::{own.lstrip(':')}" if prefix else own.lstrip(":")
    return own.rsplit("::", 1)[-1], qualified
