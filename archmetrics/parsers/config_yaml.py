"""YAML configuration files to facts: every mapping as a table (a ROS parameter file's
``node: ros__parameters: ...``, a YAML launch file's ``- node: {pkg: ..., exec: ...}``).

Read with PyYAML's safe composer (libyaml's when installed), which builds the node graph and
nothing else: no tag is constructed into an object, no code runs (docs/security.md). The
graph is walked once, without recursion: an alias is read where its anchor is and skipped
where it is used again, so a "billion laughs" of aliases costs what its text does; mappings
deeper than 32 keys are not read (a warning says so); a file larger than
:data:`MAX_BYTES`, with more than :data:`MAX_TABLES` mappings, nested deeper than the
composer can follow, or that is not YAML, is not measured, with the reason. Each mapping is
one :class:`ConfigTable`: its keys the mapping keys leading to it (sequence positions left
out), its line (its key's, as a TOML table written inline takes its key's line; a mapping in
a sequence, where it starts), its scalar values (and sequences of scalars) as written,
``parent`` the index of the mapping holding it.
"""

from __future__ import annotations

from collections.abc import Iterator

import yaml

from archmetrics.facts import ConfigFormat, ConfigTable, FileFacts, ParseWarning
from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits, not_measured

MAX_BYTES = 2 << 20
"""A YAML file larger than this (2 MiB) is not read as configuration: launch and parameter
files are kilobytes, and the pure-Python composer reads about a megabyte a second."""

MAX_TABLES = 50_000
MAX_KEYS = 32
MAX_NODES = 500_000  # nodes walked, aliases included once each

_Loader = getattr(yaml, "CSafeLoader", yaml.SafeLoader)


def parse(path: str, source: str, limits: ParseLimits = DEFAULT_LIMITS) -> FileFacts:
    """The mappings of a YAML document (every document of a stream), each with its line;
    never raises for bad input."""
    language = ConfigFormat.YAML.value
    if len(source) > MAX_BYTES:
        message = f"larger than {MAX_BYTES:,} characters; not read as configuration"
        return not_measured(path, language, 1, message)
    try:
        documents = list(yaml.compose_all(source, Loader=_Loader))
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        line = mark.line + 1 if mark is not None else 1
        return not_measured(path, language, line, f"not valid YAML: {error.problem}")
    except yaml.YAMLError as error:
        return not_measured(path, language, 1, f"not valid YAML: {error}")
    except RecursionError:
        return not_measured(path, language, 1, "not valid YAML: nested too deeply to read")
    walk = _Walk()
    for document in documents:
        walk.read(document)
        if walk.failure:
            return not_measured(path, language, 1, walk.failure)
    warnings: tuple[ParseWarning, ...] = ()
    if walk.deep:
        message = f"mappings nested deeper than {MAX_KEYS} keys are not read"
        warnings = (ParseWarning(path, 1, message),)
    return FileFacts(path=path, language=language, tables=tuple(walk.tables), warnings=warnings)


class _Walk:
    """The tables of a node graph, walked depth first in document order."""

    def __init__(self) -> None:
        self.tables: list[ConfigTable] = []
        self.seen: set[int] = set()
        self.nodes = 0
        self.deep = False
        self.failure = ""

    def read(self, root: yaml.Node | None) -> None:
        pending: list[tuple[yaml.Node, tuple[str, ...], int, int]] = []
        if root is not None:
            pending.append((root, (), -1, 0))
        while pending and not self.failure:
            node, keys, parent, line = pending.pop()
            if id(node) in self.seen:
                continue  # an alias: read where its anchor is
            self.seen.add(id(node))
            self.nodes += 1
            if self.nodes > MAX_NODES:
                self.failure = f"more than {MAX_NODES:,} nodes; not read as configuration"
            elif isinstance(node, yaml.SequenceNode):
                pending.extend((item, keys, parent, 0) for item in reversed(node.value))
            elif isinstance(node, yaml.MappingNode):
                pending.extend(reversed(self._mapping(node, keys, parent, line)))

    def _mapping(
        self, node: yaml.MappingNode, keys: tuple[str, ...], parent: int, line: int
    ) -> list[tuple[yaml.Node, tuple[str, ...], int, int]]:
        """The table of a mapping, on ``line`` (its key's; 0: where it starts), and the
        nodes below it to walk."""
        if len(keys) > MAX_KEYS:
            self.deep = True
            return []
        index = len(self.tables)
        values: list[tuple[str, tuple[str, ...]]] = []
        children: list[tuple[yaml.Node, tuple[str, ...], int, int]] = []
        for key, value in node.value:
            if not isinstance(key, yaml.ScalarNode):
                continue
            if isinstance(value, yaml.ScalarNode):
                values.append((key.value, (value.value,)))
            elif isinstance(value, yaml.SequenceNode) and (texts := tuple(_scalars(value))):
                values.append((key.value, texts))
            if not isinstance(value, yaml.ScalarNode):
                children.append((value, (*keys, key.value), index, key.start_mark.line + 1))
        written = line or node.start_mark.line + 1
        self.tables.append(ConfigTable(keys, written, tuple(values), parent))
        if len(self.tables) > MAX_TABLES:
            self.failure = f"more than {MAX_TABLES:,} mappings; not read as configuration"
        return children


def _scalars(node: yaml.SequenceNode) -> Iterator[str]:
    """The scalars a sequence holds directly."""
    for item in node.value:
        if isinstance(item, yaml.ScalarNode):
            yield item.value
