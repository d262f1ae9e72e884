"""C++ constructor calls written without a call expression, and what calls' values are
assigned to (facts.CallSite's ``templates`` and ``target``).

A link is often made by constructing an object: ``new tf2_ros::TransformListener(buf)``,
``message_filters::Subscriber<Image> sub(this, "image");``, a constructor's initializer
``Node("talker")`` or ``as_(nh_, "fibonacci", false)``. tree-sitter reads none of these as a
``call_expression``; each is a call site here, its callee the class (template arguments in
``templates``; a member's initializer names the member, whose declared type, when this file
declares it, is the callee). And a call's value is often kept to be used later
(``pub_ = create_publisher<T>("x", 10);`` then ``pub_->publish(m)``): ``target`` says where.
"""

from __future__ import annotations

from collections.abc import Iterable

from tree_sitter import Node

from archmetrics.parsers.c_family_bindings import declared
from archmetrics.parsers.c_family_calls import Construction  # where, class, arguments, target
from archmetrics.parsers.c_family_names import text
from archmetrics.parsers.c_family_text import compact

_ARGUMENTS = frozenset({"argument_list", "initializer_list"})
_LONGEST = 400  # bytes of a target or a type read: names, not expressions


def _short(node: Node, data: bytes) -> str | None:
    """``node``'s compact text, None when it is too long to be a name."""
    if node.end_byte - node.start_byte > _LONGEST:
        return None
    return compact(text(node, data))


def _chain_head(value: Node) -> Node | None:
    """The call an accessor chain on a call starts with: ``f(a)`` in ``f(a).value``,
    ``f(a).as_string()`` or ``f(a).g().x`` (everything after it a member, or a call of
    one without arguments); None for anything else."""
    node: Node | None = value
    for _ in range(8):
        if node is None:
            return None
        if node.type == "field_expression":
            node = node.child_by_field_name("argument")
            continue
        if node.type != "call_expression":
            return None
        arguments = node.child_by_field_name("arguments")
        function = node.child_by_field_name("function")
        with_arguments = arguments is not None and arguments.named_child_count > 0
        on_member = function is not None and function.type == "field_expression"
        if node.id != value.id and (with_arguments or not on_member):
            return node
        if with_arguments or function is None or not on_member:
            return None
        node = function.child_by_field_name("argument")
    return None


def _values(value: Node | None) -> list[Node]:
    """The calls an assigned value makes its target's: the value itself when it is a call
    (in parentheses too), and the call an accessor chain on it starts with."""
    while value is not None and value.type == "parenthesized_expression":
        value = value.named_child(0)
    if value is None:
        return []
    found = [value] if value.type in ("call_expression", "new_expression") else []
    head = _chain_head(value)
    if head is not None and head.id != value.id:
        found.append(head)
    return found


_VALUES = frozenset(
    {"call_expression", "new_expression", "field_expression", "parenthesized_expression"}
)


def _assignment(node: Node) -> tuple[Node | None, Node | None]:
    """(target, value) of an assignment, initialized declarator or member initializer whose
    value may be a call; Nones for any other (most assign literals or names: no text read)."""
    kind = node.type
    if kind == "init_declarator":
        value = node.child_by_field_name("value")
        if value is None or value.type not in _VALUES:
            return None, None
        return declared(node.child_by_field_name("declarator")), value
    if kind == "assignment_expression":
        right = node.child_by_field_name("right")
        if right is None or right.type not in _VALUES:
            return None, None
        operator = node.child_by_field_name("operator")
        if operator is None or operator.type != "=":
            return None, None
        return node.child_by_field_name("left"), right
    if kind == "field_initializer":
        name = node.named_child(0)
        arguments = node.named_child(node.named_child_count - 1) if name is not None else None
        if name is None or arguments is None or arguments.named_child_count != 1:
            return None, None
        value = arguments.named_child(0)
        return (name, value) if value is not None and value.type in _VALUES else (None, None)
    return None, None


