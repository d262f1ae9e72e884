"""Which parse reads each damaged region of a C/C++ file (docs/metrics.md, "Macros and #if").

The file as written (``base``) has ERROR regions; other spellings of the same bytes
(c_family_branches.py) may read them cleanly. A region is grown until it holds whole
syntax on both sides: every declaration, statement, body, class or namespace of either
parse that overlaps it either lies inside it or encloses it in *both* parses with the same
extent and kind (the function around a broken ``if`` is the same function in both). Inside
the region, every capture comes from the spelling that reads it with the least damage;
outside, from the base. So nothing is counted twice and nothing outside a damaged region
changes.
"""

from __future__ import annotations

import bisect
import collections
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass

from tree_sitter import Node

from archmetrics.parsers.c_family_grammar import Parents, missing_parents, parent_of
from archmetrics.parsers.c_family_text import whole_lines

#: The captures that give a parse its shape: a region never cuts one of them in two.
STRUCTURE = ("stmt", "class", "namespace", "body", "error")

Damage = tuple[int, int]  # bytes inside ERROR nodes, tokens the parser invented


class Layout:
    """One parse's structural nodes, sorted, with each one's innermost enclosing node."""

    def __init__(
        self,
        found: dict[str, list[Node]],
        data: bytes,
        set_aside: Sequence[tuple[int, int]] = (),
        within: Sequence[tuple[int, int]] | None = None,
        root: Node | None = None,
    ) -> None:
        """``data``: the bytes as written; ``set_aside``: byte ranges this parse did not
        read (#if branches its spelling blanked); ``within``: only the nodes that overlap
        these byte ranges (sorted, disjoint) are wanted (no other can cross a region
        inside them); ``root``: the parse's tree (``damaged``)."""
        self.data = data
        wanted = _overlapping(within)
        nodes = sorted(
            {
                (start, -end, node.type)
                for name in STRUCTURE
                for node in found.get(name, [])
                if wanted(start := node.start_byte, end := node.end_byte)
            }
        )
        self.starts = [start for start, _, _ in nodes]
        self.ends = [-end for _, end, _ in nodes]
        self.kinds = [kind for _, _, kind in nodes]
        self.shapes = {(start, -end, kind) for start, end, kind in nodes}
        self.parents: list[int] = []
        open_nodes: list[int] = []
        for index, start in enumerate(self.starts):
            while open_nodes and self.ends[open_nodes[-1]] <= start:
                open_nodes.pop()
            self.parents.append(open_nodes[-1] if open_nodes else -1)
            open_nodes.append(index)
        errors: list[tuple[int, int]] = []
        for node in sorted(found.get("error", []), key=lambda n: n.start_byte):
            if not errors or node.start_byte >= errors[-1][1]:
                errors.append((node.start_byte, node.end_byte))
        self.errors = errors
        self.missing = sorted(node.start_byte for node in found.get("missing", []))
        self.broken = joined(
            [whole_lines(data, s, e) for s, e in errors + [(m, m) for m in self.missing]]
        )
        self.set_aside = sorted(set_aside)
        self.damaged = damaged(found, data, errors, root)

    def crossing(self, start: int, end: int) -> Iterator[tuple[int, int, str]]:
        """The nodes that overlap ``[start, end)`` without lying inside it."""
        index = bisect.bisect_left(self.starts, start) - 1
        while index >= 0:  # the nodes around `start` are on one chain of parents
            if self.ends[index] > start:
                yield self.starts[index], self.ends[index], self.kinds[index]
            index = self.parents[index]
        first = bisect.bisect_left(self.starts, start)
        for index in range(first, bisect.bisect_left(self.starts, end)):
            if self.ends[index] > end:
                yield self.starts[index], self.ends[index], self.kinds[index]

    def damage(self, start: int, end: int) -> Damage:
        """The damage of this parse inside ``[start, end)``: the bytes of the lines it broke
        (an ERROR node, a token it had to invent), and the code (not the white space) of
        the branches its spelling set aside; then the number of tokens it invented."""
        lost = _overlap(self.broken, start, end)
        aside, index = self.set_aside, _first(self.set_aside, start)
        while index < len(aside) and aside[index][0] < end:
            s, e = aside[index]
            lost += len(self.data[max(start, s) : min(end, e)].translate(None, b" \t\r\n"))
            index += 1
        invented = bisect.bisect_right(self.missing, end) - bisect.bisect_left(self.missing, start)
        return lost, invented


def _overlapping(within: Sequence[tuple[int, int]] | None) -> Callable[[int, int], bool]:
    """Whether ``[start, end)`` overlaps one of the sorted, disjoint ranges ``within``
    (None: the whole file, whose ranges all end after its first byte)."""
    if within is None:
        return lambda start, end: end > 0
    starts = [start for start, _ in within]

    def overlaps(start: int, end: int) -> bool:
        index = bisect.bisect_left(starts, end) - 1  # the last range that starts before end
        return index >= 0 and within[index][1] > start

    return overlaps


