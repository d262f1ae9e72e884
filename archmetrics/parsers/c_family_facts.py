"""The facts of one C/C++ file from its reading: statements, functions, decisions, call
sites, bindings, classes, includes and warnings (c_family.py reads the file; this module
turns the captures into facts, with the token reading as the second opinion where the
syntax tree cannot be trusted: c_family_trust.py)."""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

from tree_sitter import Node

from archmetrics.facts import CallSite, Decision, FileFacts, Function, Language, ParseWarning
from archmetrics.parsers import c_family_tokens, c_tables
from archmetrics.parsers.c_family_bindings import bindings
from archmetrics.parsers.c_family_calls import CallSites
from archmetrics.parsers.c_family_constructs import (
    call_targets,
    constructions,
    field_types,
    initialized_members,
)
from archmetrics.parsers.c_family_definitions import Definition, definitions
from archmetrics.parsers.c_family_functions import (
    FunctionSlot,
    Owners,
    add_decisions,
    function_slots,
)
from archmetrics.parsers.c_family_grammar import Grammar, missing_parents
from archmetrics.parsers.c_family_heads import KEYWORDS
from archmetrics.parsers.c_family_macro_rules import MacroNames
from archmetrics.parsers.c_family_macros import macro_calls
from archmetrics.parsers.c_family_names import Scopes, in_order, typedef_names
from archmetrics.parsers.c_family_outline import classes, includes
from archmetrics.parsers.c_family_statements import Bodies, include_guard, statements
from archmetrics.parsers.c_family_text import blank_comments, sloc, whole_lines
from archmetrics.parsers.c_family_trust import Area, Lines, amend, areas_of, macro_heads, reconcile
from archmetrics.parsers.c_family_warnings import Counted, warnings


@dataclass(slots=True)
class Composite:
    """What the facts are read from: the captures of the file as written, and inside each
    region it could not read, those of the spelling that read the region best
    (c_family_regions.py), with the decisions of the directives a spelling blanked."""

    root: Node
    found: dict[str, list[Node]]
    standalone: list[Node]
    directive_decisions: list[tuple[int, str, int]] = field(default_factory=list)
    hidden_comments: list[tuple[int, int]] = field(default_factory=list)  # blanked to parse
    set_aside: list[tuple[int, int]] = field(default_factory=list)  # #if branches not read


def facts(
    path: str,
    language: Language,
    built: Grammar,
    reading: Composite,
    data: bytes,
    macros: MacroNames,
    second_reading: bool = True,
    damaged: bool = False,
) -> FileFacts:
    """The facts of ``reading``'s captures, with every text taken from ``data`` as written.
    ``second_reading``: where the tree cannot be trusted, compare it with the token
    reading (False: the tree's facts alone, without warnings; a measuring aid).
    ``damaged``: the first parse had errors (then macros called alone on their line, which
    a reading may have blanked, are call sites too)."""
    root, found = reading.root, reading.found
    typedefs = typedef_names(found.get("stmt", []), data)
    scopes = Scopes(found.get("namespace", []), found.get("class", []), data, typedefs)
    missing = found.get("missing", [])
    parents = missing_parents(root) if missing else {}
    made, explained = definitions(
        in_order(found.get("stmt", [])), missing, data, macros.function, parents
    )
    slots, nested = function_slots(made, data, scopes)
    suspects = suspect_regions(found, data, slots, nested, made, explained)
    suspects += [
        (*whole_lines(data, start, end), "branch")
        for start, end in reading.set_aside
        if data[start:end].strip()
    ]
    trust = None
    if suspects and second_reading:
        trust = _Trust.of(slots, suspects, data, language, scopes)
    if trust is not None:
        slots = trust.slots
    owner = Owners(slots)
    skip = {node.id for node in found.get("skip", [])}
    guard = include_guard(root, data)
    if guard is not None:
        skip.add(guard)
    nodes = in_order(
        node for node in found.get("stmt", []) + reading.standalone if node.id not in skip
    )
    comments = sorted(
        [(n.start_byte, n.end_byte) for n in found.get("comment", [])] + reading.hidden_comments
    )
    clean = blank_comments(data, comments)
    facts_statements = statements(
        nodes, built.rules, Bodies(found.get("body", [])), clean, templates(found), owner.claim
    )
    add_decisions(found, owner, reading.directive_decisions)
    _misread_and(found, owner, data)
    call_sites = _call_sites(found, data, owner, damaged)
    bound = bindings(found.get("bind", []), clean, owner.names)
    found_warnings: tuple[ParseWarning, ...] = ()
    if trust is not None:
        trust.amend(slots)
        counted = Counted(
            sorted(d.line for s in slots for d in s.decisions),
            sorted(s.span.start for s in facts_statements if s.kind != "function"),
            sorted(c.span.start for c in call_sites),
        )
        found_warnings = trust.warnings(path, data, counted)
    return FileFacts(
        path=path,
        language=str(language),
        statements=tuple(facts_statements),
        functions=tuple(
            Function(
                s.name,
                s.qualified,
                s.span,
                tuple(s.decisions),
                s.statements,
                s.parameters,
                estimated=s.estimated,
            )
            for s in slots
        ),
        classes=classes(found.get("class", []), scopes),
        dependencies=includes(nodes, data),
        call_sites=call_sites,
        bindings=bound,
        sloc=sloc(clean),
        warnings=found_warnings,
    )


