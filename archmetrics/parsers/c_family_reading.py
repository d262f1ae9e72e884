"""One reading of a C/C++ file: a tree-sitter parse of its bytes (as written, or with macros
or #if branches blanked) and the captures of the query, with the damage it holds."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from tree_sitter import Node, QueryCursor, Tree

from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_facts import standalone
from archmetrics.parsers.c_family_grammar import (
    QUERY_DEPTH,
    Grammar,
    deeper_than,
    errors_and_missing,
    function_bodies,
    stray_directive,
    syntax_tree,
)
from archmetrics.parsers.c_family_names import (
    in_order,
)
from archmetrics.parsers.limits import ParseLimits


@dataclass(slots=True)
class Reading:
    """One parse of a file's bytes (as written, or with macros blanked) and its captures.
    Texts are always read from the bytes as written: blanking keeps every offset."""

    data: bytes
    tree: Tree
    found: dict[str, list[Node]]
    damage: tuple[int, int]  # bytes inside outermost ERROR nodes, tokens the parser invented
    complete: bool = True  # False: only the ERROR and MISSING nodes were found

    @property
    def root(self) -> Node:
        return self.tree.root_node

    @classmethod
    def of(
        cls,
        built: Grammar,
        data: bytes,
        limits: ParseLimits,
        like: Reading | None = None,
        within: Sequence[tuple[int, int]] | None = None,
        damage_only: bool = False,
    ) -> Reading | str:
        """The reading of ``data``, or why there is none (a limit). ``like``: a reading of
        the same file with other spans blanked, whose tree the parse reuses; ``within``:
        only the captures that overlap these byte ranges (sorted, disjoint) are wanted;
        ``damage_only``: if the parse has errors, only they and the tokens it invented are
        found (``completed`` takes the captures; a clean parse is captured at once)."""
        old = (like.tree, like.data) if like is not None else None
        tree = syntax_tree(built.parser, data, limits.parse_seconds, old)
        if tree is None:
            return (
                f"tree-sitter's parse took longer than {limits.parse_seconds:g} s and was cut"
                " off (raise limits.parse-seconds, ParseLimits.parse_seconds, to measure it)"
            )
        root = tree.root_node
        if damage_only and root.has_error:  # found without a query: any depth is safe
            found = errors_and_missing(root, data)
            return cls(data, tree, found, _damage(found), complete=False)
        problem = _too_deep(root, limits)
        if problem is not None:
            return problem
        found = _captures(built, root, data, within)
        return cls(data, tree, found, _damage(found))

    def completed(
        self,
        built: Grammar,
        limits: ParseLimits,
        within: Sequence[tuple[int, int]] | None = None,
    ) -> Reading | str:
        """This reading with every capture of the full query (``within``: only those that
        overlap these byte ranges, as ``of`` takes them), or why there is none."""
        if self.complete:
            return self
        problem = _too_deep(self.root, limits)
        if problem is not None:
            return problem
        found = _captures(built, self.root, self.data, within)
        return Reading(self.data, self.tree, found, _damage(found))

    def standalone(self) -> list[Node]:
        """The type specifiers that are a statement of their own (``struct S { ... };``)."""
        return standalone(self.root, self.found.get("specifier", []))

    def bodies(self) -> list[tuple[int, int]]:
        """Byte ranges of the function bodies this parse found."""
        if not self.complete:
            return function_bodies(self.root)
        ranges = []
        for node in self.found.get("stmt", []):
            body = node.child_by_field_name("body") if node.type == c_tables.FUNCTION else None
            if body is not None:
                ranges.append((body.start_byte, body.end_byte))
        return ranges


def _captures(
    built: Grammar, root: Node, data: bytes, within: Sequence[tuple[int, int]] | None
) -> dict[str, list[Node]]:
    """The query's captures of the tree of ``data``; ``within``: only those that overlap one
    of these byte ranges, each once (a node around two ranges, a namespace say, is captured
    in both).

    A function's name is a ``catch`` capture only when it is spelled ``catch``: that is
    checked here, not by a ``#eq?`` predicate in the query, which py-tree-sitter evaluates
    by asking the parse's read callback for the name's text (a 64 KB chunk per function:
    +0.3 s over the 1,709 benchmark files)."""
    if within is None:
        found = QueryCursor(built.query).captures(root)
    else:
        found = {}
        seen: set[tuple[str, int]] = set()
        for start, end in within:
            cursor = QueryCursor(built.query)
            cursor.set_byte_range(start, end)
            for name, nodes in cursor.captures(root).items():
                kept = found.setdefault(name, [])
                for node in nodes:
                    if (name, node.id) not in seen:
                        seen.add((name, node.id))
                        kept.append(node)
    strays = [
        node
        for node in found.get("stmt", [])
        if node.type == "preproc_call" and stray_directive(node, data)
    ]
    if strays:  # an #else of a group closed early: damage (c_family_grammar.py)
        found.setdefault("error", []).extend(strays)
    named = found.get("catch")
    if named:
        catches = [node for node in named if data[node.start_byte : node.end_byte] == b"catch"]
        if catches:
            found["catch"] = catches
        else:
            del found["catch"]
    return found


def _too_deep(root: Node, limits: ParseLimits) -> str | None:
    """Why the query may not walk this tree (it is too deep), or None."""
    depth = min(limits.max_depth, QUERY_DEPTH)
    if not deeper_than(root, depth):
        return None
    return f"tree-sitter's tree of this file is more than {depth:,} levels deep; " + (
        "the limit is limits.nesting, ParseLimits.max_depth (raise it to measure the file)"
        if depth == limits.max_depth
        else "tree-sitter's query cannot go deeper"
    )


def _damage(found: dict[str, list[Node]]) -> tuple[int, int]:
    lost, last_end = 0, -1
    for node in in_order(found.get("error", [])):
        if node.start_byte >= last_end:
            lost += node.end_byte - node.start_byte
            last_end = node.end_byte
    return lost, len(found.get("missing", []))
