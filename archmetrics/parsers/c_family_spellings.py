"""Reading a damaged C/C++ file again without its #if directives: every branch kept, then
one branch of each group at a time (c_family_branches.py), region by region, each region
read from the spelling that loses least there (docs/metrics.md, "Macros and #if")."""

from __future__ import annotations

import bisect

from tree_sitter import Node

from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_branches import ALL, Conditionals, Group
from archmetrics.parsers.c_family_facts import Composite
from archmetrics.parsers.c_family_grammar import (
    Grammar,
)
from archmetrics.parsers.c_family_reading import Reading
from archmetrics.parsers.c_family_regions import Choice, Layout, choose, damaged, joined
from archmetrics.parsers.limits import ParseLimits

#: Spellings with one branch of each #if group kept, tried after the one that keeps them all.
BRANCH_SPELLINGS = 3


def branches(built: Grammar, reading: Reading, limits: ParseLimits) -> Composite | None:
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
    spans = nearby(data, base.damaged)
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
    return Conditionals.near_in(groups, nearby(data, every.damaged))


def nearby(data: bytes, damaged: list[tuple[int, int]]) -> list[tuple[int, int]]:
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
