"""Validating a pack's ``[[configuration]]`` rules: which files are configuration, which of
their tables are links. Every key is checked up front; errors name the file, rule and key."""

from __future__ import annotations

import re
from collections.abc import Mapping

from archmetrics.coupling.patterns import PatternError, compile_pattern
from archmetrics.coupling.rules import (
    ENDPOINT_TYPES,
    INTERPRETERS,
    ConfigEndpoint,
    ConfigRule,
    LinkKind,
    Role,
    RulePackError,
)
from archmetrics.coupling.validate_where import Where, rule_header
from archmetrics.facts import ConfigFormat

_KEYS = frozenset(
    {"id", "files", "format", "table", "when", "defaults", "kind", "role", "endpoint",
     "description", "example", "example_endpoint", "interpret", "within"}
)  # fmt: skip
_ENDPOINT_KEYS = frozenset({"type", "key", "pattern"})
_FORMATS = frozenset(str(f) for f in ConfigFormat)
_TABLE = re.compile(r"^[A-Za-z0-9_-]+(?:\.[A-Za-z0-9_-]+)*$")


def parse_configuration(raw: object, pack: str, source: str) -> tuple[ConfigRule, ...]:
    """The ``[[configuration]]`` array of a pack (absent: none)."""
    if not isinstance(raw, list):
        Where(source).fail("configuration", "must be an array of tables ([[configuration]])")
    return tuple(_rule(item, pack, source, index) for index, item in enumerate(raw))


def _rule(raw: object, pack: str, source: str, index: int) -> ConfigRule:
    where, table, ident = rule_header(raw, source, f"configuration #{index + 1}", _KEYS)
    files = where.texts(table, "files", required=True)
    for glob in files:
        if glob.startswith("!") or not glob.strip("/"):
            where.fail("files", f"{glob!r}: a glob may not be empty, '/' or a '!' negation")
    interpret = table.get("interpret")
    if interpret is not None and interpret not in INTERPRETERS:
        where.fail("interpret", f"{interpret!r} is not one of {', '.join(sorted(INTERPRETERS))}")
    selector = where.text(table, "table", "" if interpret else None)
    if selector and not _TABLE.match(selector):
        where.fail("table", f"{selector!r} must be bare keys joined by dots (rules.to)")
    example_endpoint = table.get("example_endpoint")
    if example_endpoint is not None and not isinstance(example_endpoint, str):
        where.fail("example_endpoint", "must be a string")
    return ConfigRule(
        pack=pack,
        id=ident,
        files=files,
        format=where.choice(table, "format", _FORMATS),
        table=tuple(selector.split(".")) if selector else (),
        kind=LinkKind(where.choice(table, "kind", frozenset(LinkKind))),
        role=Role(where.choice(table, "role", frozenset(Role))),
        endpoint=_endpoint(where, table.get("endpoint"), bool(interpret)),
        when=_when(where, table.get("when", {})),
        defaults=_defaults(where, table.get("defaults", {})),
        description=where.text(table, "description", ""),
        example=where.text(table, "example", ""),
        example_endpoint=example_endpoint,
        interpret=interpret if isinstance(interpret, str) else None,
        within=_within(where, table.get("within")),
    )


def _within(where: Where, raw: object) -> str | None:
    """``within = "package.xml"``: a file name (no folder, no glob)."""
    if raw is None:
        return None
    if not isinstance(raw, str) or not raw or any(c in raw for c in "/*?[\\"):
        where.fail("within", "must be a file name, as package.xml")
    return raw


def _endpoint(where: Where, raw: object, interpreted: bool) -> ConfigEndpoint:
    table = where.table(raw, "endpoint", _ENDPOINT_KEYS)
    try:
        kind = where.choice(table, "type", ENDPOINT_TYPES)
        key = where.text(table, "key", "" if interpreted else None)
        pattern = where.text(table, "pattern", "") or None
    except RulePackError as error:
        key = f"endpoint.{error.key}"
        raise RulePackError(error.source, error.rule, key, error.problem) from None
    if pattern is not None:
        try:
            compile_pattern(pattern)
        except PatternError as error:
            where.fail("endpoint.pattern", f"bad regular expression: {error}")
    return ConfigEndpoint(kind, key, pattern)


def _when(where: Where, raw: object) -> tuple[tuple[str, tuple[str, ...]], ...]:
    """``when = { kind = ["send", "request"] }``: each key's allowed values."""
    if not isinstance(raw, Mapping):
        where.fail("when", f"must be a table, got {type(raw).__name__}")
    found = []
    for key in raw:
        try:
            found.append((str(key), where.texts(raw, key, required=True)))
        except RulePackError as error:
            raise RulePackError(error.source, error.rule, f"when.{key}", error.problem) from None
    return tuple(found)


def _defaults(where: Where, raw: object) -> tuple[tuple[str, str], ...]:
    """``defaults = { kind = "request" }``: what the configuration's reader assumes for a key
    a table leaves out."""
    if not isinstance(raw, Mapping):
        where.fail("defaults", f"must be a table, got {type(raw).__name__}")
    for key, value in raw.items():
        if not isinstance(value, str):
            where.fail(f"defaults.{key}", "must be a string")
    return tuple((str(k), str(v)) for k, v in raw.items())