def _call_sites(
    found: dict[str, list[Node]], data: bytes, owner: Owners, damaged: bool
) -> tuple[CallSite, ...]:
    """The file's call sites: calls, with their targets and template arguments; objects
    constructed without a call expression (``T x(a);``, a member's initializer); and, in a
    damaged file, macros called alone on their line (``PLUGINLIB_EXPORT_CLASS(...)``)."""
    constructs = in_order(found.get("construct", []))
    wanted = initialized_members(constructs, data) if constructs else set()
    members = field_types(found.get("field", []), data, wanted) if wanted else {}
    targets = call_targets(
        [*found.get("bind", []), *(n for n in constructs if n.type == "field_initializer")], data
    )
    constructed = [c for node in constructs for c in constructions(node, data, members, targets)]
    called = macro_calls(data, ()) if damaged else []
    return CallSites(found.get("call", []), data, targets).sites(owner.names, constructed, called)


@dataclass(slots=True)
class _Trust:
    """The second reading of a file whose tree cannot be trusted everywhere."""

    slots: list[FunctionSlot]
    areas: list[Area]
    regions: list[tuple[int, int]]
    pairs: dict[int, c_family_tokens.TokenFunction]
    reading: c_family_tokens.TokenReading
    lines: Lines

    @classmethod
    def of(
        cls,
        slots: list[FunctionSlot],
        suspects: list[tuple[int, int, str]],
        data: bytes,
        language: Language,
        scopes: Scopes,
    ) -> _Trust:
        lines = Lines(data)
        spans = windows(suspects, slots, len(data))
        reading = c_family_tokens.read(data, language == Language.CPP, spans)
        starts = [start for start, _ in spans]
        for function in reading.functions:  # the scopes around its window, from the tree
            at = spans[bisect.bisect_right(starts, function.start) - 1][0]
            outer = scopes.prefix_at(at)
            if outer:
                function.qualified = f"{outer}::{function.qualified}"
        kept, areas, pairs = reconcile(slots, reading, areas_of(suspects), data, lines)
        regions = [(start, end) for start, end, _ in suspects]
        return cls(kept, areas, regions, pairs, reading, lines)

    def amend(self, slots: list[FunctionSlot]) -> None:
        amend(slots, self.areas, self.regions, self.pairs, self.lines)

    def warnings(self, path: str, data: bytes, counted: Counted) -> tuple[ParseWarning, ...]:
        return warnings(path, self.areas, self.reading, data, counted, self.lines)


def windows(
    suspects: list[tuple[int, int, str]], slots: list[FunctionSlot], size: int
) -> list[tuple[int, int]]:
    """The byte ranges the token reading reads: around each suspect region, from the end
    of the last function of the tree before it (where the tree stands between
    declarations) to the end of the first function after every function that overlaps it
    (a function the region swallowed may end far after it), joined where they meet."""
    ends = [slot.end for slot in slots]
    starts = [slot.start for slot in slots]
    found: list[tuple[int, int]] = []
    for start, end, _ in sorted(suspects):
        before = bisect.bisect_right(ends, start) - 1
        begin = ends[before] if before >= 0 else 0
        index = bisect.bisect_left(ends, start + 1)  # the first slot ending after the start
        while index < len(slots) and starts[index] < end:
            end = max(end, ends[index])
            index += 1
        stop = ends[index] if index < len(slots) else size
        if found and begin <= found[-1][1]:
            found[-1] = (found[-1][0], max(found[-1][1], stop))
        else:
            found.append((begin, stop))
    return found


