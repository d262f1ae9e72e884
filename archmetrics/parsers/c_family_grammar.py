"""tree-sitter for C and C++: each language's parser and its one query, and a parse that
stops when it runs out of time.

The query captures every node the walker needs in one pass on the C side (c_family.py).
A pattern that names a node's parent, ``(parent (child))``, keeps a partial match open for
every ``parent`` the query cursor is inside: with a parent type that nests (a block) that
is n² work on n nested blocks (4,000 nested `if` blocks: 4 s for one such pattern), so the
patterns here name parents only where they do not nest deeply.
"""

from __future__ import annotations

import importlib
import re
import time
from collections.abc import Iterator, Mapping
from dataclasses import dataclass

from tree_sitter import Language as TSLanguage
from tree_sitter import Node, Parser, Point, Query, QueryError, Tree

from archmetrics.facts import Language
from archmetrics.parsers import c_tables

_CHUNK = 1 << 16  # bytes handed to the parser at a time
# tree-sitter's query cursor counts depth in 16 bits: past 65,535 levels it drops captures
# (32,766 of 34,000 chained calls) and slows quadratically (2 s; 36 s at 80,000 levels).
QUERY_DEPTH = 65_000


@dataclass(frozen=True, slots=True)
class Grammar:
    """A language's parser and queries, built once per process."""

    parser: Parser
    query: Query
    rules: Mapping[str, c_tables.StatementRule]


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
        f"[{specifiers}] @specifier",  # kept only where they stand alone (c_family.py)
        *c_tables.NOT_STATEMENTS,
        f"[{tokens}] @decision",
        c_tables.CATCH_READ_AS_FUNCTION,
        *c_tables.NOT_DECISIONS,
        *c_tables.DIRECTIVE_CONDITIONS,
        f"[{classes}] @class",
        f"({c_tables.NAMESPACE}) @namespace",
        "(call_expression) @call",
        # constructor calls without a call expression (c_family_constructs.py)
        "[(new_expression) (field_initializer)] @construct",
        "(declaration declarator: (init_declarator value: [(argument_list) (initializer_list)]))"
        " @construct",
        # ``T x(a);`` in a body: read as a function declaration, taken as a construction
        "(compound_statement (declaration declarator: (function_declarator)) @construct)",
        "(field_declaration type: (_) declarator: (field_identifier)) @field",
        "[(init_declarator) (assignment_expression) (preproc_def)] @bind",
        "(field_declaration default_value: (_)) @bind",  # c_family_bindings
        # C++ type aliases; C has no alias_declaration, so this pattern is C++ only
        "[(alias_declaration) (using_declaration) (type_definition declarator: (type_identifier))]"
        " @bind",
        "(comment) @comment",
        "(ERROR) @error",
        "(MISSING) @missing",
        "(template_instantiation (MISSING) @expected)",  # `template class Box<int>;`
        f"({c_tables.TEMPLATE}) @template",
        *c_tables.STRAY_BLOCKS,
        c_tables.MISREAD_HEAD,
        c_tables.CAST_AND,
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
    patterns = _patterns(ts_language, rules)
    try:  # C++ has every node type the patterns name: one compile, not one per pattern
        query = Query(ts_language, "\n".join(patterns))
    except QueryError:
        kept = [pattern for pattern in patterns if _compiles(ts_language, pattern)]
        query = Query(ts_language, "\n".join(kept))
    built = Grammar(Parser(ts_language), query, rules)
    _GRAMMARS[language] = built
    return built


def syntax_tree(
    parser: Parser, data: bytes, seconds: float, old: tuple[Tree, bytes] | None = None
) -> Tree | None:
    """``data`` parsed, or None when the parse takes longer than ``seconds`` (wall clock).

    ``old``: a tree of other bytes of the same length (the same file with some spans
    overwritten by spaces); tree-sitter then reparses only around the spans that differ
    (:func:`edited`), which is what makes a second reading of a file cheap.

    tree-sitter asks whether to go on every hundred or so steps of its parse; a cut-off
    parse would resume with the next call, so the parser is reset. (The query that follows
    the parse is not cut off: py-tree-sitter 0.26's query cursor keeps a pointer to an
    options record that has gone out of scope when it calls back, and crashes.)
    """
    deadline = time.monotonic() + seconds

    def read(offset: int, _: Point) -> bytes:
        return data[offset : offset + _CHUNK]

    def stop(_offset: int, _has_error: bool) -> bool:
        return time.monotonic() > deadline

    try:
        if old is not None:
            return parser.parse(read, old_tree=edited(*old, data), progress_callback=stop)
        return parser.parse(read, progress_callback=stop)
    except ValueError:  # "Parsing failed": cut off
        parser.reset()
        return None


_NEAR = 64  # differing spans closer than this are one edit


def edited(tree: Tree, before: bytes, after: bytes) -> Tree:
    """A copy of ``tree`` (of ``before``) told where ``after``, as long, differs from it."""
    copy = tree.copy()
    spans: list[list[int]] = []
    for start, end in differing(before, after):
        if spans and start - spans[-1][1] < _NEAR:
            spans[-1][1] = end
        else:
            spans.append([start, end])
    row, last = 0, 0  # the points (row, column), counted along the file once
    for start, end in spans:
        points = []
        for offset in (start, end):
            row += before.count(b"\n", last, offset)
            line_start = before.rfind(b"\n", 0, offset) + 1 if row else 0
            points.append(Point(row, offset - line_start))
            last = offset
        copy.edit(start, end, end, points[0], points[1], points[1])
    return copy


