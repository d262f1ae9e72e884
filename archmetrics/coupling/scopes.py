"""What a file's graph names resolve against: the nodes and ROS 1 NodeHandles it makes (a
pack's ``[[scopes]]``; docs/metrics.md, "ROS: names and types").

A node scope is a call naming a node (``Node("talker")`` in a constructor's initializer,
``rclcpp::Node::make_shared("talker")``, ``super().__init__("talker")``,
``ros::init(argc, argv, "talker")``). A call's names resolve against, in this order: the
node made by the object it is called on (``node->create_publisher(...)`` after ``node =
rclcpp::Node::make_shared("talker")``); the node its class makes (the constructor's
``Node("talker")`` for a call in any method of the class); the file's one node. A handle
scope is a ROS 1 NodeHandle made with a namespace (``ros::NodeHandle pnh("~")``): names given
to calls on it resolve under that namespace.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from archmetrics.coupling.matching import (
    Requirements,
    constructed,
    matches,
    normalize_callee,
)
from archmetrics.coupling.rosnames import NodeName, clean_namespace
from archmetrics.coupling.rules import Place, ScopeRule
from archmetrics.coupling.trace import ArgumentReader, member
from archmetrics.coupling.values import pick
from archmetrics.facts import CallSite, FileFacts


@dataclass(frozen=True, slots=True)
class Scope:
    """One node or handle a file makes: where, what it makes it into, what it names."""

    kind: str
    function: str | None
    target: str | None
    node: NodeName | None = None
    namespace: str | None = None  # a handle's, as written


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
        return found

    def context(self, call: CallSite) -> tuple[NodeName, str | None]:
        """The node a call's names resolve in (its name None when not known), and the
        namespace of the handle it is made on (None: none)."""
        receiver = receiver_of(call)
        handle = next(
            (s.namespace for s in self.scopes if s.kind == "handle" and s.target == receiver),
            None,
        )
        nodes = [s for s in self.scopes if s.kind == "node" and s.node is not None]
        found = [s for s in nodes if receiver is not None and s.target == receiver]
        if not found:
            found = [s for s in nodes if owner(s.function) == owner(call.function)]
        if not found:
            found = nodes
        distinct = {s.node for s in found}
        node = distinct.pop() if len(distinct) == 1 else None
        return node or NodeName(None), handle


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


def _scope(call: CallSite, rule: ScopeRule, read: ArgumentReader) -> Scope:
    target = member(call.target) if call.target else None
    namespace = _text(call, rule.namespace, read)
    if rule.kind == "handle":
        return Scope("handle", call.function, target, namespace=namespace)
    name = _text(call, rule.name, read)
    node = NodeName(name.strip("/") or None, clean_namespace(namespace)) if name else None
    return Scope("node", call.function, target, node=node)