def suspect_regions(
    found: dict[str, list[Node]],
    data: bytes,
    slots: list[FunctionSlot],
    nested: list[Definition],
    made: list[Definition],
    explained: list[Node],
) -> list[tuple[int, int, str]]:
    """Where the tree cannot be trusted, (start, end, cause) in bytes: its ``ERROR`` nodes
    and the tokens it had to invent (whole lines, joined where they touch); a function
    named by a keyword; a definition inside a function's body that is no method of a class
    defined there; a block outside any function that is no macro-made function's body."""
    expected = {node.id for node in found.get("expected", []) + explained}
    spots = [(n.start_byte, n.end_byte) for n in found.get("error", [])] + [
        (n.start_byte, n.end_byte) for n in found.get("missing", []) if n.id not in expected
    ]  # (tree-sitter-cpp wants a declarator in `template class Box<int>;`: expected)
    regions: list[tuple[int, int, str]] = []
    for start, end in sorted(spots):
        start, end = whole_lines(data, start, end)
        if regions and start <= regions[-1][1] + 1:
            regions[-1] = (regions[-1][0], max(end, regions[-1][1]), "damage")
        else:
            regions.append((start, end, "damage"))
    regions += [(s.start, s.end, "keyword") for s in slots if s.name.encode() in KEYWORDS]
    if nested:
        local = sorted((n.start_byte, n.end_byte) for n in found.get("class", []))
        regions += [
            (*whole_lines(data, d.start, d.end), "nested")
            for d in nested
            if not _in_local_class(d, local, slots)
        ]
    bodies = {d.body.start_byte for d in made if d.macro is not None}
    inside = sorted((s.body_start, s.body_end) for s in slots)
    starts = [start for start, _ in inside]
    for node in found.get("stray", []):
        index = bisect.bisect_right(starts, node.start_byte) - 1
        if node.start_byte in bodies or (index >= 0 and node.end_byte <= inside[index][1]):
            continue  # a macro-made function's body, or a block in an #if inside a body
        regions.append((*whole_lines(data, node.start_byte, node.end_byte), "stray"))
    regions += [
        (*whole_lines(data, n.start_byte, n.end_byte), "braced") for n in found.get("braced", [])
    ]
    for node in found.get("misread", []):  # the head before the body
        head = next((s for s in slots if s.body_start == node.start_byte), None)
        if head is not None:
            regions.append((*whole_lines(data, head.start, node.start_byte), "head"))
    regions += [
        (*whole_lines(data, start, end), cause) for start, end, cause in macro_heads(slots, data)
    ]
    return regions


def _in_local_class(
    definition: Definition, classes: list[tuple[int, int]], slots: list[FunctionSlot]
) -> bool:
    """Whether ``definition`` is a method of a class defined inside a function's body."""
    starts = [start for start, _ in classes]
    index = bisect.bisect_right(starts, definition.start) - 1
    while index >= 0:
        start, end = classes[index]
        if end >= definition.end:
            return any(s.body_start <= start and end <= s.body_end for s in slots)
        index -= 1
    return False


def _misread_and(found: dict[str, list[Node]], owner: Owners, data: bytes) -> None:
    """A `&&` tree-sitter read as two address-of operators after a parenthesised name it
    took for a cast (``(std::isnan)(a) && b > 0``): a decision like any `&&`."""
    for node in found.get("castand", []):
        offset = node.start_byte
        if data[offset : offset + 2] != b"&&":
            continue
        slot = owner.at(offset)
        if slot is not None and not slot.from_tokens and slot.body_start <= offset < slot.body_end:
            slot.decisions.append(Decision("&&", node.start_point.row + 1))
            slot.decisions.sort(key=lambda decision: decision.line)


def standalone(root: Node, specifiers: list[Node]) -> list[Node]:
    """Type specifiers that are a statement of their own: those whose parent is a container
    (a file, a block, a class or namespace body), not a declaration.

    The parents are found by one cursor moving through the tree from one specifier to the
    next (up, forward, down), not by ``node.parent``: tree-sitter finds a parent by
    descending from the root again, which costs n² steps for n nested specifiers."""
    containers = c_tables.SPECIFIER_CONTAINERS
    standalone: list[Node] = []
    cursor = root.walk()
    above: list[str] = []  # the types of the nodes above the cursor's, innermost last
    for node in in_order(specifiers):
        start, end = node.start_byte, node.end_byte
        at: Node | None = cursor.node
        while at is not None and not (at.start_byte <= start and end <= at.end_byte):
            if at.end_byte <= start and cursor.goto_next_sibling():
                at = cursor.node  # forward among siblings: a wide node is crossed once
            elif cursor.goto_parent():
                at = cursor.node
                above.pop()
            else:
                break
        while at is not None and at.id != node.id:
            kind = at.type
            if cursor.goto_first_child_for_byte(start) is None:
                break
            above.append(kind)
            at = cursor.node
            while at is not None and at.end_byte < end and cursor.goto_next_sibling():
                at = cursor.node  # a child that ends too soon (empty, or a missing token)
        if at is not None and at.id == node.id and above and above[-1] in containers:
            standalone.append(node)
    return standalone


def templates(found: dict[str, list[Node]]) -> dict[int, tuple[int, int]]:
    """Start byte of each templated declaration -> (byte, row) where its `template` begins."""
    starts: dict[int, tuple[int, int]] = {}
    for node in in_order(found.get("template", [])):
        inner = node.named_child(node.named_child_count - 1) if node.named_child_count else None
        if inner is None:
            continue
        begin = starts.get(node.start_byte, (node.start_byte, node.start_point.row))
        starts[inner.start_byte] = begin
    return starts
