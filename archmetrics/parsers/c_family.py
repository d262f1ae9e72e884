"""C and C++ facts: one tree-sitter walker, parametrised by the node tables in ``c_tables``.

A single query per language captures every node we need in one pass on the C side;
Python then touches only those nodes (statements, decisions, calls, comments), never the
tokens in between. Statement rules follow thesis page 103; decisions follow lizard.
"""

from __future__ import annotations

import bisect
import re
from collections.abc import Sequence
from dataclasses import dataclass

from tree_sitter import Node, QueryCursor, Tree

from archmetrics.facts import (
    FileFacts,
    Language,
    ParseWarning,
    Severity,
)
from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_branches import ALL, Conditionals, Group
from archmetrics.parsers.c_family_facts import Composite, facts, standalone
from archmetrics.parsers.c_family_grammar import (
    QUERY_DEPTH,
    Grammar,
    deeper_than,
    errors_and_missing,
    function_bodies,
    grammar,
    stray_directive,
    syntax_tree,
)
from archmetrics.parsers.c_family_macros import blank_macros, directive_comments
from archmetrics.parsers.c_family_names import (
    in_order,
)
from archmetrics.parsers.c_family_regions import Choice, Layout, choose, damaged, joined
from archmetrics.parsers.c_family_text import blank_spans
from archmetrics.parsers.limits import DEFAULT_LIMITS, ParseLimits, not_measured

__all__ = ["Grammar", "grammar", "hide_extern_c_guards", "parse"]


def parse(
    path: str,
    source: str,
    language: Language,
    limits: ParseLimits = DEFAULT_LIMITS,
    second_reading: bool = True,
) -> FileFacts:
    """Facts for one C or C++ file. Never raises: what cannot be read becomes a warning.
    ``second_reading=False``: the syntax tree's facts alone, no token reading where it
    cannot be trusted and no warnings (benchmarks/oracle_c.py measures warnings by it)."""
    try:
        return _parse(path, source, language, limits, second_reading)
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


#: Spellings with one branch of each #if group kept, tried after the one that keeps them all.
BRANCH_SPELLINGS = 3


def _parse(
    path: str, source: str, language: Language, limits: ParseLimits, second_reading: bool
) -> FileFacts:
    if "\r" in source:  # a compiler reads \r\n and a lone \r as newlines, and so do we: the
        # macro rules read lines as ending in \n (a CRLF checkout of a file read otherwise
        # than its LF blob; docs/metrics.md, "Line endings")
        source = source.replace("\r\n", "\n").replace("\r", "\n")
    built = grammar(language)
    data = hide_extern_c_guards(source.encode("utf-8", "surrogatepass"))
    first = blank_macros(data, names=limits.c_macros, first=True)
    hidden = directive_comments(data)
    if hidden:  # comments that end a continued #define for tree-sitter
        first = blank_spans(first, hidden)
    reading = Reading.of(built, first, limits, damage_only=True)
    if isinstance(reading, str):
        return not_measured(path, str(language), 1, reading)
    damaged = reading.root.has_error  # (a macro called without its `;` is damage)
    if damaged:
        reading = _recover(built, reading, limits)
        if isinstance(reading, str):
            return not_measured(path, str(language), 1, reading)
    composite = _branches(built, reading, limits) if reading.root.has_error else None
    reading_used = composite or Composite(reading.root, reading.found, reading.standalone())
    reading_used.hidden_comments = hidden
    return facts(
        path, language, built, reading_used, data, limits.c_macros, second_reading, damaged
    )


def _recover(built: Grammar, reading: Reading, limits: ParseLimits) -> Reading | str:
    """The first parse had errors: parse again with the macros tree-sitter cannot know
    blanked (c_family_macros.py), first only those near the damage, then (if damage is
    left) all of them, and keep whichever parse lost least. Blanking only near the damage
    keeps a macro-like word that was read well elsewhere (a return type ``PVOID`` alone on
    its line above a function's name). The depth limit is checked on the reading kept
    (the query walks it; the rereadings are judged without one)."""
    bodies = reading.bodies()
    damage = damaged(reading.found, reading.data, root=reading.root)
    near = _nearby(reading.data, damage)
    best, tried = reading, {reading.data}
    for spans in (joined(near), None):
        if spans is None and not _widespread(best):
            break
        blanked = blank_macros(reading.data, bodies, limits.c_macros, near=spans)
        if blanked in tried:
            continue
        tried.add(blanked)
        other = Reading.of(built, blanked, limits, reading, damage_only=True)
        if not isinstance(other, str) and other.damage < best.damage:
            best = other
    completed = best.completed(built, limits)
    if isinstance(completed, str) and best is not reading:  # too deep: the first reading
        return reading.completed(built, limits)
    return completed


