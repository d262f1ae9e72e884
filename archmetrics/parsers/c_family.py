"""C and C++ facts: one tree-sitter walker, parametrised by the node tables in ``c_tables``.

A single query per language captures every node we need in one pass on the C side;
Python then touches only those nodes (statements, decisions, calls, comments), never the
tokens in between. Statement rules follow thesis page 103; decisions follow lizard.
"""

from __future__ import annotations

import bisect
import importlib
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

from tree_sitter import Language as TSLanguage
from tree_sitter import Node, Parser, Query, QueryCursor, QueryError

from archmetrics.facts import (
    Decision,
    FileFacts,
    Function,
    Language,
    ParseWarning,
    Severity,
    Span,
)
from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_names import (
    call_site,
    function_name,
    in_order,
    span,
)
from archmetrics.parsers.c_family_outline import classes, includes, warnings
from archmetrics.parsers.c_family_statements import Bodies, include_guard, statements
from archmetrics.parsers.c_family_text import blank_comments, sloc


@dataclass(frozen=True, slots=True)
class Grammar:
    """A language's parser and queries, built once per process."""

    parser: Parser
    query: Query
    rules: Mapping[str, c_tables.StatementRule]


@dataclass(slots=True)
class FunctionSlot:
    """A function being measured: where it is and what has been found inside it."""

    name: str
    qualified: str
    span: Span
    start: int
    end: int
    body_start: int
    body_end: int
    decisions: list[Decision] = field(default_factory=list)
    statements: int = 0


_GRAMMARS: dict[str, Grammar] = {}


def _patterns(language: TSLanguage, rules: Mapping[str, c_tables.StatementRule]) -> list[str]:
    def known(kind: str, named: bool = True) -> bool:
        return language.id_for_node_kind(kind, named) is not None

    plain = [kind for kind in rules if kind not in c_tables.SPECIFIERS and known(kind)]
    specifiers = " ".join(f"({kind})" for kind in c_tables.SPECIFIERS if known(kind))
    tokens = " ".join(f'"{token}"' for token in c_tables.DECISIONS if known(token, False))
    classes = " ".join(f"({kind} body: (_))" for kind in c_tables.CLASSES if known(kind))
    return [
        "[" + " ".join(f"({kind})" for kind in plain) + "] @stmt",
        f"[{specifiers}] @specifier",  # kept only where they stand alone (see _standalone)
        *c_tables.NOT_STATEMENTS,
        f"[{tokens}] @decision",
        *c_tables.NOT_DECISIONS,
        *c_tables.DIRECTIVE_CONDITIONS,
        f"[{classes}] @class",
        "(call_expression) @call",
        "(comment) @comment",
        "(ERROR) @error",
        "(MISSING) @missing",
        f"({c_tables.TEMPLATE}) @template",
        "[" + " ".join(f"({kind})" for kind in c_tables.BODIES) + "] @body",
    ]


def _compiles(language: TSLanguage, pattern: str) -> bool:
    try:
        Query(language, pattern)
    except QueryError:
        return False  # a node type this grammar does not have (C has no templates)
    return True


def grammar(language: str) -> Grammar:
    """The parser and queries for ``language`` (C or C++), built on first use."""
    built = _GRAMMARS.get(language)
    if built is not None:
        return built
    is_c = language == Language.C
    module = importlib.import_module("tree_sitter_c" if is_c else "tree_sitter_cpp")
    ts_language = TSLanguage(module.language())
    rules = c_tables.C_STATEMENTS if is_c else c_tables.CPP_STATEMENTS
    patterns = [p for p in _patterns(ts_language, rules) if _compiles(ts_language, p)]
    built = Grammar(Parser(ts_language), Query(ts_language, "\n".join(patterns)), rules)
    _GRAMMARS[language] = built
    return built


def parse(path: str, source: str, language: Language) -> FileFacts:
    """Facts for one C or C++ file. Never raises: what cannot be read becomes a warning."""
    try:
        return _parse(path, source, language)
    except Exception as error:  # a bug here must not stop a whole repository's measurement
        message = f"C/C++ parser failed ({type(error).__name__}: {error}); file not measured"
        return FileFacts(
            path,
            str(language),
            parsed=False,
            warnings=(ParseWarning(path, 1, message, Severity.ERROR),),
        )


_CPLUSPLUS = rb"#[ \t]*if(?:def[ \t]+__cplusplus|[ \t]+defined[ \t(]*__cplusplus[ \t)]*)[^\n]*\n"
_EXTERN_C_GUARD = re.compile(
    rb"(" + _CPLUSPLUS + rb")([ \t]*(?:extern[ \t]+\"C\"[ \t]*)?[{}][ \t]*)(?=\n[ \t]*#[ \t]*endif)"
)


