"""Validating a decoded rule pack: every key checked up front, errors name file, rule and key."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import NoReturn

from archmetrics.coupling.matching import normalize_callee
from archmetrics.coupling.patterns import PatternError, compile_pattern
from archmetrics.coupling.rules import (
    ENDPOINT_TYPES,
    KNOWN_LANGUAGES,
    NAMINGS,
    EndpointSource,
    EndpointSpec,
    FunctionHint,
    LinkKind,
    Place,
    Role,
    Rule,
    RulePack,
    RulePackError,
    SiteKind,
)
from archmetrics.globs import BadPattern, compile_glob

_PACK_KEYS = frozenset({"name", "description"})
_RULE_KEYS = frozenset(
    {"id", "language", "match", "kind", "role", "site", "requires", "priority", "endpoint",
     "description", "example", "example_endpoint", "unless_from"}
)  # fmt: skip
_ENDPOINT_KEYS = frozenset(
    {"type", "arg", "keyword", "from", "pattern", "same_function", "same_file", "value",
     "created_by", "naming", "data_type", "created_only"}
)  # fmt: skip
_PLACE_KEYS = frozenset({"template", "arg", "keyword", "value", "callback"})
_HINT_KEYS = frozenset({"match", "arg", "keyword"})
_ID = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")


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
                known = _list(allowed)
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
            self.fail(key, f"{value!r} is not one of {_list(allowed)}")
        return value


def _list(values: frozenset[str]) -> str:
    return ", ".join(sorted(values))


def parse_pack(data: Mapping[str, object], source: str) -> RulePack:
    """Validate one decoded TOML document and build its :class:`RulePack`."""
    from archmetrics.coupling.validate_config import parse_configuration
    from archmetrics.coupling.validate_scopes import parse_scopes, parse_values

    top = Where(source)
    top.table(data, "", frozenset({"pack", "rules", "configuration", "scopes", "values"}))
    pack = top.table(data.get("pack"), "pack", _PACK_KEYS)
    name = top.text(pack, "name")
    if not _ID.match(name):
        top.fail("pack.name", f"{name!r} must be letters, digits and _.+-")
    raw_rules = data.get("rules", [])
    if not isinstance(raw_rules, list) or not (raw_rules or "configuration" in data):
        top.fail("rules", "a pack needs a non-empty [[rules]] or [[configuration]] array")
    rules = tuple(_parse_rule(raw, name, source, index) for index, raw in enumerate(raw_rules))
    configuration = parse_configuration(data.get("configuration", []), name, source)
    scopes = parse_scopes(data.get("scopes", []), name, source)
    values = parse_values(data.get("values", []), name, source)
    seen: set[str] = set()
    for ident in [r.id for group in (rules, configuration, scopes, values) for r in group]:
        if ident in seen:
            Where(source, ident).fail("id", "duplicate rule id in this pack")
        seen.add(ident)
    description = top.text(pack, "description", "")
    return RulePack(name, source, description, rules, configuration, "", scopes, values)


def rule_header(
    raw: object, source: str, unnamed: str, keys: frozenset[str]
) -> tuple[Where, Mapping[str, object], str]:
    """A rule's table read with these ``keys``, the place errors name (the rule's id, or
    ``unnamed`` when it has none) and its id, checked."""
    rule_id = raw.get("id") if isinstance(raw, Mapping) else None
    where = Where(source, rule_id if isinstance(rule_id, str) else unnamed)
    table = where.table(raw, "", keys)
    ident = where.text(table, "id")
    if not _ID.match(ident):
        where.fail("id", f"{ident!r} must be letters, digits and _.+-")
    return where, table, ident


def _parse_rule(raw: object, pack: str, source: str, index: int) -> Rule:
    where, table, ident = rule_header(raw, source, f"#{index + 1}", _RULE_KEYS)
    languages = where.texts(table, "language", required=True)
    for language in languages:
        if language not in KNOWN_LANGUAGES:
            where.fail("language", f"{language!r} is not one of {_list(KNOWN_LANGUAGES)}")
    endpoint = table.get("endpoint")
    example_endpoint = table.get("example_endpoint")
    if example_endpoint is not None and not isinstance(example_endpoint, str):
        where.fail("example_endpoint", "must be a string")
    return Rule(
        pack=pack,
        id=ident,
        languages=languages,
        match=_patterns(where, table),
        kind=LinkKind(where.choice(table, "kind", frozenset(LinkKind))),
        role=Role(where.choice(table, "role", frozenset(Role))),
        site=SiteKind(where.choice(table, "site", frozenset(SiteKind), SiteKind.CALL)),
        requires=where.texts(table, "requires", required=False),
        priority=where.integer(table, "priority") or 0,
        endpoint=None if endpoint is None else _parse_endpoint(where, endpoint),
        description=where.text(table, "description", ""),
        examples=_examples(where, table.get("example"), languages),
        example_endpoint=example_endpoint,
        unless_from=where.texts(table, "unless_from", required=False),
    )


def _examples(where: Where, raw: object, languages: tuple[str, ...]) -> tuple[tuple[str, str], ...]:
    """``example = "..."`` (in the rule's first language) or ``[rules.example]`` by language."""
    if raw is None:
        return ()
    if isinstance(raw, str):
        return ((languages[0], raw),)
    table = where.table(raw, "example", frozenset(languages))
    if not all(isinstance(text, str) for text in table.values()):
        where.fail("example", "examples must be strings")
    return tuple((language, str(text)) for language, text in table.items())


def _patterns(where: Where, table: Mapping[str, object]) -> tuple[str, ...]:
    patterns = where.texts(table, "match", required=True)
    for pattern in patterns:
        _check_glob(where, "match", pattern)
    return patterns


def _check_glob(where: Where, key: str, pattern: str) -> None:
    """A ``match`` pattern: a dotted callee name with globs of the one dialect (globs.py)."""
    if any(c.isspace() for c in pattern) or "(" in pattern or "/" in pattern:
        where.fail(key, f"{pattern!r}: a pattern is a dotted callee name with * globs")
    try:
        compile_glob(normalize_callee(pattern))
    except BadPattern as error:
        where.fail(key, str(error))


def _parse_endpoint(where: Where, raw: object) -> EndpointSpec:
    table = where.table(raw, "endpoint", _ENDPOINT_KEYS)
    try:
        spec = _endpoint_fields(where, table)
    except RulePackError as error:
        key = error.key or ""
        key = key if key.startswith("endpoint") else f"endpoint.{key}"
        raise RulePackError(error.source, error.rule, key, error.problem) from None
    if spec.source is EndpointSource.CALLEE and spec.pattern is None:
        where.fail("endpoint.pattern", "an endpoint taken from the callee needs a pattern")
    return spec


def _endpoint_fields(where: Where, table: Mapping[str, object]) -> EndpointSpec:
    pattern = table.get("pattern")
    if pattern is not None:
        if not isinstance(pattern, str):
            where.fail("pattern", "must be a string")
        try:
            compile_pattern(pattern)
        except PatternError as error:
            where.fail("pattern", f"bad regular expression: {error}")
    hints = table.get("same_function", [])
    if not isinstance(hints, list):
        where.fail("same_function", "must be an array of tables")
    source = where.choice(table, "from", frozenset(EndpointSource), EndpointSource.ARGUMENT)
    same_file = table.get("same_file", False)
    if not isinstance(same_file, bool):
        where.fail("same_file", "must be true or false")
    created_by = where.texts(table, "created_by", required=False)
    for match in created_by:
        _check_glob(where, "created_by", match)
    naming = table.get("naming")
    if naming is not None and naming not in NAMINGS:
        where.fail("naming", f"{naming!r} is not one of {_list(NAMINGS)}")
    data_type = table.get("data_type")
    raw_arg = table.get("arg")
    more_args: tuple[int, ...] = ()
    if isinstance(raw_arg, list):
        if not raw_arg or not all(isinstance(a, int) and not isinstance(a, bool) and a >= 0
                                  for a in raw_arg):  # fmt: skip
            where.fail("arg", "a list of argument indexes must hold integers >= 0")
        more_args = tuple(raw_arg[1:])
    created_only = table.get("created_only", False)
    if not isinstance(created_only, bool) or (created_only and not created_by):
        where.fail("created_only", "must be true or false, and true only with created_by")
    return EndpointSpec(
        type=where.choice(table, "type", ENDPOINT_TYPES),
        arg=where.integer(table, "arg"),
        keyword=where.text(table, "keyword", "") or None,
        source=EndpointSource(source),
        pattern=pattern,
        same_function=tuple(_parse_hint(where, hint) for hint in hints),
        same_file=same_file,
        value=where.texts(table, "value", required=False),
        created_by=created_by,
        naming=naming if isinstance(naming, str) else None,
        data_type=None if data_type is None else parse_place(where, data_type, "data_type"),
        created_only=created_only,
        more_args=more_args,
    )


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


def _parse_hint(where: Where, raw: object) -> FunctionHint:
    table = where.table(raw, "endpoint.same_function", _HINT_KEYS)
    try:
        match = where.text(table, "match")
        arg, keyword = where.integer(table, "arg"), where.text(table, "keyword", "") or None
    except RulePackError as error:
        key = f"endpoint.same_function.{error.key}"
        raise RulePackError(error.source, error.rule, key, error.problem) from None
    if arg is None and keyword is None:
        where.fail("endpoint.same_function", "a hint needs arg or keyword")
    _check_glob(where, "endpoint.same_function.match", match)
    return FunctionHint(match, arg, keyword)
