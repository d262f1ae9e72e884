"""Read an integration plan from TOML text into frozen values, checking every key (pure).

The plan is untrusted input: its size and every count and list are bounded, unknown keys
are refused, and each problem is a :class:`PlanError` naming the plan's file and the key,
e.g. ``plan.toml: architecture.soa.element[2].statements_added: must be an integer >= 0``.
The JSON Schema archmetrics/schemas/plan-1.schema.json describes the same document; this
reader is the spec and tests/changeset/test_plan_read.py checks the schema against it.
"""

from __future__ import annotations

import re
import tomllib
from collections.abc import Callable, Mapping
from typing import TypeVar

from archmetrics.changeset.locations import Location
from archmetrics.changeset.plan import (
    PLAN_SCHEMA,
    Architecture,
    Plan,
    PlanError,
    PlannedElement,
    PlannedLink,
    PlannedStage,
    Sketch,
    SketchKind,
)

MAX_PLAN_BYTES = 1_000_000
MAX_ARCHITECTURES = 32
MAX_STAGES = 16
MAX_ELEMENTS = 5_000  # per stage
MAX_ITEMS = 1_000  # static dependencies or dynamic links of one element
MAX_COUNT = 10_000_000  # any one planned count
MAX_TEXT = 512  # characters of any name, rule, path or label
_NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,63}")
_COUNTS = {
    "statements_added": "added",
    "statements_removed": "removed",
    "statements_modified": "modified",
    "decisions_added": "decisions_added",
    "decisions_removed": "decisions_removed",
    "functions_added": "functions_added",
    "functions_removed": "functions_removed",
}
_ELEMENT_KEYS = {"name", "new", "location", "static_dependencies", "dynamic_links", *_COUNTS}
_T = TypeVar("_T")


