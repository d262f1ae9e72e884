"""Validating a pack's ``[[scopes]]`` (what names resolve against) and ``[[values]]`` (calls
whose value is known statically). Every key is checked up front; errors name the file, the
rule and the key, as for ``[[rules]]``."""

from __future__ import annotations

from archmetrics.coupling.rules import KNOWN_LANGUAGES, ScopeRule, ValueRule
from archmetrics.coupling.validate_where import Where, check_glob, list_of, parse_place, rule_header

_COMMON = frozenset({"id", "language", "match", "requires", "description"})
_SCOPE_KEYS = _COMMON | {"kind", "name", "namespace"}
_VALUE_KEYS = _COMMON | {"value", "name", "out"}
SCOPE_KINDS = frozenset({"node", "handle"})


def _head(
    raw: object, source: str, unnamed: str, keys: frozenset[str]
) -> tuple[Where, dict[str, object], str, tuple[str, ...], tuple[str, ...], tuple[str, ...]]:
    where, table, ident = rule_header(raw, source, unnamed, keys)
    languages = where.texts(table, "language", required=True)
    for language in languages:
        if language not in KNOWN_LANGUAGES:
            where.fail("language", f"{language!r} is not one of {list_of(KNOWN_LANGUAGES)}")
    match = where.texts(table, "match", required=True)
    for pattern in match:
        check_glob(where, "match", pattern)
    requires = where.texts(table, "requires", required=False)
    return where, dict(table), ident, languages, match, requires


def _array(raw: object, key: str, source: str) -> list[object]:
    if not isinstance(raw, list):
        Where(source).fail(key, f"must be an array of tables ([[{key}]])")
    return raw


def parse_scopes(raw: object, pack: str, source: str) -> tuple[ScopeRule, ...]:
    """The ``[[scopes]]`` array of a pack (absent: none)."""
    found = []
    for index, item in enumerate(_array(raw, "scopes", source)):
        where, table, ident, languages, match, requires = _head(
            item, source, f"scopes #{index + 1}", _SCOPE_KEYS
        )
        name, namespace = table.get("name"), table.get("namespace")
        if name is None and namespace is None:
            where.fail("name", "a scope needs a name or a namespace")
        found.append(
            ScopeRule(
                pack=pack,
                id=ident,
                languages=languages,
                match=match,
                kind=where.choice(table, "kind", SCOPE_KINDS),
                name=None if name is None else parse_place(where, name, "name"),
                namespace=None if namespace is None else parse_place(where, namespace, "namespace"),
                requires=requires,
                description=where.text(table, "description", ""),
            )
        )
    return tuple(found)


def parse_values(raw: object, pack: str, source: str) -> tuple[ValueRule, ...]:
    """The ``[[values]]`` array of a pack (absent: none)."""
    found = []
    for index, item in enumerate(_array(raw, "values", source)):
        where, table, ident, languages, match, requires = _head(
            item, source, f"values #{index + 1}", _VALUE_KEYS
        )
        value, name = table.get("value"), table.get("name")
        out = where.integer(table, "out")
        if out is not None and out < 0:
            where.fail("out", "argument index must be >= 0")
        if value is None and name is None:
            where.fail("value", "a value rule needs a value or a name")
        found.append(
            ValueRule(
                pack=pack,
                id=ident,
                languages=languages,
                match=match,
                value=None if value is None else parse_place(where, value, "value"),
                name=None if name is None else parse_place(where, name, "name"),
                out=out,
                requires=requires,
                description=where.text(table, "description", ""),
            )
        )
    return tuple(found)
