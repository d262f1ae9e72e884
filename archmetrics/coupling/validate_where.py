"""Where a rule-pack error is: the pack's source and the rule, and the checked reads every
table of a pack goes through (rules, configuration links)."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import NoReturn

from archmetrics.coupling.matching import normalize_callee
from archmetrics.coupling.rules import Place, RulePackError
from archmetrics.globs import BadPattern, compile_glob

ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")


@dataclass(frozen=True, slots=True)
class Where:
    source: str
    rule: str | None = None

    def fail(self, key: str | None, problem: str) -> NoReturn:
        raise RulePackError(self.source, self.rule, key, problem)

    def table(self, value: object, key: str, allowed: frozenset[str]) -> Mapping[str, object]:
        if not isinstance(value, Mapping):
            self.fail(key, f"must be a table, got {type(value).__name__}")
        for name in value:
            if name not in allowed:
                known = list_of(allowed)
                self.fail(f"{key}.{name}" if key else name, f"unknown key (known: {known})")
        return value

    def text(self, table: Mapping[str, object], key: str, default: str | None = None) -> str:
        value = table.get(key, default)
        if not isinstance(value, str) or (default is None and not value):
            self.fail(key, "required non-empty string" if value is None else "must be a string")
        return value

    def texts(self, table: Mapping[str, object], key: str, required: bool) -> tuple[str, ...]:
        value = table.get(key, [] if not required else None)
        items = [value] if isinstance(value, str) else value
        if not isinstance(items, list) or not all(isinstance(i, str) and i for i in items):
            self.fail(key, "must be a string or a list of non-empty strings")
        if required and not items:
            self.fail(key, "must not be empty")
        return tuple(str(i) for i in items)

    def integer(self, table: Mapping[str, object], key: str) -> int | None:
        value = table.get(key)
        if key == "arg" and isinstance(value, list) and value:  # [1, 4]: 1, else 4
            value = value[0]
        if value is not None and (not isinstance(value, int) or isinstance(value, bool)):
            self.fail(key, f"must be an integer, got {value!r}")
        if isinstance(value, int) and key == "arg" and value < 0:
            self.fail(key, "argument index must be >= 0")
        return value

    def choice(self, table: Mapping[str, object], key: str, allowed: frozenset[str],
               default: str | None = None) -> str:  # fmt: skip
        value = self.text(table, key, default)
        if value not in allowed:
            self.fail(key, f"{value!r} is not one of {list_of(allowed)}")
        return value


def list_of(values: frozenset[str]) -> str:
    return ", ".join(sorted(values))


def rule_header(
    raw: object, source: str, unnamed: str, keys: frozenset[str]
) -> tuple[Where, Mapping[str, object], str]:
    """A rule's table read with these ``keys``, the place errors name (the rule's id, or
    ``unnamed`` when it has none) and its id, checked."""
    rule_id = raw.get("id") if isinstance(raw, Mapping) else None
    where = Where(source, rule_id if isinstance(rule_id, str) else unnamed)
    table = where.table(raw, "", keys)
    ident = where.text(table, "id")
    if not ID.match(ident):
        where.fail("id", f"{ident!r} must be letters, digits and _.+-")
    return where, table, ident


_PLACE_KEYS = frozenset({"template", "arg", "keyword", "value", "callback"})


def check_glob(where: Where, key: str, pattern: str) -> None:
    """A ``match`` pattern: a dotted callee name with globs of the one dialect (globs.py)."""
    if any(c.isspace() for c in pattern) or "(" in pattern or "/" in pattern:
        where.fail(key, f"{pattern!r}: a pattern is a dotted callee name with * globs")
    try:
        compile_glob(normalize_callee(pattern))
    except BadPattern as error:
        where.fail(key, str(error))


def parse_place(where: Where, raw: object, key: str) -> Place:
    """``{ template = 0 }``, ``{ arg = 1, keyword = "name" }`` or ``{ value = "~" }``."""
    table = where.table(raw, key, _PLACE_KEYS)
    try:
        place = Place(
            template=where.integer(table, "template"),
            arg=where.integer(table, "arg"),
            keyword=where.text(table, "keyword", "") or None,
            value=where.text(table, "value", "") or None,
            callback=where.integer(table, "callback"),
        )
    except RulePackError as error:
        raise RulePackError(error.source, error.rule, f"{key}.{error.key}", error.problem) from None
    if place == Place():
        where.fail(key, "says nowhere: give template, arg, keyword or value")
    if place.template is not None and place.template < 0:
        where.fail(f"{key}.template", "template argument index must be >= 0")
    if place.callback is not None and place.callback < 0:
        where.fail(f"{key}.callback", "argument index must be >= 0")
    return place