def call_targets(nodes: Iterable[Node], data: bytes) -> dict[tuple[int, int], str]:
    """For each call (or ``new``) whose value an assignment, an initialized declarator or
    a constructor's member initializer keeps: its byte range -> the target as written."""
    targets: dict[tuple[int, int], str] = {}
    for node in nodes:
        target, value = _assignment(node)
        if target is None:
            continue
        calls = _values(value)
        if calls and (name := _short(target, data)) is not None:
            for call in calls:
                targets[(call.start_byte, call.end_byte)] = name
    return targets


def field_types(nodes: Iterable[Node], data: bytes, wanted: set[str]) -> dict[str, str]:
    """The declared type of each member among ``wanted`` a file declares by a plain name
    (``Foo x_;``, not a pointer or a reference), for names declared with one type only."""
    types: dict[str, str | None] = {}
    for node in nodes:
        for index in range(node.named_child_count):
            declarator = node.named_child(index)
            if declarator is None or declarator.type != "field_identifier":
                continue
            name = text(declarator, data).decode("utf-8", "replace")
            if name not in wanted:
                continue
            kind = node.child_by_field_name("type")
            written = _short(kind, data) if kind is not None else None
            types[name] = written if types.get(name, written) == written else None
    return {name: kind for name, kind in types.items() if kind}


def initialized_members(nodes: Iterable[Node], data: bytes) -> set[str]:
    """The names of the members constructors' initializers name (``as_`` of ``as_(...)``)."""
    found = set()
    for node in nodes:
        name = node.named_child(0) if node.type == "field_initializer" else None
        if name is not None and name.type == "field_identifier":
            found.add(text(name, data).decode("utf-8", "replace"))
    return found


def _vexing(declarator: Node, made: Node, data: bytes) -> Construction | None:
    """``tf2_ros::TransformListener listener(buffer);`` in a function body, which the grammar
    reads as declaring a function ``listener`` taking a ``buffer`` (C++'s "most vexing
    parse"): a construction when the type is a class and each parameter is one plain name,
    as no local function declaration is written."""
    name = declarator.child_by_field_name("declarator")
    parameters = declarator.child_by_field_name("parameters")
    if name is None or name.type != "identifier" or parameters is None:
        return None
    if made.type not in ("type_identifier", "qualified_identifier", "template_type"):
        return None
    named = [child for child in parameters.named_children if child.type != "comment"]
    if not named or any(
        child.type != "parameter_declaration"
        or child.named_child_count != 1
        or (child.named_child(0) or child).type != "type_identifier"
        for child in named
    ):
        return None
    written = _short(made, data)
    return (declarator, written, parameters, _short(name, data)) if written else None


def constructions(
    node: Node, data: bytes, members: dict[str, str], targets: dict[tuple[int, int], str]
) -> list[Construction]:
    """The constructor calls ``node`` makes: (where, class, arguments, target) for a
    ``new`` expression, each declarator of a declaration initialized by ``(...)`` or
    ``{...}`` (or read as a function declaration: :func:`_vexing`), a constructor's
    initializer of a base or a member."""
    kind = node.type
    if kind == "new_expression":
        made = node.child_by_field_name("type")
        arguments = node.child_by_field_name("arguments")
        if made is None or arguments is None or (written := _short(made, data)) is None:
            return []
        return [(node, written, arguments, targets.get((node.start_byte, node.end_byte)))]
    if kind == "declaration":
        made = node.child_by_field_name("type")
        written = _short(made, data) if made is not None else None
        if made is None or written is None:
            return []
        found = []
        for index in range(node.named_child_count):
            declarator = node.named_child(index)
            if declarator is not None and declarator.type == "function_declarator":
                if (vexing := _vexing(declarator, made, data)) is not None:
                    found.append(vexing)
                continue
            if declarator is None or declarator.type != "init_declarator":
                continue
            value = declarator.child_by_field_name("value")
            name = declared(declarator.child_by_field_name("declarator"))
            if value is not None and value.type in _ARGUMENTS and name is not None:
                found.append((declarator, written, value, _short(name, data)))
        return found
    if kind == "field_initializer":
        name = node.named_child(0)
        arguments = node.named_child(node.named_child_count - 1) if name is not None else None
        if name is None or arguments is None or arguments.type not in _ARGUMENTS:
            return []
        written = _short(name, data)
        if written is None:
            return []
        member = members.get(written)
        return [(node, member or written, arguments, written if member else None)]
    return []
