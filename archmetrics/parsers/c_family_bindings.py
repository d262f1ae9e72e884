"""C and C++ bindings (facts.Binding): what names are given which values, as written.

Four shapes, captured by the query (``@bind``): an object-like macro with a body
(``#define PORT "3490"``), an initialized declarator with ``=`` (``const char *port =
getenv("P")``, every declarator of ``int a = 1, b = 2;``, at any scope, a class member's
``static constexpr int P = 7;`` too) and a plain
assignment to a name (``fd = socket(...)``, also inside a condition:
``if ((fd = open(p)) < 0)``) or to a member of ``this`` (``this->topic_ = "x"``, named
``this->topic_``). The declared name is found through pointer, array, reference
and parenthesized declarators; brace and constructor initializers (``int x{5}``,
``std::string s("x")``) and compound assignments (``+=``) bind nothing. And a C++ type
alias, at any scope: ``using Msg = std_msgs::msg::String;``, ``using std_msgs::msg::Int32;``
(``Int32`` bound to ``std_msgs::msg::Int32``) and a ``typedef`` of one plain name (``typedef
a::B C;``); ``using namespace`` binds nothing. The value's text is normalized as statement
texts are.
"""

from __future__ import annotations

from collections.abc import Callable

from tree_sitter import Node

from archmetrics.facts import Binding
from archmetrics.parsers.c_family_names import in_order
from archmetrics.parsers.c_family_text import compact, normal_many

_WRAPPERS = frozenset(
    {"pointer_declarator", "array_declarator", "reference_declarator", "parenthesized_declarator"}
)
_NOT_ASSIGNED = frozenset({"argument_list", "initializer_list"})
_NAMES = frozenset({"identifier", "field_identifier"})
_ASSIGNED = frozenset({"identifier", "field_expression"})  # x = ..., this->x = ...
_ONE_TOKEN = _NAMES | {"type_identifier"}


def declared(declarator: Node | None) -> Node | None:
    """The identifier a declarator declares, through the declarators that wrap it."""
    for _ in range(64):  # ``int *(*(*p))`` nests, but never this deep in real code
        if declarator is None or declarator.type in _NAMES:
            return declarator
        if declarator.type not in _WRAPPERS:
            return None
        inner = declarator.child_by_field_name("declarator")
        declarator = inner if inner is not None else declarator.named_child(0)
    return None


def _parts(node: Node) -> tuple[Node | None, Node | None]:
    """(name, value) of one captured node, or Nones when it binds no plain name."""
    kind = node.type
    if kind == "alias_declaration":  # using Msg = std_msgs::msg::String;
        return node.child_by_field_name("name"), node.child_by_field_name("type")
    if kind == "type_definition":  # typedef a::B C;
        declarator = node.child_by_field_name("declarator")
        if declarator is None or declarator.type != "type_identifier":
            return None, None
        return declarator, node.child_by_field_name("type")
    if kind == "using_declaration":  # using std_msgs::msg::Int32;
        used = node.named_child(0)
        if (
            used is None
            or used.type != "qualified_identifier"
            or any(not child.is_named and child.type == "namespace" for child in node.children)
        ):
            return None, None
        name: Node | None = used
        while name is not None and name.type == "qualified_identifier":
            name = name.child_by_field_name("name")
        return (name if name is not None and name.type in _ONE_TOKEN else None), used
    if kind == "preproc_def":
        return node.child_by_field_name("name"), node.child_by_field_name("value")
    if kind == "init_declarator" or kind == "field_declaration":
        value = node.child_by_field_name("value" if kind[0] == "i" else "default_value")
        if value is None or value.type in _NOT_ASSIGNED:
            return None, None
        return declared(node.child_by_field_name("declarator")), value
    operator = node.child_by_field_name("operator")
    if operator is None or operator.type != "=":
        return None, None
    left = node.child_by_field_name("left")
    if left is not None and left.type == "field_expression":  # this->x = value
        argument = left.child_by_field_name("argument")
        if argument is None or argument.type != "this":
            left = None
    return (left if left is not None and left.type in _ASSIGNED else None), (
        node.child_by_field_name("right")
    )


def bindings(
    captured: list[Node], clean: bytes, owners: Callable[[list[int]], list[str | None]]
) -> tuple[Binding, ...]:
    """The bindings of the captured nodes in source order; ``clean``: the file with comments
    blanked; ``owners``: the enclosing function's qualified name at each byte offset."""
    found: list[tuple[str, int]] = []
    starts: list[int] = []
    values: list[bytes] = []
    for node in in_order(captured):
        name, value = _parts(node)
        if name is None or value is None:
            continue
        written = clean[name.start_byte : name.end_byte]
        # an identifier is one token: its compact form is its bytes
        text = written.decode("utf-8", "replace") if name.type in _ONE_TOKEN else compact(written)
        found.append((text, node.start_point.row + 1))
        starts.append(node.start_byte)
        values.append(clean[value.start_byte : value.end_byte])
    texts = normal_many(values)
    new = tuple.__new__
    return tuple(
        [
            new(Binding, (name, text, line, function))
            for (name, line), text, function in zip(found, texts, owners(starts), strict=True)
            if text
        ]
    )
