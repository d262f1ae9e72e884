"""Calls whose value is known statically although they are no literal (a pack's
``[[values]]``): a parameter declared with its default, read back by name, written into a
variable, or wrapped (docs/metrics.md, "ROS: names and types").

``topic_ = declare_parameter("topic", "cmd_vel")`` gives ``topic_`` the default
``"cmd_vel"``; ``declare_parameter("topic", "cmd_vel")`` then ``topic_ =
get_parameter("topic").as_string()`` or ``get_parameter("topic", topic_)`` give it the same;
``rclcpp::ParameterValue("cmd_vel")`` and ``std::string("cmd_vel")`` are ``"cmd_vel"``. The
tracer (trace.py) asks this index which calls give a name its value; a value read through a
parameter's default says so (``via = "parameter:topic"``), so that a parameter file that sets
the parameter can replace it (rosgraph.py).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence

from archmetrics.coupling.matching import matches
from archmetrics.coupling.rules import Place, ValueRule
from archmetrics.coupling.trace import member
from archmetrics.facts import Argument, CallSite, FileFacts
from archmetrics.parsers.c_family_calls import split_top_level

_CALL_TEXT = re.compile(r"^\s*([A-Za-z_][\w:.>\-]*?)\s*(?:<.*>)?\s*\((.*)\)\s*$", re.DOTALL)


def pick(arguments: Sequence[Argument], place: Place) -> Argument | None:
    """The argument ``place`` names (its keyword first, then its position)."""
    if place.keyword is not None:
        for argument in arguments:
            if argument.keyword == place.keyword:
                return argument
    positional = [a for a in arguments if a.keyword is None]
    if place.arg is not None and place.arg < len(positional):
        return positional[place.arg]
    return None


class ValueCalls:
    """A file's calls that the ``[[values]]`` rules know, indexed by what they give a value
    to: the name their value is assigned to (``target``), the argument they write
    (``out``), the parameter they declare with a default."""

    def __init__(self, facts: FileFacts, rules: Sequence[ValueRule]) -> None:
        self.rules = [r for r in rules if facts.language in r.languages]
        self.assigned: dict[str, list[tuple[CallSite, ValueRule]]] = {}
        self.defaults: dict[str, list[tuple[CallSite, ValueRule]]] = {}
        if not self.rules:
            return
        wanted = {p.rsplit(".", 1)[-1] for r in self.rules for p in r.match}
        for call in facts.call_sites:
            if call.name not in wanted and not any("*" in w for w in wanted):
                continue
            rule = self.rule_of(call.callee)
            if rule is None:
                continue
            if call.target is not None:
                self.assigned.setdefault(member(call.target), []).append((call, rule))
            if rule.out is not None:
                written = [a for a in call.arguments if a.keyword is None]
                if rule.out < len(written):
                    self.assigned.setdefault(member(written[rule.out].text), []).append(
                        (call, rule)
                    )
            if rule.value is not None and rule.name is not None:
                named = pick(call.arguments, rule.name)
                if named is not None and isinstance(named.value, str):
                    self.defaults.setdefault(named.value, []).append((call, rule))

    def rule_of(self, callee: str) -> ValueRule | None:
        """The first value rule whose ``match`` names ``callee``."""
        for rule in self.rules:
            if any(matches(pattern, callee) for pattern in rule.match):
                return rule
        return None

    def giving(self, name: str) -> Iterable[tuple[CallSite, ValueRule]]:
        """The calls that give the variable or member ``name`` its value."""
        return self.assigned.get(member(name), ())

    def declared(self, parameter: str) -> Iterable[tuple[CallSite, ValueRule]]:
        """The calls that declare ``parameter`` with a default."""
        return self.defaults.get(parameter, ())

    def wrapped(self, text: str) -> tuple[ValueRule, tuple[Argument, ...]] | None:
        """An argument written as a call a value rule knows (``rclcpp::ParameterValue("x")``):
        that rule and the call's arguments as texts."""
        found = _CALL_TEXT.match(text)
        if found is None or not self.rules:
            return None
        rule = self.rule_of(found.group(1))
        if rule is None or rule.value is None:
            return None
        parts = split_top_level(found.group(2))
        return rule, tuple(Argument(part) for part in parts)
