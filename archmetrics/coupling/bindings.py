"""Names a Python file binds to modules by importing them (``import a.b as c`` binds ``c``).

A call through such a name (``su.request(...)`` after ``from proxy import service_utilities
as su``) is a static call of a module function, not a method of a run-time object, so rules
with ``*.name`` patterns do not match it; a rule naming the module (``robosoa.connect``) does.
"""

from __future__ import annotations

from collections.abc import Iterable

from archmetrics.coupling.imports import dotted
from archmetrics.facts import Dependency


def module_bindings(dependencies: Iterable[Dependency], modules: Iterable[str]) -> frozenset[str]:
    """Local names bound to modules: every ``import`` name, and ``from`` names in ``modules``.

    ``modules`` are the dotted names (as written, relative ones with their dots) this file's
    ``from X import Y`` statements resolved to as submodules.
    """
    known = set(modules)
    bound: set[str] = set()
    for dependency in dependencies:
        if not dependency.names:  # import a.b [as c]
            bound.update(dependency.bound)
            continue
        origin = "." * dependency.level + dependency.target
        for name, local in zip(dependency.names, dependency.bound, strict=False):
            if dotted(origin, name) in known:
                bound.add(local)
    return frozenset(bound)
