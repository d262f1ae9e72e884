"""C and C++ statements (λ): each captured node becomes one Statement with its normal text.

Which node types count is the table in ``c_tables``; this module only cuts each node down
to its own part (a header, a label) and normalizes that part's text.
"""

from __future__ import annotations

import bisect
import re
from collections.abc import Callable, Mapping

from tree_sitter import Node, Point

from archmetrics.facts import Span, Statement
from archmetrics.parsers.c_family_names import text
from archmetrics.parsers.c_family_text import compact, normal, normal_many
from archmetrics.parsers.c_tables import Shape, StatementRule

_NOT_COUNTED_DIRECTIVES = frozenset({"#pragma once", "#"})
_GUARD_CONDITION = re.compile(r"!defined\(?(\w+)\)?")

# (start byte, end byte, first row, last row, prefix, kind)
_Extent = tuple[int, int, int, int, str, str]


def _last_row(point: Point) -> int:
    """The 0-based row a node ending at ``point`` ends on (a trailing newline does not count)."""
    return point.row if point.column else point.row - 1


def _previous_token(node: Node, child: Node) -> Node | None:
    """The token or node before ``child`` of ``node``, comments skipped. (Not
    ``child.prev_sibling``: tree-sitter finds it by descending from the root again, a cost
    that grows with the depth, so an `else if` chain of n took n² steps.)"""
    previous = None
    for sibling in node.children:
        if sibling.id == child.id:
            return previous
        if sibling.type != "comment":
            previous = sibling
    return None


def _header(node: Node, rule: StatementRule) -> _Extent | None:
    body = node.child_by_field_name(rule.body_field)
    if body is None:
        return None
    last = _previous_token(node, body)
    if last is None:
        return node.start_byte, body.start_byte, node.start_point.row, body.start_point.row, "", ""
    return node.start_byte, last.end_byte, node.start_point.row, _last_row(last.end_point), "", ""


def _label(node: Node) -> _Extent | None:
    first = node.child(0)
    kind = "default" if first is not None and first.type == "default" else "case"
    for index in range(1, 8):
        child = node.child(index)
        if child is None:
            break
        if child.type == ":":
            end = child.end_point.row
            return node.start_byte, child.end_byte, node.start_point.row, end, "", kind
    return None


def _do_while(node: Node) -> _Extent | None:
    condition = node.child_by_field_name("condition")
    keyword = _previous_token(node, condition) if condition is not None else None
    if keyword is None or keyword.type != "while":
        return None
    last = _last_row(node.end_point)
    return keyword.start_byte, node.end_byte, keyword.start_point.row, last, "do ", ""


def _extent(node: Node, rule: StatementRule) -> _Extent:
    """The byte and row range of the statement's own part, a text prefix, a kind override."""
    shaped: _Extent | None = None
    if rule.shape is Shape.HEADER:
        shaped = _header(node, rule)
    elif rule.shape is Shape.LABEL:
        shaped = _label(node)
    elif rule.shape is Shape.DO_WHILE:
        shaped = _do_while(node)
    if shaped is not None:
        return shaped
    first = node.start_point.row
    return node.start_byte, node.end_byte, first, max(first, _last_row(node.end_point)), "", ""


class Bodies:
    """Nested bodies (blocks, member lists) by position, to cut out of statement texts."""

    def __init__(self, nodes: list[Node]) -> None:
        ranges = sorted((node.start_byte, node.end_byte) for node in nodes)
        self.starts = [start for start, _ in ranges]
        self._ends = [end for _, end in ranges]

    def inside(self, start: int, end: int) -> list[tuple[int, int]]:
        """The outermost bodies lying wholly inside [start, end); those inside them are
        stepped over, not visited (a statement around n nested lambdas would visit n)."""
        cuts: list[tuple[int, int]] = []
        starts = self.starts
        index = bisect.bisect_left(starts, start)
        while index < len(starts) and starts[index] < end:
            body_start, body_end = starts[index], self._ends[index]
            if body_end <= end:
                cuts.append((body_start, body_end))
                index = bisect.bisect_left(starts, body_end, index + 1)
            else:
                index += 1  # it runs past the statement (an unbalanced brace, say)
        return cuts


def _piece(start: int, end: int, clean: bytes, bodies: Bodies) -> bytes:
    """The statement's own bytes, comments blanked and nested bodies cut to `{ }`; only
    the bytes kept are copied (the bodies of nested statements are theirs)."""
    cuts = bodies.inside(start, end)
    if not cuts:
        return clean[start:end]
    parts: list[bytes] = []
    position = start
    for cut_start, cut_end in cuts:
        parts.append(clean[position:cut_start])
        parts.append(b"{ }")
        position = cut_end
    parts.append(clean[position:end])
    return b"".join(parts)


def _fixed_text(node: Node, start: int, end: int, clean: bytes) -> str | None:
    """The text of the few statements normalized one by one (includes, directives)."""
    kind = node.type
    if kind == "preproc_include":
        target = node.child_by_field_name("path")
        if target is not None:
            return "#include " + compact(text(target, clean))
    if kind.startswith("preproc_"):
        return normal(clean[start:end])
    return None


