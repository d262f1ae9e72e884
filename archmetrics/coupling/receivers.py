"""A call on an object takes the endpoint of the call that made the object (a rule's
``created_by``): ``pub_->publish(msg)`` publishes where ``pub_ =
create_publisher<T>("cmd_vel", 10)`` said, ``self.cli.call_async(req)`` calls the service
``self.cli = self.create_client(AddTwoInts, "add_two_ints")`` named.

The object is matched by name (``this->pub_`` and ``pub_`` are one member) among the file's
link sites whose call's value was assigned to it (facts.CallSite.target), preferring a
making call in the same class; two makers with different endpoints leave the site unknown,
its note listing them. A call whose object no link site made is no site when the file
shows the object is something else: it is assigned from the construction of a class
(``self.client = mqtt.Client()``), or a class of the file other than the caller's defines
the method (``EventBus::publish``: an in-process bus sharing ROS's verbs).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

from archmetrics.coupling.matching import constructed, matches, member
from archmetrics.coupling.model import LinkSite
from archmetrics.coupling.rules import Rule
from archmetrics.coupling.scopes import owner, receiver_of
from archmetrics.facts import CallSite, FileFacts


@dataclass(frozen=True, slots=True)
class Found:
    """A link site as first read, with the rule and the call that made it."""

    rule: Rule
    site: LinkSite
    call: CallSite | None  # None for a definition site


def _makers(found: Found, everything: Sequence[Found]) -> list[Found]:
    spec = found.rule.endpoint
    receiver = receiver_of(found.call) if found.call is not None else None
    if spec is None or receiver is None:
        return []
    makers = [
        other
        for other in everything
        if other.call is not None
        and other.call.target is not None
        and member(other.call.target) == receiver
        and any(matches(p, constructed(other.call)[0]) for p in spec.created_by)
    ]
    mine = owner(found.site.function)
    same_class = [m for m in makers if owner(m.site.function) == mine]
    return same_class or makers


def _wrapped(found: Found, everything: Sequence[Found], facts: FileFacts) -> list[Found]:
    """The makers of the object a wrapper made by ``created_by`` was given: a realtime
    publisher ``rt_ = std::make_shared<RealtimePublisher<T>>(pub_)`` publishes where
    ``pub_`` was made to (the wrapper itself is no site)."""
    spec = found.rule.endpoint
    receiver = receiver_of(found.call) if found.call is not None else None
    if spec is None or receiver is None:
        return []
    inner = {
        member(call.arguments[0].text.removeprefix("std::move(").rstrip(")"))
        for call in facts.call_sites
        if call.target is not None and member(call.target) == receiver and call.arguments
        and any(matches(p, constructed(call)[0]) for p in spec.created_by)
    }  # fmt: skip
    return [
        other
        for other in everything
        if other.call is not None and other.call.target is not None
        and member(other.call.target) in inner
    ]  # fmt: skip


def _other_object(call: CallSite, receiver: str, facts: FileFacts) -> bool:
    """Whether ``facts`` show the object ``receiver`` names is no ROS object (module doc)."""
    for other in facts.call_sites:
        if other.target is not None and member(other.target) == receiver:
            last = other.callee.replace("::", ".").rpartition(".")[2]
            if last[:1].isupper() and "<" not in other.callee:
                return True  # made by a class no rule names (a maker would have a site)
    mine = owner(call.function)
    for function in facts.functions:
        name = function.qualified_name
        if name.endswith(("::" + call.name, "." + call.name)):
            defined = owner(name)
            if defined and defined != mine:
                return True
    return False


def invoked(call: CallSite, made: set[str]) -> CallSite | None:
    """A call of an object itself (``add_two_ints(x, y)`` on a ``rospy.ServiceProxy``) as
    the method call rules name it, ``add_two_ints.__call__``; None when ``call`` calls no
    object a link site of the file made (``made``: their targets)."""
    if call.receiver not in (None, "self", "this") or member(call.callee) not in made:
        return None
    return call._replace(callee=f"{call.callee}.__call__", name="__call__", receiver=call.callee)


def bound_to_makers(found: Sequence[Found], facts: FileFacts | None = None) -> list[Found]:
    """Each site of ``found`` whose rule says ``created_by`` and that has no endpoint of its
    own, given the endpoint, name, node, data type and parameter of its object's maker; a
    site whose rule says ``created_only`` and whose object no call of the file made is left
    out (a method name too common to count on any receiver: ``call``)."""
    done = []
    for item in found:
        spec = item.rule.endpoint
        if spec is None or not spec.created_by or item.site.endpoint is not None:
            done.append(item)
            continue
        receiver = receiver_of(item.call) if item.call is not None else None
        if receiver in (None, "this", "self", "(*this)"):
            continue  # a method of the class itself (this->publish()): no object made
        makers = _makers(item, found)
        if not makers and facts is not None:
            makers = _wrapped(item, found, facts)
        if not makers and spec.created_only:
            continue  # no object this file makes: no link (``subprocess.call``)
        if (
            not makers and item.call is not None and facts is not None and receiver is not None
            and _other_object(item.call, receiver, facts)
        ):
            continue  # fmt: skip
        points = {m.site.endpoint.key for m in makers if m.site.endpoint is not None}
        site = item.site
        if len(points) > 1:
            listed = ", ".join(sorted(points))
            site = replace(site, note=f"made by several calls: {listed}")
        elif makers:
            maker = next((m for m in makers if m.site.endpoint is not None), makers[0])
            made = maker.site
            endpoint = None if made.endpoint is None else replace(made.endpoint, via="receiver")
            site = replace(
                site, endpoint=endpoint, note=made.note if endpoint is None else "",
                name=made.name, node=made.node, data_type=site.data_type or made.data_type,
                parameter=made.parameter,
            )  # fmt: skip
        elif not site.note:
            receiver = receiver_of(item.call) if item.call is not None else None
            site = replace(site, note=f"{receiver or 'the object'} is not made in this file")
        done.append(Found(item.rule, site, item.call))
    return done