_DIFFERENT = re.compile(rb"[^\x00]+")
_BLOCK = 4096  # bytes compared at a time: equal blocks (most of a file) are skipped at once


def differing(before: bytes, after: bytes) -> Iterator[tuple[int, int]]:
    """The byte ranges where ``before`` and ``after`` (as long) differ, in order; ranges
    that meet at a block's edge come as two."""
    for offset in range(0, len(before), _BLOCK):
        stop = offset + _BLOCK
        if before[offset:stop] == after[offset:stop]:
            continue
        size = min(stop, len(before)) - offset
        differ = int.from_bytes(before[offset:stop], "big") ^ int.from_bytes(
            after[offset:stop], "big"
        )
        for found in _DIFFERENT.finditer(differ.to_bytes(size, "big")):
            yield offset + found.start(), offset + found.end()


_STRAY_DIRECTIVE = re.compile(rb"\#[ \t]*+(?:elif|else|endif|elifdef|elifndef)\b")


def stray_directive(node: Node, data: bytes) -> bool:
    """Whether ``node``, a directive tree-sitter read as one of its own (``preproc_call``),
    is an ``#elif``, ``#else`` or ``#endif``: the rest of a conditional group whose ``#if``
    the parser closed early (an ``#if`` branch that closes a brace, ``} else {``), read as
    no group at all. It is damage, like an ``ERROR``."""
    return _STRAY_DIRECTIVE.match(data, node.start_byte, node.end_byte) is not None


def errors_and_missing(root: Node, data: bytes) -> dict[str, list[Node]]:
    """A tree's ``ERROR`` nodes (and stray ``#else`` lines: ``stray_directive``) and the
    tokens its parser invented (``MISSING``), as the query's ``error`` and ``missing``
    captures would give them, in no order. Found without a query: only children that hold
    an error are entered (``has_error``), so a clean stretch of the file costs nothing,
    where a query walks every node."""
    errors: list[Node] = []
    missing: list[Node] = []
    stack = [root] if root.has_error else []
    if root.is_error:
        errors.append(root)  # nothing of the file could be read
    while stack:
        for child in stack.pop().children:
            if child.is_missing:
                missing.append(child)
            elif child.is_error:
                errors.append(child)  # (an ERROR leaf inside an ERROR may lack has_error)
            elif child.type == "preproc_call" and stray_directive(child, data):
                errors.append(child)
            if child.has_error:
                stack.append(child)
    return {"error": errors, "missing": missing}


Parents = dict[int, tuple[Node, Node]]  # a MISSING token's id -> (the token, its parent)


def missing_parents(root: Node) -> Parents:
    """The parent of each token the parser invented, found in one walk of the subtrees
    that hold an error: ``node.parent`` walks down from the root again for each node, which
    for thousands of tokens thousands of levels deep took minutes."""
    parents: Parents = {}
    stack = [root] if root.has_error else []
    while stack:
        parent = stack.pop()
        for child in parent.children:
            if child.is_missing:
                parents[child.id] = (child, parent)
            if child.has_error:
                stack.append(child)
    return parents


def parent_of(node: Node, parents: Parents) -> Node | None:
    """``node``'s parent, from ``parents`` if it holds this node of this tree."""
    known = parents.get(node.id)
    if known is not None and known[0] == node:  # equal nodes: the same tree, the same node
        return known[1]
    return node.parent


#: Nodes that may hold a function definition between declarations.
_HOLDERS = frozenset(
    {
        "translation_unit", "namespace_definition", "declaration_list", "linkage_specification",
        "template_declaration", "declaration", "type_definition", "field_declaration_list",
        "class_specifier", "struct_specifier", "union_specifier", "field_declaration",
        "friend_declaration", "ERROR", "preproc_if",
        "preproc_ifdef", "preproc_else", "preproc_elif", "preproc_elifdef",
    }
)  # fmt: skip


def function_bodies(root: Node) -> list[tuple[int, int]]:
    """Byte ranges of the bodies of the functions between declarations (not those inside a
    body, nor in an initializer: only declaration-holding nodes are entered)."""
    ranges: list[tuple[int, int]] = []
    stack = [root]
    while stack:
        for child in stack.pop().children:
            if child.type == "function_definition":
                body = child.child_by_field_name("body")
                if body is not None:
                    ranges.append((body.start_byte, body.end_byte))
            elif child.type in _HOLDERS:
                stack.append(child)
    return ranges


def deeper_than(root: Node, limit: int) -> bool:
    """True when the tree under ``root`` is more than ``limit`` levels deep.

    A walk that enters only subtrees big enough to be that deep: a subtree of n nodes is at
    most n - 1 levels deep (``descendant_count`` counts the node itself, and is stored, not
    counted). An ordinary file costs a step per top-level declaration; a node with a million
    small children (a one-line table) a step per child."""
    if root.descendant_count <= limit:
        return False
    cursor = root.walk()
    depth = 0
    while True:
        if depth > limit:
            return True
        node = cursor.node
        if node is not None and node.descendant_count > limit - depth and cursor.goto_first_child():
            depth += 1
            continue
        while not cursor.goto_next_sibling():
            if not cursor.goto_parent():
                return False
            depth -= 1