def _first(ranges: list[tuple[int, int]], start: int) -> int:
    """The index of the first of sorted, disjoint ``ranges`` that may overlap ``start``."""
    return max(0, bisect.bisect_right(ranges, (start, start)) - 1)


def _overlap(ranges: list[tuple[int, int]], start: int, end: int) -> int:
    """How many bytes of sorted, disjoint ``ranges`` lie in ``[start, end)``."""
    total = 0
    index = _first(ranges, start)
    while index < len(ranges) and ranges[index][0] < end:
        s, e = ranges[index]
        total += max(0, min(end, e) - max(start, s))
        index += 1
    return total


def joined(ranges: list[tuple[int, int]]) -> list[tuple[int, int]]:
    """Sorted ranges, those that overlap or touch joined."""
    union: list[tuple[int, int]] = []
    for start, end in sorted(ranges):
        if union and start <= union[-1][1]:
            union[-1] = (union[-1][0], max(end, union[-1][1]))
        else:
            union.append((start, end))
    return union


def damaged(
    found: dict[str, list[Node]],
    data: bytes,
    errors: list[tuple[int, int]] | None = None,
    root: Node | None = None,
) -> list[tuple[int, int]]:
    """The regions a parse damaged, sorted: its ``ERROR`` nodes and the nodes its invented
    tokens complete, those at most a line apart joined. ``errors``: the ``ERROR`` spans,
    if known; ``root``: the parse's tree, whose invented tokens' parents are then found in
    one walk."""
    if errors is None:
        errors = [(node.start_byte, node.end_byte) for node in found.get("error", [])]
    missing = found.get("missing", [])
    parents = missing_parents(root) if root is not None and missing else {}
    return _close(joined(errors + [_around(node, parents) for node in missing]), data)


def _close(ranges: list[tuple[int, int]], data: bytes) -> list[tuple[int, int]]:
    """Sorted, disjoint ``ranges`` with those at most one line apart joined: what lies
    between two broken lines belongs to the same damage (``#if A / -1 / #else / x / #endif``
    broken at each directive leaves a line that reads as a statement only by chance)."""
    closed: list[tuple[int, int]] = []
    for start, end in ranges:
        if closed and data.count(b"\n", closed[-1][1], start) <= 2:
            closed[-1] = (closed[-1][0], end)
        else:
            closed.append((start, end))
    return closed


def _around(missing: Node, parents: Parents) -> tuple[int, int]:
    """The region a token the parser invented damages: the node it completes."""
    parent = parent_of(missing, parents)
    node = parent if parent is not None else missing
    return node.start_byte, node.end_byte


def grow(start: int, end: int, base: Layout, other: Layout) -> tuple[int, int]:
    """``[start, end)`` grown until no node of either parse crosses its edges, except nodes
    that enclose it in both parses alike."""
    while True:
        grown = (start, end)
        for mine, theirs in ((base, other), (other, base)):
            for s, e, kind in list(mine.crossing(start, end)):
                if s <= start and end <= e and (s, e, kind) in theirs.shapes:
                    continue
                start, end = min(start, s), max(end, e)
        if (start, end) == grown:
            return start, end


@dataclass(frozen=True, slots=True)
class Choice:
    """Region ``[start, end)`` is read by spelling number ``reader``."""

    start: int
    end: int
    reader: int


def choose(base: Layout, others: Sequence[Layout]) -> list[Choice]:
    """For each damaged region of ``base``, the spelling (an index into ``others``) that reads
    it with the least damage, if one reads it with less than the base; regions do not
    overlap. Ties go to the earlier spelling."""
    choices: list[Choice] = []  # sorted, disjoint
    pending = collections.deque(base.damaged)
    while pending:
        start, end = pending.popleft()
        index = bisect.bisect_right(choices, start, key=lambda c: c.start) - 1
        if index >= 0 and end <= choices[index].end:
            continue  # a region chosen before holds this one
        best: Choice | None = None
        best_damage: Damage | None = None
        for reader, other in enumerate(others):
            s, e = grow(start, end, base, other)
            damage = other.damage(s, e)
            if damage < base.damage(s, e) and (best_damage is None or damage < best_damage):
                best, best_damage = Choice(s, e, reader), damage
        if best is None:
            continue
        low = bisect.bisect_left(choices, best.start, key=lambda c: c.end)  # first ending after
        high = bisect.bisect_left(choices, best.end, key=lambda c: c.start)  # first starting after
        overlapping = choices[low:high]
        if overlapping:  # two regions grew into one: choose again for their union
            union = (min(best.start, overlapping[0].start), max(best.end, overlapping[-1].end))
            del choices[low:high]
            if union != (best.start, best.end) or len(overlapping) > 1:
                pending.appendleft(union)
                continue
        choices.insert(low, best)
    return choices