def _bounds(node: Node, rule: StatementRule, templates: Mapping[int, tuple[int, int]]) -> _Extent:
    """Bytes and rows of the statement's own part; a template starts at its `template`.
    (Statements of the whole-node shape are bounded inline by ``statements``, the hot loop;
    this takes the other shapes.)"""
    bounds = _extent(node, rule)
    if bounds[0] in templates:
        start, first = templates[bounds[0]]
        return start, bounds[1], first, bounds[3], bounds[4], bounds[5]
    return bounds


def statements(
    nodes: list[Node],
    rules: Mapping[str, StatementRule],
    bodies: Bodies,
    clean: bytes,
    templates: Mapping[int, tuple[int, int]],
    owners: Callable[[list[int]], list[str | None]],
) -> list[Statement]:
    """One Statement per counted node; ``owners`` names (and counts in) the enclosing
    function of each statement's start byte, all at once.

    ``clean`` is the file with comments blanked. Texts are normalized in one batch at the
    end. The loop is the parser's hottest: a node of the commonest shape (the whole node,
    no body inside it) costs a few attribute reads and no call of ours."""
    whole = {kind: rule.kind for kind, rule in rules.items() if rule.shape is Shape.WHOLE}
    body_starts = bodies.starts
    no_body = len(body_starts)
    kinds: list[str] = []
    rows: list[tuple[int, int]] = []
    prefixes: dict[int, str] = {}
    starts: list[int] = []
    pieces: list[bytes] = []
    fixed: dict[int, str] = {}
    for node in nodes:
        kind = node.type
        if kind == "expression_statement" and node.named_child_count == 0:
            continue  # the empty statement `;`
        kind_name = whole.get(kind)
        if kind_name is not None:
            start, end = node.start_byte, node.end_byte
            first = node.start_point.row
            end_point = node.end_point
            last = end_point.row if end_point.column else end_point.row - 1
            if start in templates:
                start, first = templates[start]
            prefix = ""
        else:
            rule = rules[kind]
            start, end, first, last, prefix, override = _bounds(node, rule, templates)
            kind_name = override or rule.kind
        if kind[0] == "p":  # preproc_*: normalized one by one, some do not count
            own = _fixed_text(node, start, end, clean)
            if own in _NOT_COUNTED_DIRECTIVES:
                continue
            if own is not None:
                fixed[len(pieces)] = own
                pieces.append(b"")
        if len(pieces) == len(kinds):  # not fixed: its own bytes, nested bodies cut
            index = bisect.bisect_left(body_starts, start)
            if index == no_body or body_starts[index] >= end:
                pieces.append(clean[start:end])
            else:
                pieces.append(_piece(start, end, clean, bodies))
        if prefix:
            prefixes[len(kinds)] = prefix
        kinds.append(kind_name)
        rows.append((first + 1, (first if first > last else last) + 1))
        starts.append(node.start_byte)
    texts = normal_many(pieces)
    for index, own in fixed.items():
        texts[index] = own
    for index, prefix in prefixes.items():
        texts[index] = prefix + texts[index]
    return _records(kinds, rows, texts, owners(starts))


def _records(
    kinds: list[str], rows: list[tuple[int, int]], texts: list[str], functions: list[str | None]
) -> list[Statement]:
    """The statements, built by ``tuple.__new__``: each row is a valid span (first >= 1,
    last >= first), so Span's check is not run again."""
    new = tuple.__new__
    return [
        new(Statement, (kind, new(Span, row), text, function))
        for kind, row, text, function in zip(kinds, rows, texts, functions, strict=True)
    ]


def include_guard(root: Node, data: bytes) -> int | None:
    """The node id of an include guard's `#define`, when the whole file sits inside the guard."""
    top = [
        node
        for node in root.named_children
        if node.type != "comment"
        and not (node.type == "preproc_call" and normal(text(node, data)) == "#pragma once")
    ]
    if len(top) != 1 or top[0].child_by_field_name("alternative") is not None:
        return None
    guard = top[0]
    inside = [node for node in guard.named_children if node.type != "comment"]
    if len(inside) < 2 or inside[1].type != "preproc_def":
        return None
    if guard.type == "preproc_ifdef" and guard.child(0) is not None:
        keyword = guard.child(0)
        if keyword is None or keyword.type != "#ifndef":
            return None
        name = compact(text(inside[0], data))
    elif guard.type == "preproc_if":
        match = _GUARD_CONDITION.fullmatch(compact(text(inside[0], data)))
        if match is None:
            return None
        name = match.group(1)
    else:
        return None
    define = inside[1]
    defined = define.child_by_field_name("name")
    value = define.child_by_field_name("value")
    if defined is None or compact(text(defined, data)) != name:
        return None
    if value is not None and compact(text(value, data)) not in ("", "1"):
        return None
    return define.id