def hide_extern_c_guards(data: bytes) -> bytes:
    """Blank the ``extern "C" {`` and ``}`` lines that sit alone inside ``#ifdef __cplusplus``.

    The idiom opens a brace in one preprocessor branch and closes it in another, which no
    grammar of the unpreprocessed text can follow (tree-sitter reports a missing ``#endif``).
    Those lines count 0 anyway (an ``extern "C"`` block is not a statement); blanking them with
    spaces keeps every byte offset and line number.
    """
    return _EXTERN_C_GUARD.sub(lambda m: m.group(1) + b" " * len(m.group(2)), data)


def _parse(path: str, source: str, language: Language) -> FileFacts:
    built = grammar(language)
    data = hide_extern_c_guards(source.encode("utf-8", "surrogatepass"))
    root = built.parser.parse(data).root_node
    found = QueryCursor(built.query).captures(root)
    slots = _functions(found.get("stmt", []), data)
    owner = _Owners(slots)
    skip = {node.id for node in found.get("skip", [])}
    guard = include_guard(root, data)
    if guard is not None:
        skip.add(guard)
    nodes = in_order(
        node for node in found.get("stmt", []) + _standalone(found) if node.id not in skip
    )
    comments = sorted((n.start_byte, n.end_byte) for n in found.get("comment", []))
    clean = blank_comments(data, comments)
    facts_statements = statements(
        nodes, built.rules, Bodies(found.get("body", [])), clean, _templates(found), owner.claim
    )
    _decisions(found, owner)
    return FileFacts(
        path=path,
        language=str(language),
        statements=tuple(facts_statements),
        functions=tuple(
            Function(s.name, s.qualified, s.span, tuple(s.decisions), s.statements) for s in slots
        ),
        classes=classes(found.get("class", []), data),
        dependencies=includes(nodes, data),
        call_sites=tuple(
            call_site(node, data, owner.name(node.start_byte))
            for node in in_order(found.get("call", []))
        ),
        sloc=sloc(clean),
        warnings=warnings(path, found, data),
    )


def _standalone(found: dict[str, list[Node]]) -> list[Node]:
    """Type specifiers that are a statement of their own (not inside a declaration)."""
    containers = c_tables.SPECIFIER_CONTAINERS
    standalone: list[Node] = []
    for node in found.get("specifier", []):
        parent = node.parent
        if parent is not None and parent.type in containers:
            standalone.append(node)
    return standalone


class _Owners:
    """Which measured function encloses a byte offset (functions do not overlap)."""

    def __init__(self, slots: list[FunctionSlot]) -> None:
        self._slots = slots
        self._starts = [slot.start for slot in slots]

    def at(self, offset: int) -> FunctionSlot | None:
        """The function whose definition holds byte ``offset``, if any."""
        index = bisect.bisect_right(self._starts, offset) - 1
        if index >= 0 and offset < self._slots[index].end:
            return self._slots[index]
        return None

    def claim(self, offset: int) -> str | None:
        """The enclosing function's name; counts one more statement in it."""
        slot = self.at(offset)
        if slot is None:
            return None
        slot.statements += 1
        return slot.qualified

    def name(self, offset: int) -> str | None:
        slot = self.at(offset)
        return slot.qualified if slot is not None else None


def _functions(nodes: list[Node], data: bytes) -> list[FunctionSlot]:
    """Function definitions with a body that are not inside another function (as lizard)."""
    slots: list[FunctionSlot] = []
    last_end = -1
    definitions = in_order(node for node in nodes if node.type == c_tables.FUNCTION)
    for node in definitions:
        body = node.child_by_field_name("body")
        if body is None or node.start_byte < last_end:
            continue
        name, qualified = function_name(node, data)
        slots.append(
            FunctionSlot(
                name,
                qualified,
                span(node),
                node.start_byte,
                node.end_byte,
                body.start_byte,
                body.end_byte,
            )
        )
        last_end = node.end_byte
    return slots


def _decisions(found: dict[str, list[Node]], owner: _Owners) -> None:
    """Add each decision token inside a function body to that function."""
    not_decisions = {node.id for node in found.get("nodecision", [])}
    directives = sorted((node.start_byte, node.end_byte) for node in found.get("directive", []))
    directive_starts = [start for start, _ in directives]
    for node in in_order(found.get("decision", [])):
        offset = node.start_byte
        slot = owner.at(offset)
        if slot is None or node.id in not_decisions:
            continue
        index = bisect.bisect_right(directive_starts, offset) - 1
        if index >= 0 and offset < directives[index][1]:
            continue  # inside `#if A && B`
        if slot.body_start <= offset < slot.body_end:
            kind = c_tables.DECISIONS[node.type]
            slot.decisions.append(Decision(kind, node.start_point.row + 1))


def _templates(found: dict[str, list[Node]]) -> dict[int, tuple[int, int]]:
    """Start byte of each templated declaration -> (byte, row) where its `template` begins."""
    starts: dict[int, tuple[int, int]] = {}
    for node in in_order(found.get("template", [])):
        inner = node.named_child(node.named_child_count - 1) if node.named_child_count else None
        if inner is None:
            continue
        begin = starts.get(node.start_byte, (node.start_byte, node.start_point.row))
        starts[inner.start_byte] = begin
    return starts