_FAR_LINES = 10  # a damaged region this long may come from a macro far from it


def _widespread(reading: Reading) -> bool:
    """Whether a damaged region of ``reading`` spans more than ``_FAR_LINES`` lines: a
    macro that breaks a file's structure (``ABSL_NAMESPACE_BEGIN`` before a class) damages
    what follows it, so its cause may lie outside the lines near the damage; a macro that
    breaks one declaration damages only that, near it."""
    data = reading.data
    return any(
        data.count(b"\n", s, e) > _FAR_LINES
        for s, e in damaged(reading.found, data, root=reading.root)
    )


def _branches(built: Grammar, reading: Reading, limits: ParseLimits) -> Composite | None:
    """Where ``reading`` has errors, the file read again without its #if directives (every
    branch kept, then one branch at a time: c_family_branches.py), region by region."""
    conditionals = Conditionals(reading.data)
    if not conditionals.groups:
        return None
    damage = damaged(reading.found, reading.data, root=reading.root)
    if not damage:
        return None
    # only the groups near the damage are read otherwise, and only the captures there are
    # taken, unless a region grows past those windows: then the whole file is read again
    window: list[tuple[int, int]] | None = joined(
        [_around(reading.data, [span], _CONTEXT_LINES) for span in damage]
    )
    base = Layout(reading.found, reading.data, within=window, root=reading.root)
    readings: list[Reading] = []
    layouts: list[Layout] = []
    found_in: list[list[tuple[int, str, int]]] = []  # the blanked directives' decisions
    choices: list[Choice] = []
    groups = conditionals.near(_suspects(reading.data, base))
    if not groups:
        return None  # no #if near the damage: another spelling would read it alike
    spellings = _spellings(groups)
    index = 0
    reduced: list[Group] | None = None  # the groups one branch at a time: near ALL's damage
    while index < len(spellings):
        spelling = conditionals.spelling(spellings[index], groups, reduced)
        # a spelling is judged first by the code it sets aside (no parse), then by its
        # parse's errors alone (no query), and captured only if it may still read a damaged
        # region better than the first reading or the spelling chosen there so far
        branch = spellings[index]
        index += 1
        if branch != ALL and not _may_read_better(
            Layout({}, reading.data, spelling.set_aside), base, layouts, choices
        ):
            continue
        other = Reading.of(built, spelling.data, limits, reading, window, damage_only=True)
        if isinstance(other, str):
            continue
        if not other.complete:
            lost = Layout(other.found, reading.data, spelling.set_aside, root=other.root)
            if branch == ALL:
                reduced = _still_damaged(reading.data, groups, lost)
                if reduced is not None:  # one branch at a time only where it can read more
                    spellings = _spellings(reduced)
            if not _may_read_better(lost, base, layouts, choices):
                continue
            other = other.completed(built, limits, window)
            if isinstance(other, str):
                continue
        readings.append(other)
        layouts.append(Layout(other.found, reading.data, spelling.set_aside, root=other.root))
        if branch == ALL and other.complete:  # read without damage: every group may help
            reduced = _still_damaged(reading.data, groups, layouts[-1])
        found_in.append(spelling.decisions)
        choices = choose(base, layouts)
        if window is not None and not all(_inside(window, c.start, c.end) for c in choices):
            window, index, readings, layouts, found_in, choices = None, 0, [], [], [], []
            groups, reduced = conditionals.near(None), None
            spellings = _spellings(groups)
            base = Layout(reading.found, reading.data, root=reading.root)
            continue
        if _all_read(base, layouts, choices):
            break
    if not choices:
        return None
    return _merge(reading, readings, choices, found_in, [layout.set_aside for layout in layouts])


def _covered(base: Layout, choices: list[Choice]) -> bool:
    """Whether every damaged region of ``base`` lies inside a chosen region."""
    starts = [choice.start for choice in choices]
    for start, end in base.damaged:
        index = bisect.bisect_right(starts, start) - 1
        if index < 0 or end > choices[index].end:
            return False
    return True


def _may_read_better(
    damage: Layout, base: Layout, layouts: list[Layout], choices: list[Choice]
) -> bool:
    """Whether a spelling whose damage ``damage`` gives (its errors, invented tokens and
    set-aside branches, or a lower bound of them: the set-aside branches alone; no
    structure) loses less inside one of ``base``'s damaged regions than the best reading
    of it so far: the spelling chosen for a region that holds it, else the first reading.
    A spelling that does not is not read further (docs/metrics.md, "Macros and #if"). Where
    a spelling was chosen, this changes nothing: the region a spelling gets holds the
    damaged region (``grow`` only widens) and damage only grows with the region."""
    starts = [choice.start for choice in choices]
    for start, end in base.damaged:
        index = bisect.bisect_right(starts, start) - 1
        if index >= 0 and end <= choices[index].end:
            chosen = choices[index]
            best = layouts[chosen.reader].damage(chosen.start, chosen.end)
        else:
            best = base.damage(start, end)
        if damage.damage(start, end) < best:
            return True
    return False


