"""The outline of a C/C++ file: its classes, its includes, and what could not be parsed."""

from __future__ import annotations

from tree_sitter import Node

from archmetrics.facts import Class, Dependency, DependencyKind, ParseWarning
from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_names import Scopes, in_order, span, text
from archmetrics.parsers.c_family_text import string_value

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


def warnings(path: str, found: dict[str, list[Node]], data: bytes) -> tuple[ParseWarning, ...]:
    """One warning per unparsed region (outermost ERROR) and per token the parser had to invent."""
    problems: list[tuple[int, str]] = []
    last_end = -1
    for node in in_order(found.get("error", [])):
        if node.start_byte < last_end:
            continue
        last_end = node.end_byte
        snippet = text(node, data)[:40].decode("utf-8", "replace").split("\n")[0]
        problems.append(
            (
                node.start_point.row + 1,
                f"could not parse {snippet!r} (a macro?); lines here may be under-counted",
            )
        )
    expected = {node.id for node in found.get("expected", [])}
    for node in found.get("missing", []):
        if node.id in expected:
            continue  # tree-sitter-cpp wants a declarator in `template class Box<int>;`
        problems.append((node.start_point.row + 1, f"missing {node.type!r} assumed by the parser"))
    problems.sort()
    found_warnings = [
        ParseWarning(path, line, message) for line, message in problems[:_MAX_WARNINGS]
    ]
    if len(problems) > _MAX_WARNINGS:
        more = len(problems) - _MAX_WARNINGS
        found_warnings.append(ParseWarning(path, problems[_MAX_WARNINGS][0], f"... {more} more"))
    return tuple(found_warnings)
