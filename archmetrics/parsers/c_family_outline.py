"""The outline of a C/C++ file: its classes, its includes, and what could not be parsed."""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field

from tree_sitter import Node

from archmetrics.facts import Class, Dependency, DependencyKind, ParseWarning
from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_names import Scopes, in_order, span, text
from archmetrics.parsers.c_family_text import string_value, whole_lines

_MAX_WARNINGS = 20


def classes(nodes: list[Node], scopes: Scopes) -> tuple[Class, ...]:
    """Structs, classes and unions with a body; anonymous ones only under a typedef name."""
    classes: list[Class] = []
    ordered = in_order(nodes)
    prefixes = scopes.prefixes(ordered)
    for node in ordered:
        name = scopes.class_names[node.id]
        if name is None:
            continue
        prefix = prefixes[node.id]
        qualified = f"{prefix}::{name}" if prefix else name
        classes.append(Class(name, qualified, span(node), c_tables.CLASSES[node.type]))
    return tuple(classes)


def includes(nodes: list[Node], data: bytes) -> tuple[Dependency, ...]:
    """Each `#include "x.h"` / `#include <x.h>`; computed includes (`#include FOO`) are skipped."""
    found: list[Dependency] = []
    for node in nodes:
        if node.type != "preproc_include":
            continue
        target = node.child_by_field_name("path")
        if target is None:
            continue
        written = text(target, data)
        if target.type == "system_lib_string":
            name = written.decode("utf-8", "replace").strip("<>").strip()
            found.append(Dependency(name, DependencyKind.INCLUDE_SYSTEM, span(node)))
        elif target.type == "string_literal":
            value = string_value(written)
            if value is not None:
                found.append(Dependency(value, DependencyKind.INCLUDE, span(node)))
    return tuple(found)


_DECISION_TOKENS = re.compile(rb"\b(?:if|for|while|case|catch)\b|&&|\|\||\?")
_CALL_TOKENS = re.compile(
    rb"\b(?!(?:if|for|while|switch|return|sizeof|catch|alignof|decltype|defined)\b)"
    rb"[A-Za-z_]\w*+\s*+\("
)


@dataclass(frozen=True, slots=True)
class Counted:
    """The first lines of what the facts counted, sorted: decisions, statements, calls."""

    decisions: list[int] = field(default_factory=list)
    statements: list[int] = field(default_factory=list)
    calls: list[int] = field(default_factory=list)


def warnings(
    path: str,
    found: dict[str, list[Node]],
    data: bytes,
    clean: bytes | None = None,
    counted: Counted | None = None,
) -> tuple[ParseWarning, ...]:
    """One warning per region tree-sitter could not read (``ERROR`` nodes and tokens it had
    to invent, joined by line) where facts were lost there: the decision tokens, statement
    ends (``;``) and calls the region's text (``clean``: comments blanked) holds beyond
    those the facts ``counted`` on its lines. A region that lost nothing is not reported."""
    clean = data if clean is None else clean
    counted = counted or Counted()
    expected = {node.id for node in found.get("expected", [])}
    spots = [(n.start_byte, n.end_byte) for n in found.get("error", [])] + [
        (n.start_byte, n.end_byte) for n in found.get("missing", []) if n.id not in expected
    ]  # (tree-sitter-cpp wants a declarator in `template class Box<int>;`: expected)
    regions: list[tuple[int, int]] = []
    for start, end in sorted(spots):
        start, end = whole_lines(data, start, end)
        if regions and start <= regions[-1][1] + 1:
            regions[-1] = (regions[-1][0], max(end, regions[-1][1]))
        else:
            regions.append((start, end))
    if not regions:
        return ()
    problems: list[tuple[int, str]] = []
    for start, end in regions:
        part = clean[start:end]
        first = data.count(b"\n", 0, start) + 1
        last = first + part.count(b"\n")
        lost = {
            "decisions": len(_DECISION_TOKENS.findall(part))
            - _between(counted.decisions, first, last),
            "statements": part.count(b";") - _between(counted.statements, first, last),
            "call sites": len(_CALL_TOKENS.findall(part)) - _between(counted.calls, first, last),
        }
        shown = [
            f"{count} {what if count > 1 else what[:-1]}"
            for what, count in lost.items()
            if count > 0
        ]
        if not shown:
            continue
        lines = f"line {first}" if first == last else f"lines {first}-{last}"
        code = start + len(part) - len(part.lstrip())  # the first byte that is not a comment
        snippet = data[code : min(end, code + 40)].decode("utf-8", "replace").split("\n")[0]
        problems.append(
            (
                first,
                f"{lines} could not be parsed ({snippet!r}: a macro or an #if?); not counted"
                f" there: about {', '.join(shown)}",
            )
        )
    found_warnings = [
        ParseWarning(path, line, message) for line, message in problems[:_MAX_WARNINGS]
    ]
    if len(problems) > _MAX_WARNINGS:
        more = len(problems) - _MAX_WARNINGS
        found_warnings.append(
            ParseWarning(path, problems[_MAX_WARNINGS][0], f"... {more} more regions not parsed")
        )
    return tuple(found_warnings)


def _between(lines: list[int], first: int, last: int) -> int:
    return bisect.bisect_right(lines, last) - bisect.bisect_left(lines, first)