def _spellings(groups: list[Group]) -> list[int]:
    """Every branch kept (``ALL``), then the first, second... branch of each of ``groups``,
    as many as the group with most branches has (at most ``BRANCH_SPELLINGS``)."""
    return [ALL, *range(min(max((g.branches for g in groups), default=0), BRANCH_SPELLINGS))]


_CONTEXT_LINES = 40  # lines either side of the damage whose captures a spelling takes


def _inside(ranges: list[tuple[int, int]], start: int, end: int) -> bool:
    """Whether ``[start, end)`` lies inside one of sorted, disjoint ``ranges``."""
    index = bisect.bisect_right(ranges, start, key=lambda r: r[0]) - 1
    return index >= 0 and ranges[index][0] <= start and end <= ranges[index][1]


_SUSPECT_LINES = 3  # an #if group this near a damaged region may be its cause


def _suspects(data: bytes, base: Layout) -> list[tuple[int, int]]:
    """Where an #if directive may have caused the damage: each damaged region of ``base``
    with ``_SUSPECT_LINES`` lines either side, and the function definition around it."""
    spans = _nearby(data, base.damaged)
    for start, end in base.damaged:
        spans.extend(
            (s, e) for s, e, kind in base.crossing(start, end) if kind == c_tables.FUNCTION
        )
    return spans


def _still_damaged(data: bytes, groups: list[Group], every: Layout) -> list[Group] | None:
    """Of ``groups``, those with a directive near the damage left where every branch was
    kept (``every``): only they need reading one branch at a time (none: no spelling of
    one branch reads more; None: ``every`` left no damage, all of them)."""
    if not every.damaged:
        return None
    return Conditionals.near_in(groups, _nearby(data, every.damaged))


def _nearby(data: bytes, damaged: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Each damaged span with ``_SUSPECT_LINES`` lines either side: where its cause (a
    macro, an #if directive) may stand."""
    return [_around(data, [span], _SUSPECT_LINES) for span in damaged]


def _around(data: bytes, damaged: list[tuple[int, int]], lines: int) -> tuple[int, int]:
    """The bytes from ``lines`` lines before the first damage to as many after the last."""
    start, end = damaged[0][0], damaged[-1][1]
    for _ in range(lines):
        start = max(0, data.rfind(b"\n", 0, max(0, start - 1)))
        found = data.find(b"\n", end + 1)
        end = len(data) if found < 0 else found
    return start, end


def _all_read(base: Layout, layouts: list[Layout], choices: list[Choice]) -> bool:
    """Whether every damaged region of ``base`` is read without damage by its choice."""
    return _covered(base, choices) and all(
        layouts[c.reader].damage(c.start, c.end) == (0, 0) for c in choices
    )


def _merge(
    base: Reading,
    readings: list[Reading],
    choices: list[Choice],
    directives: list[list[tuple[int, str, int]]],
    set_aside: list[list[tuple[int, int]]],
) -> Composite:
    """``base``'s captures outside the chosen regions, the chosen readings' inside, and the
    #if branches a chosen reading set aside there (they are read from tokens: a function
    there is reported, estimated, under a warning; c_family_trust.py)."""
    starts = [choice.start for choice in choices]

    def outside(node: Node) -> bool:
        index = bisect.bisect_right(starts, node.start_byte) - 1
        return index < 0 or node.end_byte > choices[index].end

    found = {name: [n for n in nodes if outside(n)] for name, nodes in base.found.items()}
    standalone = [node for node in base.standalone() if outside(node)]
    decisions: list[tuple[int, str, int]] = []
    aside: list[tuple[int, int]] = []
    for choice in choices:
        chosen = readings[choice.reader]
        aside.extend(
            (max(s, choice.start), min(e, choice.end))
            for s, e in set_aside[choice.reader]
            if s < choice.end and choice.start < e
        )

        def inside(node: Node, choice: Choice = choice) -> bool:
            return choice.start <= node.start_byte and node.end_byte <= choice.end

        for name, nodes in chosen.found.items():
            found.setdefault(name, []).extend(filter(inside, nodes))
        standalone.extend(filter(inside, chosen.standalone()))
        blanked = directives[choice.reader]
        decisions.extend(d for d in blanked if choice.start <= d[0] < choice.end)
    return Composite(base.root, found, standalone, decisions, set_aside=aside)
