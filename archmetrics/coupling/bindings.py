"""Names a Python file binds to modules by importing them (``import a.b as c`` binds ``c``).

A call through such a name (``su.request(...)`` after ``from proxy import service_utilities
as su``) is a static call of a module function, not a method of a run-time object, so rules
with ``*.name`` patterns do not match it; a rule naming the module (``robosoa.connect``) does.
"""

from __future__ import annotations

from collections.abc import Iterable

from archmetrics.coupling.imports import dotted
from archmetrics.facts import Statement


def _clauses(text: str) -> list[list[str]]:
    inner = text.replace("(", " ").replace(")", " ").replace("\\", " ")
    return [clause.split() for clause in inner.split(",") if clause.strip()]


def module_bindings(statements: Iterable[Statement], modules: Iterable[str]) -> frozenset[str]:
    """Local names bound to modules: every ``import`` name, and ``from`` names in ``modules``.

    ``modules`` are the dotted names (as written, relative ones with their dots) this file's
    ``from X import Y`` statements resolved to as submodules.
    """
    known = set(modules)
    bound: set[str] = set()
    for statement in statements:
        text = statement.text
        if text.startswith("import "):
            for words in _clauses(text[len("import ") :]):
                name = "".join(words[: words.index("as")] if "as" in words else words)
                bound.add(words[-1] if "as" in words else name.split(".")[0])
        elif text.startswith("from ") and " import " in text:
            source, _, names = text[len("from ") :].partition(" import ")
            origin = source.replace(" ", "")
            for words in _clauses(names):
                if dotted(origin, words[0]) in known:
                    bound.add(words[-1])
    return frozenset(bound)
