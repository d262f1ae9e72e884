"""Parsers: bytes in, :class:`~archmetrics.facts.FileFacts` out, nothing else.

One module per language family. A language is registered as a :class:`LanguageSpec`;
third-party languages arrive through the ``archmetrics.languages`` entry-point group and are
type-checked when loaded.
"""

from __future__ import annotations

from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits
from archmetrics.parsers.registry import (
    DEFAULT_EXTENSIONS,
    LanguageSpec,
    LanguageTable,
    UnknownLanguage,
    parse_source,
)

__all__ = [
    "DEFAULT_EXTENSIONS",
    "DEFAULT_LIMITS",
    "LanguageSpec",
    "LanguageTable",
    "ParseLimits",
    "UnknownLanguage",
    "parse_source",
]
