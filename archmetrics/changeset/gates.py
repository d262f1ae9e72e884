"""Gates: conditions over the summary fields that fail a run (``--fail-on 'cost(new) > 20'``).

A gate is ``FIELD(LOCATION) OP NUMBER`` or ``FIELD OP NUMBER`` (the total), where FIELD is a
numeric summary field (cost, delta_s_e, scaled_changes ...), LOCATION is base, new, framework
or total, and OP is one of > >= < <= == !=. A field that is undefined (null, with a note) never
fails a gate: the note says why it has no value.
"""

from __future__ import annotations

import operator
import re
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass

from archmetrics.changeset.model import SUMMARY_FIELDS, Summary

_OPERATORS: Mapping[str, Callable[[float, float], bool]] = {
    ">=": operator.ge,
    "<=": operator.le,
    "==": operator.eq,
    "!=": operator.ne,
    ">": operator.gt,
    "<": operator.lt,
}
_GATE = re.compile(
    r"^\s*(?P<field>[a-z_]+)\s*(?:\(\s*(?P<location>[a-z]+)\s*\))?\s*"
    r"(?P<op>>=|<=|==|!=|>|<)\s*(?P<number>-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)\s*$"
)
NUMERIC_FIELDS = tuple(f for f in SUMMARY_FIELDS if f != "notes")
LOCATIONS = ("base", "new", "framework", "total")


class GateError(ValueError):
    """A gate expression that cannot be read; the message says what is wrong with it."""


@dataclass(frozen=True, slots=True)
class Gate:
    text: str
    field: str
    location: str
    op: str
    threshold: float

    def holds(self, summaries: Mapping[str, Summary]) -> tuple[bool, float | None]:
        """Whether the gate holds, and the value it read (None: undefined, so it holds)."""
        value = getattr(summaries[self.location], self.field)
        if value is None:
            return True, None
        return not _OPERATORS[self.op](float(value), self.threshold), float(value)


def parse_gate(text: str) -> Gate:
    match = _GATE.match(text)
    if not match:
        raise GateError(f"gate {text!r}: expected FIELD(LOCATION) OP NUMBER, e.g. 'cost(new) > 20'")
    field, location = match["field"], match["location"] or "total"
    if field not in NUMERIC_FIELDS:
        raise GateError(
            f"gate {text!r}: unknown field {field!r} (known: {', '.join(NUMERIC_FIELDS)})"
        )
    if location not in LOCATIONS:
        raise GateError(
            f"gate {text!r}: unknown location {location!r} (known: {', '.join(LOCATIONS)})"
        )
    return Gate(text.strip(), field, location, match["op"], float(match["number"]))


@dataclass(frozen=True, slots=True)
class GateFailure:
    gate: Gate
    value: float

    def __str__(self) -> str:
        gate = self.gate
        return f"gate failed: {gate.text} ({gate.field}({gate.location}) = {self.value:g})"


def check_gates(gates: Iterable[Gate], summaries: Mapping[str, Summary]) -> tuple[GateFailure, ...]:
    """The gates that fail on these summaries (keys: base, new, framework, total)."""
    failures = []
    for gate in gates:
        held, value = gate.holds(summaries)
        if not held and value is not None:
            failures.append(GateFailure(gate, value))
    return tuple(failures)