class _Reader:
    """Checks values at a key path of the plan, failing with the plan's file and the key."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, key: str, problem: str) -> PlanError:
        return PlanError(self.source, key, problem)

    def table(self, value: object, key: str, allowed: set[str]) -> Mapping[str, object]:
        if not isinstance(value, dict):
            raise self.fail(key, "must be a table")
        for name in value:
            if name not in allowed:
                known = ", ".join(sorted(allowed))
                raise self.fail(_join(key, name), f"unknown key (known: {known})")
        return value

    def text(self, value: object, key: str) -> str:
        if not isinstance(value, str) or not value.strip():
            raise self.fail(key, "must be a non-empty string")
        if len(value) > MAX_TEXT or any(ord(c) < 32 or ord(c) == 127 for c in value):
            raise self.fail(key, f"must be at most {MAX_TEXT} printable characters")
        return value

    def count(self, value: object, key: str) -> int:
        if type(value) is not int or not 0 <= value <= MAX_COUNT:
            raise self.fail(key, f"must be an integer >= 0 and <= {MAX_COUNT} (got {value!r})")
        return value

    def items(
        self, value: object, key: str, limit: int, read: Callable[[object, str], _T]
    ) -> tuple[_T, ...]:
        if not isinstance(value, list):
            raise self.fail(key, "must be an array")
        if len(value) > limit:
            raise self.fail(key, f"at most {limit} entries (got {len(value)})")
        return tuple(read(item, f"{key}[{i}]") for i, item in enumerate(value))


def _join(key: str, name: str) -> str:
    return f"{key}.{name}" if key else name


def read_plan(data: bytes, source: str) -> Plan:
    """The plan in ``data`` (TOML), read from ``source`` (named in every error)."""
    reader = _Reader(source)
    if len(data) > MAX_PLAN_BYTES:
        raise reader.fail("", f"a plan may hold at most {MAX_PLAN_BYTES} bytes")
    try:
        document = tomllib.loads(data.decode("utf-8"))
    except UnicodeDecodeError as error:
        raise reader.fail("", f"not UTF-8 text ({error.reason} at byte {error.start})") from None
    except tomllib.TOMLDecodeError as error:
        raise reader.fail("", f"not valid TOML ({error})") from None
    top = reader.table(document, "", {"schema", "title", "architecture"})
    if "schema" in top and top["schema"] != PLAN_SCHEMA:
        raise reader.fail("schema", f"must be {PLAN_SCHEMA!r} (got {top['schema']!r})")
    title = reader.text(top["title"], "title") if "title" in top else ""
    if "architecture" not in top:
        raise reader.fail("architecture", "missing: a plan needs at least one architecture")
    architectures = top["architecture"]
    if not isinstance(architectures, dict) or not architectures:
        raise reader.fail(
            "architecture", "must be a table of architectures, e.g. [architecture.soa]"
        )
    if len(architectures) > MAX_ARCHITECTURES:
        raise reader.fail("architecture", f"at most {MAX_ARCHITECTURES} architectures")
    return Plan(
        source,
        tuple(_architecture(reader, name, value) for name, value in architectures.items()),
        title,
    )


def _architecture(reader: _Reader, name: str, value: object) -> Architecture:
    key = f"architecture.{name}"
    if not _NAME.fullmatch(name):
        raise reader.fail(key, "an architecture's name is 1-64 letters, digits, '.', '_', '-'")
    table = reader.table(value, key, {"base", "description", "element", "sketch", "stage"})
    base = reader.text(table["base"], f"{key}.base") if "base" in table else None
    description = (
        reader.text(table["description"], f"{key}.description") if "description" in table else ""
    )
    given = [k for k in ("element", "sketch", "stage") if k in table]
    if len(given) != 1:
        raise reader.fail(key, "needs exactly one of element, sketch or stage")
    if "stage" in table:
        stages = reader.items(
            table["stage"], f"{key}.stage", MAX_STAGES, lambda v, k: _stage(reader, v, k)
        )
        if not stages:
            raise reader.fail(f"{key}.stage", "needs at least one stage")
        labels: set[str] = set()
        for stage in stages:
            if stage.label in labels:
                raise reader.fail(f"{stage.key}.label", f"stage {stage.label!r} given twice")
            labels.add(stage.label)
    else:
        stages = (_stage_body(reader, table, key, "estimate"),)
    return Architecture(name, key, stages, description, base)


def _stage(reader: _Reader, value: object, key: str) -> PlannedStage:
    table = reader.table(value, key, {"label", "element", "sketch"})
    if "label" not in table:
        raise reader.fail(f"{key}.label", "missing: every stage needs a label (e.g. 'first')")
    label = reader.text(table["label"], f"{key}.label")
    if len([k for k in ("element", "sketch") if k in table]) != 1:
        raise reader.fail(key, "needs exactly one of element or sketch")
    return _stage_body(reader, table, key, label)


def _stage_body(reader: _Reader, table: Mapping[str, object], key: str, label: str) -> PlannedStage:
    if "sketch" in table:
        return PlannedStage(label, key, sketch=_sketch(reader, table["sketch"], f"{key}.sketch"))
    elements = reader.items(
        table["element"], f"{key}.element", MAX_ELEMENTS, lambda v, k: _element(reader, v, k)
    )
    seen: dict[str, str] = {}
    for element in elements:
        if element.name in seen:
            raise reader.fail(
                f"{element.key}.name", f"element {element.name!r} is also {seen[element.name]}"
            )
        seen[element.name] = element.key
    return PlannedStage(label, key, elements=elements)


def _sketch(reader: _Reader, value: object, key: str) -> Sketch:
    kinds = {k.value for k in SketchKind}
    table = reader.table(value, key, kinds)
    if len(table) != 1:
        raise reader.fail(key, "needs exactly one of revision, patch or stubs")
    ((kind, text),) = table.items()
    return Sketch(SketchKind(kind), reader.text(text, f"{key}.{kind}"), f"{key}.{kind}")


def _element(reader: _Reader, value: object, key: str) -> PlannedElement:
    table = reader.table(value, key, _ELEMENT_KEYS)
    if "name" not in table:
        raise reader.fail(f"{key}.name", "missing: every element needs a name")
    new = table.get("new", False)
    if not isinstance(new, bool):
        raise reader.fail(f"{key}.new", "must be true or false")
    location = None
    if "location" in table:
        try:
            location = Location(table["location"])  # type: ignore[arg-type]
        except ValueError:
            known = ", ".join(loc.value for loc in Location)
            raise reader.fail(
                f"{key}.location", f"unknown location {table['location']!r} (known: {known})"
            ) from None
    counts = {field: reader.count(table.get(k, 0), f"{key}.{k}") for k, field in _COUNTS.items()}
    return PlannedElement(
        name=reader.text(table["name"], f"{key}.name"),
        key=key,
        new=new,
        location=location,
        static_dependencies=reader.items(
            table.get("static_dependencies", []),
            f"{key}.static_dependencies",
            MAX_ITEMS,
            reader.text,
        ),
        dynamic_links=reader.items(
            table.get("dynamic_links", []),
            f"{key}.dynamic_links",
            MAX_ITEMS,
            lambda v, k: _link(reader, v, k),
        ),
        **counts,
    )


def _link(reader: _Reader, value: object, key: str) -> PlannedLink:
    table = reader.table(value, key, {"rule", "count", "to"})
    if "rule" not in table:
        raise reader.fail(f"{key}.rule", "missing: a dynamic link names its rule (e.g. 'send')")
    count = reader.count(table.get("count", 1), f"{key}.count")
    to = reader.text(table["to"], f"{key}.to") if "to" in table else None
    return PlannedLink(reader.text(table["rule"], f"{key}.rule"), count, to, key)
