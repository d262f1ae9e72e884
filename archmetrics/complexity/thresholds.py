"""Thresholds: absolute limits a scan checks (``--fail-on 'vg(function) > 15'``), as xenon and
lizard users expect of a complexity gate.

A threshold is one or more conditions ``FIELD(UNIT) OP NUMBER`` joined by ``and`` / ``or``
(``and`` binds tighter), every condition on the same UNIT: ``function``, ``file``,
``element`` or ``total``. FIELD is one of the unit's numbers (:data:`FIELDS`); OP one of
``> >= < <= == !=``. The expression says when a unit fails: ``vg(function) > 15 and
loc(function) > 60`` fails every function over both limits, each named with its file and line.
"""

from __future__ import annotations

import operator
import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass
from typing import NamedTuple, Protocol

OPERATORS: Mapping[str, Callable[[float, float], bool]] = {
    ">=": operator.ge,
    "<=": operator.le,
    "==": operator.eq,
    "!=": operator.ne,
    ">": operator.gt,
    "<": operator.lt,
}
COMPARISON = r"(?P<op>>=|<=|==|!=|>|<)\s*(?P<number>-?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?)\s*$"
"""An operator and a number, ending a condition (the gates of a diff read the same)."""
_CONDITION = re.compile(r"^\s*(?P<field>[a-z_]+)\s*\(\s*(?P<unit>[a-z]+)\s*\)\s*" + COMPARISON)
_JOIN = re.compile(r"\s+(and|or)\s+")


def or_of_ands(text: str) -> list[list[str]]:
    """The conditions of ``text`` joined by ``and`` / ``or``, ``and`` binding tighter: the
    groups (any of which fails), each a list of conditions (all of which must hold)."""
    groups: list[list[str]] = [[]]
    for index, part in enumerate(_JOIN.split(text.strip())):
        if index % 2 == 0:
            groups[-1].append(part)
        elif part == "or":
            groups.append([])
    return groups


FIELDS: Mapping[str, tuple[str, ...]] = {
    "function": ("vg", "loc"),
    "file": ("vg", "loc", "sloc", "functions", "warnings"),
    "element": ("vg", "loc", "sloc", "s_a", "s_e", "d_a", "d_e"),
    "total": ("files", "functions", "loc", "sloc", "vg", "warnings", "unparsed"),
}
"""The numbers each unit has (docs/metrics.md: λ is ``loc``, v_g is ``vg``)."""


class ThresholdError(ValueError):
    """A threshold that cannot be read; the message says what is wrong with it."""


@dataclass(frozen=True, slots=True)
class Condition:
    field: str
    op: str
    limit: float

    def holds(self, values: Mapping[str, int]) -> bool:
        return OPERATORS[self.op](float(values[self.field]), self.limit)


@dataclass(frozen=True, slots=True)
class Threshold:
    """``any`` of the groups, each ``all`` of its conditions, on one ``unit``."""

    text: str
    unit: str
    groups: tuple[tuple[Condition, ...], ...]

    def fails(self, values: Mapping[str, int]) -> bool:
        return any(all(c.holds(values) for c in group) for group in self.groups)

    @property
    def fields(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(c.field for group in self.groups for c in group))


def parse_threshold(text: str) -> Threshold:
    example = "e.g. 'vg(function) > 15' or 'vg(function) > 10 and loc(function) > 60'"
    groups = [[_condition(text, part, example) for part in group] for group in or_of_ands(text)]
    units = {unit for group in groups for unit, _ in group}
    if len(units) != 1:
        raise ThresholdError(
            f"threshold {text!r}: conditions joined by and/or must name one unit, not "
            + " and ".join(sorted(units))
        )
    conditions = tuple(tuple(condition for _, condition in group) for group in groups)
    return Threshold(text.strip(), units.pop(), conditions)


def _condition(text: str, part: str, example: str) -> tuple[str, Condition]:
    """One condition's unit and the condition."""
    match = _CONDITION.match(part)
    if not match:
        raise ThresholdError(
            f"threshold {text!r}: {part!r} is not FIELD(UNIT) OP NUMBER, {example}"
        )
    field, unit = match["field"], match["unit"]
    if unit not in FIELDS:
        known = ", ".join(FIELDS)
        raise ThresholdError(f"threshold {text!r}: unknown unit {unit!r} (known: {known})")
    if field not in FIELDS[unit]:
        known = ", ".join(FIELDS[unit])
        raise ThresholdError(f"threshold {text!r}: a {unit} has no {field!r} (it has: {known})")
    return unit, Condition(field, match["op"], float(match["number"]))


