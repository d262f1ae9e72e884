"""The outline of a C/C++ file: its classes and its includes."""

from __future__ import annotations

from tree_sitter import Node

from archmetrics.facts import Class, Dependency, DependencyKind
from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_names import Scopes, in_order, span, text
from archmetrics.parsers.c_family_text import string_value


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
