"""Where C/C++ functions are defined: tree-sitter's function definitions, and two shapes it
reads as something else (docs/metrics.md, "Macros and #if").

* A function-defining macro, ``TEST(Suite, Name) { ... }`` or ``MATCHER(IsEven, "") { ... }``:
  a call-like head at file, namespace or class scope followed by a body. tree-sitter reads
  a call that lacks its ``;`` and then a free-standing block; lizard, reading tokens,
  reports a function named after the macro, and so do we.
* ``virtual void f() {};`` in a class: tree-sitter-cpp reads the empty body as a brace
  initializer of a field; the method is a function with an empty body.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from tree_sitter import Node

from archmetrics.facts import Span
from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_grammar import Parents, parent_of
from archmetrics.parsers.c_family_names import span

#: Where a call-like head followed by a block is a definition, not a statement.
_DEFINITION_SCOPES = frozenset(
    {"translation_unit", "declaration_list", "field_declaration_list", "linkage_specification"}
    | {kind for kind in c_tables.SPECIFIER_CONTAINERS if kind.startswith("preproc_")}
)


@dataclass(frozen=True, slots=True)
class Definition:
    """A function definition: ``node`` (the definition, or a macro-made one's head) starts
    it, ``body`` is its body; ``macro`` is the macro's name for a macro-made one."""

    node: Node
    body: Node
    macro: str | None = None

    @property
    def start(self) -> int:
        return self.node.start_byte

    @property
    def end(self) -> int:
        return max(self.node.end_byte, self.body.end_byte)

    @property
    def span(self) -> Span:
        whole = span(self.node)
        return Span(whole.start, max(whole.end, span(self.body).end))


def definitions(
    statements: Iterable[Node],
    missing: Iterable[Node],
    data: bytes,
    macros: Iterable[str],
    parents: Parents | None = None,
) -> tuple[list[Definition], list[Node]]:
    """The function definitions among ``statements``, and those made by macros (found from
    the ``;`` tokens tree-sitter had to invent, ``missing``); and the invented tokens that
    belong to a macro-made definition (not a loss to warn about). ``macros``: names the
    configuration lists as function macros, recognised at any scope outside a function;
    ``parents``: the invented tokens' parents, if known (``missing_parents``)."""
    found: list[Definition] = []
    for node in statements:
        if node.type == c_tables.FUNCTION:
            body = node.child_by_field_name("body")
            if body is not None:
                found.append(Definition(node, body))
        elif node.type == "field_declaration":
            body = node.child_by_field_name("default_value")
            declarator = node.child_by_field_name("declarator")
            if (
                body is not None
                and body.type == "initializer_list"
                and declarator is not None
                and declarator.type == "function_declarator"
            ):
                found.append(Definition(node, body))
    explained: list[Node] = []
    listed = frozenset(macros)
    for token in missing:
        made = _macro_made(token, data, listed, parents or {})
        if made is not None:
            found.append(made)
            explained.append(token)
    found.sort(key=lambda d: (d.start, -d.end))
    return found, explained


def _macro_made(
    token: Node, data: bytes, listed: frozenset[str], parents: Parents
) -> Definition | None:
    """The definition ``NAME(args) { ... }`` whose head lacks the invented ``token``."""
    if token.type != ";":
        return None
    head = parent_of(token, parents)
    if head is None or head.type != "expression_statement" or head.named_child_count != 1:
        return None
    call = head.named_child(0)
    if call is None or call.type != "call_expression":
        return None
    function = call.child_by_field_name("function")
    if function is None or function.type != "identifier":
        return None
    body = head.next_named_sibling
    if body is None or body.type != "compound_statement":
        return None
    name = data[function.start_byte : function.end_byte].decode("utf-8", "replace")
    scope = head.parent
    if name not in listed and (scope is None or scope.type not in _DEFINITION_SCOPES):
        return None
    return Definition(head, body, name)
