"""What a file's graph names resolve against: the nodes and ROS 1 NodeHandles it makes (a
pack's ``[[scopes]]``; docs/metrics.md, "ROS: names and types").

A node scope is a call naming a node (``Node("talker")`` in a constructor's initializer,
``rclcpp::Node::make_shared("talker")``, ``super().__init__("talker")``,
``ros::init(argc, argv, "talker")``). A call's names resolve against, in this order: the
node made by the object it is called on (``node->create_publisher(...)`` after ``node =
rclcpp::Node::make_shared("talker")``); the node its class makes (the constructor's
``Node("talker")`` for a call in any method of the class); the file's one node. A handle
scope is a ROS 1 NodeHandle made with a namespace (``ros::NodeHandle pnh("~")``, a
constructor's member initializer ``private_nh_("~")``, a child of another handle
``ros::NodeHandle layer(nh, "obstacles")``): names given to calls on it resolve under that
namespace, and under none that can be known (:data:`UNKNOWN`) when it is computed
(``ros::NodeHandle pnh("~/" + name)``). A handle a file does not make (a function's
parameter, a member initialized from one) is taken as the node's: its namespace is not
followed across calls.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

from archmetrics.coupling.matching import (
    Requirements,
    constructed,
    matches,
    member,
    normalize_callee,
)
from archmetrics.coupling.rosnames import UNKNOWN, NodeName, clean_namespace
from archmetrics.coupling.rules import Place, ScopeRule
from archmetrics.coupling.trace import ArgumentReader
from archmetrics.coupling.values import pick
from archmetrics.facts import CallSite, FileFacts


@dataclass(frozen=True, slots=True)
class Scope:
    """One node or handle a file makes: where, what it makes it into, what it names."""

    kind: str
    function: str | None
    target: str | None
    node: NodeName | None = None
    namespace: str | None = None  # a handle's, as written (UNKNOWN: computed)
    parent: str | None = None  # a handle made from another (``NodeHandle(nh, "ns")``)


def owner(function: str | None) -> str:
    """The class a function is a method of (``ns::Talker`` of ``ns::Talker::on_timer``,
    ``Talker`` of ``Talker.__init__``); "" for a free function or none."""
    if function is None:
        return ""
    for separator in ("::", "."):
        if separator in function:
            return function.rsplit(separator, 1)[0]
    return ""


def receiver_of(call: CallSite) -> str | None:
    """The object a call is made on, as members are compared (``this->pub_`` is ``pub_``)."""
    if call.receiver is None:
        return None
    return member(call.receiver)


class FileScopes:
    """The node and handle scopes of one file, and which applies to a call (found when a
    call first asks: most files' sites need none)."""

    def __init__(
        self,
        facts: FileFacts,
        rules: Sequence[ScopeRule],
        visible: Sequence[str],
        read: ArgumentReader,
    ) -> None:
        self.facts, self.rules, self.visible, self.read = facts, rules, visible, read
        self._scopes: list[Scope] | None = None
        self._members: MemberHandles | None = None

    @property
    def scopes(self) -> list[Scope]:
        if self._scopes is None:
            self._scopes = self._find()
        return self._scopes

    def _find(self) -> list[Scope]:
        language = self.facts.language
        seen = Requirements(self.visible)
        usable = [r for r in self.rules if language in r.languages and seen.met(r.requires)]
        if not usable:
            return []
        names = {normalize_callee(p).rsplit(".", 1)[-1] for r in usable for p in r.match}
        found = []
        for call in self.facts.call_sites:
            callee, _ = constructed(call)
            if normalize_callee(callee).rsplit(".", 1)[-1] not in names:
                continue
            rule = next((r for r in usable if any(matches(p, callee) for p in r.match)), None)
            if rule is not None:
                found.append(_scope(call, rule, self.read))
        handle = next((r for r in usable if r.kind == "handle" and r.namespace is not None
                       and r.namespace.value is None), None)  # fmt: skip
        if handle is not None:
            self._members = MemberHandles(self.facts.call_sites, handle, self.read)
        return found

    def context(self, call: CallSite) -> tuple[NodeName, str | None]:
        """The node a call's names resolve in (its name None when not known), and the
        namespace of the handle it is made on (None: none; UNKNOWN: computed)."""
        receiver = receiver_of(call)
        handle = self._namespace(receiver, call.function) if receiver is not None else None
        nodes = [s for s in self.scopes if s.kind == "node" and s.node is not None]
        found = [s for s in nodes if receiver is not None and s.target == receiver]
        if not found:
            found = [s for s in nodes if owner(s.function) == owner(call.function)]
        if not found:
            found = nodes
        distinct = {s.node for s in found}
        node = distinct.pop() if len(distinct) == 1 else None
        return node or NodeName(None), handle

    def _namespace(self, receiver: str, function: str | None, depth: int = 0) -> str | None:
        """The namespace of the handle ``receiver`` names in ``function``: made in this file
        (a handle scope, or a member initializer of the class's constructor), else None."""
        handles = [s for s in self.scopes if s.kind == "handle" and s.target == receiver]
        if not handles and self._members is not None:
            handles = self._members(receiver, owner(function))
        if not handles:
            return None
        found = handles[0]
        if found.parent is None or depth > 4:
            return found.namespace
        parent = self._namespace(found.parent, found.function, depth + 1)
        return _joined(parent, found.namespace)


def _text(call: CallSite, place: Place | None, read: ArgumentReader) -> str | None:
    """The text a place of a scope call holds (a literal, a constant, a traced value)."""
    if place is None:
        return None
    if place.value is not None:
        return place.value
    argument = pick(call.arguments, place)
    if argument is None:
        return None
    value, _ = read(argument, call.function, call.span.start)
    return value if isinstance(value, str) else None


def _joined(parent: str | None, child: str | None) -> str | None:
    """A child handle's namespace under its parent's (``~`` and ``layer``: ``~/layer``)."""
    if parent == UNKNOWN or child == UNKNOWN:
        return UNKNOWN
    if not child or not parent or child.startswith(("/", "~")):
        return child or parent
    return f"{parent.rstrip('/')}/{child}"


_PLAIN = re.compile(r"[A-Za-z_]\w*(?:->|\.)?[A-Za-z_]?\w*")


def _handle(call: CallSite, rule: ScopeRule, read: ArgumentReader, target: str | None) -> Scope:
    """A NodeHandle: with no argument the node's namespace; with a name, under it (computed:
    UNKNOWN); with another handle first, under that handle (``NodeHandle(nh, "ns")``)."""
    place = rule.namespace
    if place is not None and place.value is not None:
        return Scope("handle", call.function, target, namespace=place.value)
    arguments = [a for a in call.arguments if a.keyword is None]
    if not arguments:
        return Scope("handle", call.function, target)
    first = _text(call, place, read)
    if first is not None:
        return Scope("handle", call.function, target, namespace=first)
    head = arguments[0].text.replace(" ", "").lstrip("*")
    if not _PLAIN.fullmatch(head) or len(arguments) > 3:
        return Scope("handle", call.function, target, namespace=UNKNOWN)
    child: str | None = None
    if len(arguments) > 1:
        value, _ = read(arguments[1], call.function, call.span.start)
        child = value if isinstance(value, str) else UNKNOWN
    return Scope("handle", call.function, target, namespace=child, parent=member(head))


class MemberHandles:
    """The handles a class's constructors initialize as members when the member's type is
    declared in another file (``: private_nh_("~")``, ``: nh_(nh)``): the initializer is a
    call named by the member, asked for only by a call made on that member."""

    def __init__(self, calls: Sequence[CallSite], rule: ScopeRule, read: ArgumentReader) -> None:
        self.calls, self.rule, self.read = calls, rule, read
        self._found: dict[tuple[str, str], Scope] | None = None

    def __call__(self, name: str, cls: str) -> list[Scope]:
        if self._found is None:
            self._found = {}
            for call in self.calls:
                function = call.function or ""
                if call.receiver is None and not call.templates and _constructor(function):
                    key = (member(call.callee), owner(function))
                    self._found.setdefault(key, _handle(call, self.rule, self.read, key[0]))
        found = self._found.get((name, cls))
        return [found] if found is not None else []


def _constructor(function: str) -> bool:
    """Whether ``function`` is a constructor (``ns::Talker::Talker``)."""
    parts = function.rsplit("::", 2)
    return len(parts) >= 2 and parts[-1] == parts[-2]


def _scope(call: CallSite, rule: ScopeRule, read: ArgumentReader) -> Scope:
    target = member(call.target) if call.target else None
    if rule.kind == "handle":
        return _handle(call, rule, read, target)
    namespace = _text(call, rule.namespace, read)
    name = _text(call, rule.name, read)
    node = NodeName(name.strip("/") or None, clean_namespace(namespace)) if name else None
    return Scope("node", call.function, target, node=node)
