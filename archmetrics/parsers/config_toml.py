"""TOML configuration files to facts: every table with values, and the line it is written on.

``tomllib`` (the standard library's reader of the TOML spec) reads and validates the values;
it gives no lines, so a scan of the text (:mod:`archmetrics.parsers.config_lines`) finds
where each table is written. Only the facts a configuration rule can read are kept: tables,
their keys and their values as text (docs/metrics.md, "Configuration links"). A file that is
not valid TOML, nested beyond what ``tomllib`` can follow, or holding more tables than
:data:`MAX_TABLES`, is reported not measured with the reason, as a source file over a limit is.
"""

from __future__ import annotations

import datetime
import re
import tomllib
from collections.abc import Iterator, Mapping
from typing import Any

from archmetrics.facts import ConfigFormat, ConfigTable, FileFacts, ParseWarning
from archmetrics.parsers.config_lines import Concrete, table_lines
from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits, not_measured

MAX_TABLES = 50_000
"""A configuration file with more tables than this is not measured (a router's rules file
holds tens; a larger one is no hand-written configuration, and its facts would be read back
from the cache on every run)."""

MAX_KEYS = 32
"""Tables deeper than this many keys are not read (no configuration rule selects one; a
chain of ten thousand dotted keys must not cost a tuple of every length up to it)."""

_AT_LINE = re.compile(r"at line (\d+)")


def parse(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    """The tables of a TOML document, each with its line; never raises for bad input."""
    language = ConfigFormat.TOML.value
    try:
        document = tomllib.loads(source)
    except tomllib.TOMLDecodeError as error:
        found = _AT_LINE.search(str(error))
        line = int(found.group(1)) if found else source.rstrip().count("\n") + 1  # at the end
        return not_measured(path, language, line, f"not valid TOML: {error}")
    except RecursionError:
        return not_measured(path, language, 1, "not valid TOML: nested too deeply to read")
    lines = table_lines(source, MAX_KEYS)
    tables: list[ConfigTable] = []
    deep = False
    for concrete, keys, table in _walk(document):
        if len(keys) > MAX_KEYS:
            deep = True
            continue
        values = tuple(_values(table))
        if values:
            tables.append(ConfigTable(keys, _line(concrete, lines), values))
        if len(tables) > MAX_TABLES:
            message = f"more than {MAX_TABLES:,} tables; not read as configuration"
            return not_measured(path, language, 1, message)
    warnings: tuple[ParseWarning, ...] = ()
    if deep:
        message = f"tables nested deeper than {MAX_KEYS} keys are not read"
        warnings = (ParseWarning(path, 1, message),)
    tables.sort(key=lambda t: t.line)  # stable: tables on one line keep the document's order
    return FileFacts(path=path, language=language, tables=tuple(tables), warnings=warnings)


_Table = tuple[Concrete, tuple[str, ...], Mapping[str, Any]]


def _walk(document: Mapping[str, Any]) -> Iterator[_Table]:
    """Every table of ``document``, depth first in the order written, with its concrete path
    (keys and array positions) and its keys (positions left out); no recursion."""
    stack: list[_Table] = [((), (), document)]
    while stack:
        concrete, keys, table = stack.pop()
        yield concrete, keys, table
        if len(keys) > MAX_KEYS:
            continue
        children: list[_Table] = []
        for key, value in table.items():
            if isinstance(value, dict):
                children.append(((*concrete, key), (*keys, key), value))
            elif isinstance(value, list):
                children.extend(_tables_in((*concrete, key), (*keys, key), value))
        stack.extend(reversed(children))


def _tables_in(concrete: Concrete, keys: tuple[str, ...], array: list[Any]) -> Iterator[_Table]:
    """The tables an array holds, at any depth of arrays in it, in order; no recursion."""
    pending: list[tuple[Concrete, list[Any]]] = [(concrete, array)]
    while pending:
        where, items = pending.pop()
        nested: list[tuple[Concrete, list[Any]]] = []
        for index, item in enumerate(items):
            if isinstance(item, dict):
                yield (*where, index), keys, item
            elif isinstance(item, list):
                nested.append(((*where, index), item))
        pending.extend(reversed(nested))


def _values(table: Mapping[str, Any]) -> Iterator[tuple[str, tuple[str, ...]]]:
    """The keys of ``table`` holding scalars or arrays with scalars, their values as text."""
    for key, value in table.items():
        if isinstance(value, dict):
            continue
        if isinstance(value, list):
            texts = tuple(_scalars(value))
            if texts:
                yield key, texts
        else:
            yield key, (_text(value),)


def _scalars(array: list[Any]) -> Iterator[str]:
    """The scalars of an array and of the arrays in it, in order (tables left out)."""
    pending: list[Any] = list(reversed(array))
    while pending:
        item = pending.pop()
        if isinstance(item, list):
            pending.extend(reversed(item))
        elif not isinstance(item, dict):
            yield _text(item)


def _text(value: object) -> str:
    """A TOML scalar as text: strings as they are, booleans as TOML spells them."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, datetime.date | datetime.time):
        return value.isoformat()
    return str(value)


def _line(concrete: Concrete, lines: Mapping[Concrete, int]) -> int:
    """Where the table at ``concrete`` is written, else its nearest enclosing table; else 1."""
    while concrete:
        if concrete in lines:
            return lines[concrete]
        concrete = concrete[:-1]
    return 1