@dataclass(frozen=True, slots=True)
class Unit:
    """One function, file, element or the total: what names it, where it is, its numbers,
    and the fields a reviewer's comment exempts it from (a function's ``suppressed``)."""

    name: str
    path: str | None
    line: int | None
    values: Mapping[str, int]
    suppressed: tuple[str, ...] = ()

    def exempt(self, fields: Iterable[str]) -> bool:
        """Whether a suppression comment exempts this unit from every one of ``fields``."""
        return all(f in self.suppressed or "*" in self.suppressed for f in fields)


@dataclass(frozen=True, slots=True)
class ThresholdFailure:
    threshold: Threshold
    unit: Unit

    def __str__(self) -> str:
        unit = self.unit
        where = f"{unit.path}:{unit.line} " if unit.path and unit.line else ""
        if unit.path and unit.name == unit.path:
            where = ""  # a file or a one-file element: its name is its path
        numbers = ", ".join(f"{f} = {unit.values[f]}" for f in self.threshold.fields)
        return f"gate failed: {self.threshold.text}: {where}{unit.name} ({numbers})"

    @property
    def excess(self) -> float:
        """How far past its limit the unit lies: for the first condition of the first group
        that fails, (value − limit) / |limit| for ``>``/``>=`` and (limit − value) / |limit|
        for ``<``/``<=`` (|limit| at least 1); 0 for ``==``/``!=``. Worst first sorts by it."""
        for group in self.threshold.groups:
            if all(c.holds(self.unit.values) for c in group):
                first = group[0]
                return past_limit(first.op, float(self.unit.values[first.field]), first.limit)
        return 0.0


def past_limit(op: str, value: float, limit: float) -> float:
    """How far ``value`` lies past ``limit`` in the direction ``op`` fails, relative to the
    limit (at least 1 in magnitude): what orders offenders worst first."""
    scale = max(abs(limit), 1.0)
    if op in (">", ">="):
        return (value - limit) / scale
    if op in ("<", "<="):
        return (limit - value) / scale
    return 0.0


def worst_first(failures: Iterable[ThresholdFailure]) -> tuple[ThresholdFailure, ...]:
    """``failures`` with the furthest past its limit first (:attr:`ThresholdFailure.excess`),
    ties by file, line and name: what every report lists first, so no cap hides the worst."""
    return tuple(
        sorted(
            failures,
            key=lambda f: (-f.excess, f.unit.path or "", f.unit.line or 0, f.unit.name),
        )
    )


class Checked(NamedTuple):
    """What checking thresholds found: the units that fail, and those that would have
    failed but a suppression comment exempts or the baseline already knows (listed, never
    hidden)."""

    failures: tuple[ThresholdFailure, ...] = ()
    suppressed: tuple[ThresholdFailure, ...] = ()
    baselined: tuple[ThresholdFailure, ...] = ()


class Known(Protocol):
    """A baseline: which of a threshold's failures it already knows (complexity/baseline.py)."""

    def known(self, failures: Sequence[ThresholdFailure]) -> frozenset[int]: ...


def check_units(
    thresholds: Iterable[Threshold],
    units: Mapping[str, Sequence[Unit]],
    baseline: Known | None = None,
) -> Checked:
    """:func:`check_thresholds`, then set apart the failures a suppression comment exempts
    (every field the threshold reads) and, of the rest, those ``baseline`` knows."""
    failures = check_thresholds(thresholds, units)
    suppressed = tuple(f for f in failures if f.unit.exempt(f.threshold.fields))
    left = [f for f in failures if not f.unit.exempt(f.threshold.fields)]
    known = baseline.known(left) if baseline is not None else frozenset()
    return Checked(
        tuple(f for i, f in enumerate(left) if i not in known),
        suppressed,
        tuple(f for i, f in enumerate(left) if i in known),
    )


def check_thresholds(
    thresholds: Iterable[Threshold], units: Mapping[str, Sequence[Unit]]
) -> tuple[ThresholdFailure, ...]:
    """Every unit that fails a threshold, threshold by threshold, each threshold's units
    worst first (:func:`worst_first`; ``units``: the units of each kind)."""
    return tuple(
        failure
        for threshold in thresholds
        for failure in worst_first(
            ThresholdFailure(threshold, unit)
            for unit in units.get(threshold.unit, ())
            if threshold.fails(unit.values)
        )
    )
