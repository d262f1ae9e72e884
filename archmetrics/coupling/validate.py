"""Validating a decoded rule pack: every key checked up front, errors name file, rule and key."""

from __future__ import annotations

from collections.abc import Mapping

from archmetrics.coupling.patterns import PatternError, compile_pattern
from archmetrics.coupling.rules import (
    ENDPOINT_TYPES,
    KNOWN_LANGUAGES,
    NAMINGS,
    EndpointSource,
    EndpointSpec,
    FunctionHint,
    LinkKind,
    Role,
    Rule,
    RulePack,
    RulePackError,
    SiteKind,
)
from archmetrics.coupling.validate_where import ID as _ID
from archmetrics.coupling.validate_where import Where, check_glob, parse_place, rule_header
from archmetrics.coupling.validate_where import list_of as _list

_PACK_KEYS = frozenset({"name", "description"})
_RULE_KEYS = frozenset(
    {"id", "language", "match", "kind", "role", "site", "requires", "priority", "endpoint",
     "description", "example", "example_endpoint", "unless_from"}
)  # fmt: skip
_ENDPOINT_KEYS = frozenset(
    {"type", "arg", "keyword", "from", "pattern", "same_function", "same_file", "value",
     "created_by", "naming", "data_type", "created_only"}
)  # fmt: skip
_HINT_KEYS = frozenset({"match", "arg", "keyword"})


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
        check_glob(where, "match", pattern)
    return patterns


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
        check_glob(where, "created_by", match)
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
    check_glob(where, "endpoint.same_function.match", match)
    return FunctionHint(match, arg, keyword)
