"""The rule table: data rows for ``archmetrics rules`` and the Markdown table in the docs."""

from __future__ import annotations

from dataclasses import dataclass

from archmetrics.coupling.rules import (
    ConfigRule,
    EndpointSource,
    EndpointSpec,
    Place,
    Rule,
    RulePack,
    RuleSet,
)
from archmetrics.markup import code_span, table_cell


@dataclass(frozen=True, slots=True)
class RuleRow:
    """One rule as a row of text cells."""

    pack: str
    rule: str
    language: str
    match: str
    kind: str
    role: str
    endpoint: str
    requires: str = ""
    priority: int = 0


def describe_endpoint(spec: EndpointSpec | None) -> str:
    """Where a rule reads its endpoint, in a few words (``service: arg 0 / service=``)."""
    if spec is None:
        return "-"
    if spec.source is EndpointSource.CALLEE:
        return f"{spec.type}: callee ~ {spec.pattern}"
    places = []
    if spec.arg is not None:
        more = "".join(f" or {index}" for index in spec.more_args)
        places.append(f"arg {spec.arg}{more}")
    if spec.keyword is not None:
        places.append(f"{spec.keyword}=")
    if spec.pattern is not None:
        places.append(f"~ {spec.pattern}")
    hints = ", ".join(
        f"{h.match}({f'arg {h.arg}' if h.arg is not None else f'{h.keyword}='})"
        for h in spec.same_function
    )
    if hints:
        places.append(f"{'else ' if places else ''}same function: {hints}")
    if spec.same_file:
        places.append(f"{'else ' if places else ''}same file")
    if spec.created_by:
        only = " only" if spec.created_only else ""
        places.append(f"{'else ' if places else ''}made by{only}: {', '.join(spec.created_by)}")
    if spec.value:
        places.append(f"{'else ' if places else ''}{', '.join(spec.value)}")
    if spec.naming:
        places.append(f"{spec.naming} name")
    if spec.data_type is not None:
        places.append(f"type {_place(spec.data_type)}")
    return f"{spec.type}: {' / '.join(places)}" if places else spec.type


def rule_row(rule: Rule) -> RuleRow:
    """A rule as text cells."""
    match = ", ".join(rule.match) + (" (definition)" if rule.site.value == "definition" else "")
    return RuleRow(
        pack=rule.pack,
        rule=rule.id,
        language=", ".join(rule.languages),
        match=match,
        kind=rule.kind.value,
        role=rule.role.value,
        endpoint=describe_endpoint(rule.endpoint),
        requires=", ".join(rule.requires),
        priority=rule.priority,
    )


def config_row(rule: ConfigRule) -> RuleRow:
    """A configuration rule as text cells: its format as the language, the files and the
    tables it reads as what it matches."""
    when = "; ".join(f"{key} = {' | '.join(values)}" for key, values in rule.when)
    defaults = ", ".join(f"{key} = {value}" for key, value in rule.defaults)
    match = f"{', '.join(rule.files)}: [{'.'.join(rule.table)}]"
    if rule.interpret:
        match = f"{', '.join(rule.files)}: read as {rule.interpret}"
    match += f" where {when}" if when else ""
    match += f" (default {defaults})" if defaults else ""
    match += f" (in a tree with {rule.within})" if rule.within else ""
    pattern = f" ~ {rule.endpoint.pattern}" if rule.endpoint.pattern else ""
    return RuleRow(
        pack=rule.pack,
        rule=rule.id,
        language=f"{rule.format} (configuration)",
        match=match,
        kind=rule.kind.value,
        role=rule.role.value,
        endpoint=f"{rule.endpoint.type}: key {rule.endpoint.key}{pattern}"
        if rule.endpoint.key
        else rule.endpoint.type,
    )


def rule_rows(rules: RuleSet) -> tuple[RuleRow, ...]:
    """Every rule in force, in load order, each pack's configuration rules after its code
    rules: the rows of ``archmetrics rules``."""
    return tuple(
        row
        for pack in rules.packs
        for row in (*map(rule_row, pack.rules), *map(config_row, pack.configuration))
    )


def _code(text: str) -> str:
    """A cell: the pack's text as a code span (packs come from the repository:
    archmetrics.markup), or ``-`` for none."""
    return table_cell(code_span(text)) if text not in ("", "-") else "-"


def rules_markdown(rules: RuleSet, heading: str = "###") -> str:
    """The rule packs as Markdown: one section per pack (``heading`` level), a row per rule."""
    lines: list[str] = []
    header = "| rule | language | match | kind | role | endpoint | requires |"
    for pack in rules.packs:
        description = code_span(pack.description)
        lines += [f"{heading} {code_span(pack.name)}", "", description, "", header,
                  "|---|---|---|---|---|---|---|"]  # fmt: skip
        for row in (*map(rule_row, pack.rules), *map(config_row, pack.configuration)):
            cells = (row.rule, row.language, row.match, row.kind, row.role, row.endpoint,
                     row.requires)  # fmt: skip
            lines.append("| " + " | ".join(_code(c) for c in cells) + " |")
        lines.append("")
        lines += _names_and_values(pack)
    return "\n".join(lines)


def _place(place: Place | None) -> str:
    if place is None:
        return "-"
    parts = [
        f"template {place.template}" if place.template is not None else "",
        f"arg {place.arg}" if place.arg is not None else "",
        f"{place.keyword}=" if place.keyword else "",
        f"{place.value!r}" if place.value is not None else "",
        f"else callback arg {place.callback}" if place.callback is not None else "",
    ]
    return " / ".join(p for p in parts if p)


def _names_and_values(pack: RulePack) -> list[str]:
    """A pack's ``[[scopes]]`` and ``[[values]]``, a line each (they find no sites)."""
    lines = [
        f"- scope {code_span(s.id)} ({s.kind}, {', '.join(s.languages)}): "
        f"{code_span(', '.join(s.match))}, name {_place(s.name)}, namespace {_place(s.namespace)}"
        for s in pack.scopes
    ]
    lines += [
        f"- value {code_span(v.id)} ({', '.join(v.languages)}): "
        f"{code_span(', '.join(v.match))}, value {_place(v.value)}, parameter {_place(v.name)}"
        + (f", written into arg {v.out}" if v.out is not None else "")
        for v in pack.values
    ]
    return [*lines, ""] if lines else []
