"""Gates: conditions over the summary fields that fail a run (``--fail-on 'cost(new) > 20'``).

A condition is ``FIELD(LOCATION) OP NUMBER`` or ``FIELD OP NUMBER`` (the total), where FIELD is
a numeric summary field (cost, delta_s_e, scaled_changes ...), LOCATION is base, new,
framework or total, and OP is one of > >= < <= == !=. A gate is one condition or several
joined by ``and`` / ``or`` (``and`` binds tighter): ``cost(new) > 20 and changes(new) > 50``.
A field that is undefined (null, with a note) makes its condition false, so it never fails a
gate alone: the note says why it has no value.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping
from dataclasses import dataclass

from archmetrics.changeset.model import SUMMARY_FIELDS, Summary
from archmetrics.complexity.thresholds import (
    COMPARISON,
    OPERATORS,
    Threshold,
    or_of_ands,
    parse_threshold,
)

_CONDITION = re.compile(
    r"^\s*(?P<field>[a-z_]+)\s*(?:\(\s*(?P<location>[a-z]+)\s*\))?\s*" + COMPARISON
)
NUMERIC_FIELDS = (*(f for f in SUMMARY_FIELDS if f != "notes"), "unparsed")
LOCATIONS = ("base", "new", "framework", "total")


_UNIT = re.compile(r"\(\s*(?:function|file)\s*\)")


def is_unit_gate(text: str) -> bool:
    """Whether ``text`` gates the functions or files a change touches (``vg(function) >
    15``, a threshold: complexity/thresholds.py) rather than a location's summary."""
    return _UNIT.search(text) is not None


class GateError(ValueError):
    """A gate expression that cannot be read; the message says what is wrong with it."""


@dataclass(frozen=True, slots=True)
class Condition:
    field: str
    location: str
    op: str
    threshold: float

    @property
    def name(self) -> str:
        return f"{self.field}({self.location})"

    def value(self, summaries: Mapping[str, Summary]) -> float | None:
        value = getattr(summaries[self.location], self.field)
        return None if value is None else float(value)

    def true(self, summaries: Mapping[str, Summary]) -> bool:
        """Whether the comparison holds (an undefined value: it does not)."""
        value = self.value(summaries)
        return value is not None and OPERATORS[self.op](value, self.threshold)


@dataclass(frozen=True, slots=True)
class Gate:
    """``text`` fails when all conditions of one of its ``groups`` are true."""

    text: str
    groups: tuple[tuple[Condition, ...], ...]

    def failing(self, summaries: Mapping[str, Summary]) -> tuple[Condition, ...] | None:
        """The conditions of the first group that fails, or None if the gate holds."""
        for group in self.groups:
            if all(c.true(summaries) for c in group):
                return group
        return None


def parse_gate(text: str) -> Gate:
    groups = or_of_ands(text)
    return Gate(text.strip(), tuple(tuple(_condition(text, p) for p in g) for g in groups))


def _condition(text: str, part: str) -> Condition:
    match = _CONDITION.match(part)
    if not match:
        raise GateError(
            f"gate {text!r}: expected FIELD(LOCATION) OP NUMBER, e.g. 'cost(new) > 20'"
            " (conditions may be joined by and / or)"
        )
    field, location = match["field"], match["location"] or "total"
    if field not in NUMERIC_FIELDS:
        raise GateError(
            f"gate {text!r}: unknown field {field!r} (known: {', '.join(NUMERIC_FIELDS)})"
        )
    if location not in LOCATIONS:
        raise GateError(
            f"gate {text!r}: unknown location {location!r} (known: {', '.join(LOCATIONS)})"
        )
    return Condition(field, location, match["op"], float(match["number"]))


@dataclass(frozen=True, slots=True)
class GateFailure:
    gate: Gate
    values: tuple[tuple[str, float], ...]  # each condition of the failing group: its value

    def __str__(self) -> str:
        read = ", ".join(f"{name} = {value:g}" for name, value in self.values)
        return f"gate failed: {self.gate.text} ({read})"


@dataclass(frozen=True, slots=True)
class GateOrigin:
    """Where a gate is written: a configuration file (relative to the repository's top) and
    the line that holds the gate's text. A gate given on the command line has none."""

    gate: str
    path: str
    line: int


def measured_values(gate: Gate, summaries: Mapping[str, Summary]) -> dict[str, float | None]:
    """Every condition's value on these summaries, by ``FIELD(LOCATION)`` (None: undefined),
    whether the gate failed or not: what the JSON's gate entries carry."""
    return {c.name: c.value(summaries) for group in gate.groups for c in group}


def check_gates(gates: Iterable[Gate], summaries: Mapping[str, Summary]) -> tuple[GateFailure, ...]:
    """The gates that fail on these summaries (keys: base, new, framework, total)."""
    failures = []
    for gate in gates:
        group = gate.failing(summaries)
        if group is not None:
            values = tuple((c.name, c.value(summaries) or 0.0) for c in group)
            failures.append(GateFailure(gate, values))
    return tuple(failures)


UNMEASURED_GATE = "unmeasured(head) > 0"
"""The gate every gated diff adds: no file the base's configuration measures may go
unmeasured in the head (docs/ci.md, "Whose configuration")."""

_SHOWN_UNMEASURED = 5


@dataclass(frozen=True, slots=True)
class UnmeasuredFailure(GateFailure):
    """The head leaves ``files`` unmeasured that the base's configuration measures: (path,
    why) each, e.g. excluded by the head's configuration, not parsed, newly generated."""

    files: tuple[tuple[str, str], ...] = ()

    def __str__(self) -> str:
        shown = "; ".join(f"{path} ({why})" for path, why in self.files[:_SHOWN_UNMEASURED])
        more = len(self.files) - _SHOWN_UNMEASURED
        shown += f"; and {more} more" if more > 0 else ""
        count = f"{len(self.files)} file" + ("s" if len(self.files) != 1 else "")
        return (
            f"gate failed: {self.gate.text} ({count} the base's configuration measures not"
            f" measured in the head: {shown})"
        )


def unmeasured_failure(files: Iterable[tuple[str, str]]) -> UnmeasuredFailure:
    """The failure of :data:`UNMEASURED_GATE` for these (path, why) pairs."""
    found = tuple(files)
    return UnmeasuredFailure(Gate(UNMEASURED_GATE, ()), (("unmeasured(head)", len(found)),), found)


def split_gates(texts: Iterable[str]) -> tuple[tuple[Gate, ...], tuple[Threshold, ...]]:
    """Location gates and unit gates, each parsed (a bad one fails here, before any work)."""
    gates, thresholds = [], []
    for text in texts:
        if is_unit_gate(text):
            thresholds.append(parse_threshold(text))
        else:
            gates.append(parse_gate(text))
    return tuple(gates), tuple(thresholds)
