"""Golden-test helpers: a source snippet in, its facts out (pyflakes ``test/harness.py`` style)."""

from __future__ import annotations

import textwrap

from archmetrics.facts import FileFacts
from archmetrics.parsers import LanguageTable, parse_source

_TABLE = LanguageTable.default(plugins=False)


def facts_of(source: str, language: str, path: str | None = None) -> FileFacts:
    """Parse a dedented snippet as ``language`` through the real parser."""
    path = path or {"python": "snippet.py", "c": "snippet.c", "cpp": "snippet.cpp"}[language]
    data = textwrap.dedent(source).encode("utf-8")
    return parse_source(path, data, language, _TABLE)


def statement_kinds(facts: FileFacts) -> list[str]:
    return [s.kind for s in facts.statements]


def complexities(facts: FileFacts) -> dict[str, int]:
    return {f.qualified_name: f.complexity for f in facts.functions}
