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
from functools import lru_cache

from archmetrics.coupling.matching import matches, member
from archmetrics.coupling.rules import Place, ValueRule
from archmetrics.facts import Argument, CallSite, FileFacts
from archmetrics.parsers.c_family_calls import split_top_level

# a call or a brace initializer as written (``std::string("x")``, ``std::string{"x"}``)
_CALL_TEXT = re.compile(
    r"^\s*([A-Za-z_][\w:.>\-]*?)\s*(?:<.*>)?\s*(?:\((.*)\)|\{(.*)\})\s*$", re.DOTALL
)


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


class _ValueIndex:
    """Value rules by the last name their patterns match (as matching.RuleIndex does for
    link rules), a callee's rule asked once."""

    def __init__(self, rules: tuple[ValueRule, ...]) -> None:
        self.rules = rules
        self.names: set[str] = set()
        self.wild = False
        for rule in rules:
            for pattern in rule.match:
                last = pattern.rsplit(".", 1)[-1]
                self.wild = self.wild or any(c in last for c in "*?[")
                self.names.add(last)
        self.found: dict[str, ValueRule | None] = {}

    def rule_of(self, callee: str, name: str) -> ValueRule | None:
        if not self.wild and name not in self.names:
            return None
        if callee not in self.found:
            self.found[callee] = next(
                (r for r in self.rules if any(matches(p, callee) for p in r.match)), None
            )
        return self.found[callee]


@lru_cache(maxsize=64)
def _index(rules: tuple[ValueRule, ...]) -> _ValueIndex:
    return _ValueIndex(rules)


class ValueCalls:
    """A file's calls that the ``[[values]]`` rules know, indexed by what they give a value
    to: the name their value is assigned to (``target``), the argument they write
    (``out``), the parameter they declare with a default. The index is made when first
    asked (most files' endpoints are literals and never ask)."""

    def __init__(self, facts: FileFacts, rules: Sequence[ValueRule]) -> None:
        self.facts = facts
        self.index = _index(tuple(r for r in rules if facts.language in r.languages))
        self._assigned: dict[str, list[tuple[CallSite, ValueRule]]] | None = None
        self._defaults: dict[str, list[tuple[CallSite, ValueRule]]] = {}

    @property
    def rules(self) -> tuple[ValueRule, ...]:
        return self.index.rules

    @property
    def assigned(self) -> dict[str, list[tuple[CallSite, ValueRule]]]:
        if self._assigned is None:
            self._assigned = {}
            if self.index.rules:
                for call in self.facts.call_sites:
                    rule = self.index.rule_of(call.callee, call.name)
                    if rule is not None:
                        self._add(call, rule)
        return self._assigned

    @property
    def defaults(self) -> dict[str, list[tuple[CallSite, ValueRule]]]:
        _ = self.assigned  # made together
        return self._defaults

    def _add(self, call: CallSite, rule: ValueRule) -> None:
        assigned = self._assigned
        assert assigned is not None
        if call.target is not None:
            assigned.setdefault(member(call.target), []).append((call, rule))
        if rule.out is not None:
            written = [a for a in call.arguments if a.keyword is None]
            if rule.out < len(written):
                assigned.setdefault(member(written[rule.out].text), []).append((call, rule))
        if rule.value is not None and rule.name is not None:
            named = pick(call.arguments, rule.name)
            if named is not None and isinstance(named.value, str):
                self._defaults.setdefault(named.value, []).append((call, rule))

    def rule_of(self, callee: str) -> ValueRule | None:
        """The first value rule whose ``match`` names ``callee``."""
        return self.index.rule_of(callee, callee.replace("->", ".").rsplit(".", 1)[-1])

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
        parts = split_top_level(found.group(2) if found.group(2) is not None else found.group(3))
        return rule, tuple(Argument(part) for part in parts)
