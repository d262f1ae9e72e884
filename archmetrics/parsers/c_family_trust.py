"""Two readings of a C/C++ file where the syntax tree cannot be trusted (docs/metrics.md,
"Warnings").

tree-sitter reads most code well; where it cannot (an ``ERROR``, a token it had to invent)
or reads a shape as something it is not (a function named ``namespace``, a definition
inside a function body, a block outside any function), its functions there may be made up
and real ones lost. There the token reading (c_family_tokens.py) is the second opinion:

* a function of the tree that the token reading does not find, in such a region, is not
  reported when the token reading finds others in its place or its name is a keyword or a
  macro the file defines as no function head; the token reading's functions there that the
  tree lost are reported, marked ``estimated`` (their decisions from the tokens);
* in a function both readings find, a damaged region's decisions are those of the reading
  that counts more (the token reading sees an ``if`` the tree lost in an ``ERROR``).

Nothing changes where the tree has no such region: the token reading does not even run.
"""

from __future__ import annotations

import bisect
import re
from collections.abc import Iterable
from dataclasses import dataclass, field

from archmetrics.facts import Decision, Span
from archmetrics.parsers.c_family_functions import FunctionSlot
from archmetrics.parsers.c_family_heads import KEYWORDS
from archmetrics.parsers.c_family_tokens import TokenFunction, TokenReading

_DEFINE = re.compile(rb"(?m)^[ \t]*+\#[ \t]*+define[ \t]++(\w++)(\([^)\n]*+\))?+((?:\\\n|[^\n])*+)")


_PARENTHESES = re.compile(rb"\([^()]*+\)")
_ALIAS = re.compile(rb"[A-Za-z_][\w:]*+")


class Lines:
    """Byte offsets to 1-based line numbers, for one file."""

    def __init__(self, data: bytes) -> None:
        self.ends = [found.start() for found in re.finditer(rb"\n", data)]
        self.size = len(data)

    def of(self, offset: int) -> int:
        return bisect.bisect_left(self.ends, offset) + 1

    def start(self, offset: int) -> int:
        """The offset where the line holding ``offset`` starts."""
        index = bisect.bisect_left(self.ends, offset)
        return self.ends[index - 1] + 1 if index else 0


@dataclass(slots=True)
class Area:
    """A region where the readings were compared: its byte range and what the comparison
    did there (for its warning: c_family_warnings.py)."""

    start: int
    end: int
    causes: set[str] = field(default_factory=set)
    added: list[FunctionSlot] = field(default_factory=list)
    dropped: list[str] = field(default_factory=list)
    amended: list[tuple[str, int]] = field(default_factory=list)  # (function, decisions more)
    renamed: list[tuple[str, str]] = field(default_factory=list)  # (as the tree read it, name)
    unmeasured: int = 0


def areas_of(regions: Iterable[tuple[int, int, str]]) -> list[Area]:
    """Suspect regions (start, end, cause), sorted and those that overlap joined."""
    found: list[Area] = []
    for start, end, cause in sorted(regions):
        if found and start <= found[-1].end:
            found[-1].end = max(found[-1].end, end)
            found[-1].causes.add(cause)
        else:
            found.append(Area(start, end, {cause}))
    return found


def _macro_names(data: bytes) -> frozenset[str]:
    """The macros the file defines whose body does not end in a function head
    (``#define OP(m) {NAME(#m), CHILD(m)},``): a function named after one of them is none.
    A body that ends in a head after its last `;` or `}` (``#define TEST_BEGIN(f) static
    void f(void)``, a test macro that defines a class and then its method's head) makes
    real functions named after it."""
    names = set()
    for found in _DEFINE.finditer(data):
        body = found.group(3).replace(b"\\\n", b" ").rstrip(b" \t\\")
        if found.group(2) is None and _ALIAS.fullmatch(body.strip()):
            continue  # `#define Buffer mock::Buffer`: another name for a real one
        last = body[max(body.rfind(b";"), body.rfind(b"}")) + 1 :]
        outside = _PARENTHESES.sub(b"", last)
        while outside != (inner := _PARENTHESES.sub(b"", outside)):
            outside = inner  # a default argument's `=` is no initializer's
        head_like = last.rstrip().endswith((b")", b"const")) and b"=" not in outside
        if not head_like:
            names.add(found.group(1).decode("utf-8", "replace"))
    return frozenset(names)


def macro_heads(slots: list[FunctionSlot], data: bytes) -> list[tuple[int, int, str]]:
    """The heads of the functions the tree named after a macro the file defines as no
    function head (``#define LJFOLD(x)`` empty, then ``LJFOLD(ADD)`` / ``LJFOLDF(f) {``):
    suspect, (start, end, "head") in bytes."""
    named = [slot for slot in slots if slot.name.isupper()]
    macros = _macro_names(data) if named and b"define" in data else frozenset()
    return [(s.start, s.body_start, "head") for s in named if s.name in macros]


def _matches(
    slots: list[FunctionSlot], functions: list[TokenFunction], lines: Lines
) -> dict[int, int]:
    """slot index -> token function index, where both readings found one function: to the
    same last line, from the same body or under the same name (the two readings may take
    different `{`s of a head spelled twice in #if branches)."""
    by_body = {function.body_start: index for index, function in enumerate(functions)}
    by_end: dict[tuple[int, str], int] = {}
    for index, function in enumerate(functions):
        by_end.setdefault((lines.of(function.end - 1), function.name), index)
    matched: dict[int, int] = {}
    for at, slot in enumerate(slots):
        found = by_body.get(slot.body_start)
        if found is None or lines.of(functions[found].end - 1) != slot.span.end:
            found = by_end.get((slot.span.end, slot.name))
        if found is not None:
            matched[at] = found
    return matched


def _overlaps(start: int, end: int, area: Area) -> bool:
    return start < area.end and area.start < end


def _contested(
    areas: list[Area],
    slots: list[FunctionSlot],
    functions: list[TokenFunction],
    matched: dict[int, int],
    lines: Lines,
) -> list[Area]:
    """``areas`` grown over the functions only one reading finds that overlap them, joined
    where they meet, until none grows."""
    taken = set(matched.values())
    spans = [(s.start, s.end) for i, s in enumerate(slots) if i not in matched] + [
        (lines.start(f.name_at), f.end) for i, f in enumerate(functions) if i not in taken
    ]
    spans.sort()
    while True:
        grown = False
        for area in areas:
            for start, end in spans:
                if start >= area.end:
                    break
                if _overlaps(start, end, area) and (start < area.start or end > area.end):
                    area.start, area.end, grown = min(start, area.start), max(end, area.end), True
        joined: list[Area] = []
        for area in sorted(areas, key=lambda a: a.start):
            if joined and area.start < joined[-1].end:
                joined[-1].end = max(joined[-1].end, area.end)
                joined[-1].causes |= area.causes
                grown = True
            else:
                joined.append(area)
        areas = joined
        if not grown:
            return areas


def reconcile(
    slots: list[FunctionSlot],
    reading: TokenReading,
    areas: list[Area],
    data: bytes,
    lines: Lines,
) -> tuple[list[FunctionSlot], list[Area], dict[int, TokenFunction]]:
    """The functions to report: ``slots`` without those made up, with the token reading's
    functions the tree lost in ``areas`` (grown over the functions only one reading finds);
    the areas; and the token function matched to each kept slot (by ``id``)."""
    functions = reading.functions
    matched = _matches(slots, functions, lines)
    areas = _contested(areas, slots, functions, matched, lines)
    macros = _macro_names(data) if areas else frozenset()
    starts = [area.start for area in areas]

    def area_of(start: int, end: int) -> Area | None:
        index = bisect.bisect_right(starts, end - 1) - 1
        return areas[index] if index >= 0 and _overlaps(start, end, areas[index]) else None

    kept: list[FunctionSlot] = []
    pairs: dict[int, TokenFunction] = {}
    function_starts = sorted(function.start for function in functions)
    for at, slot in enumerate(slots):
        area = area_of(slot.start, slot.end)
        keyword = slot.name.encode() in KEYWORDS
        if area is None and not keyword:
            kept.append(slot)
        elif at in matched and not keyword:
            token = functions[matched[at]]
            if area is not None:
                _adopt_head(slot, token, area, function_starts, (data, lines))
            kept.append(slot)
            pairs[id(slot)] = token
        elif not keyword and slot.name not in macros and not _replaced(slot, functions):
            kept.append(slot)  # the token reading sees no function there: trust the tree
        else:
            (area or _area_for(areas, slot)).dropped.append(slot.qualified)
    taken = set(matched.values())
    for index, function in enumerate(functions):
        area = area_of(lines.start(function.name_at), function.end)
        if index in taken or area is None:
            continue
        added = _slot(function, lines, data)
        if any(_overlaps(s.start, s.end, Area(added.start, added.end)) for s in kept):
            area.unmeasured += 1
            continue
        kept.append(added)
        area.added.append(added)
    kept.sort(key=lambda slot: slot.start)
    return kept, areas, pairs


def _adopt_head(
    slot: FunctionSlot,
    token: TokenFunction,
    area: Area,
    function_starts: list[int],
    text: tuple[bytes, Lines],
) -> None:
    """Where the tree misread a function's head, the token reading's: its name, when the
    tree named it after a macro before it (``GENERATE_TEST(a) ... int main(void) {``),
    and its start, when the tree's head holds other functions (a class read as the head
    of the function after its methods). ``function_starts``: those of the token reading's
    functions, sorted. The tree's name is kept when it stands after the token reading's,
    nearer the body (``f(p) int *p; extern void g(int*); void f(int *p)`` across #if
    branches: the tree's ``f``, not the declared ``g``). Names that differ only in spaces
    (``operator Matcher< C>``) are one name."""
    data, lines = text
    renamed = not _spaceless(slot.name).startswith(_spaceless(token.name))
    renamed = renamed and token.name_at > _last_word(data, slot.name, slot.start, slot.body_start)
    swallowed = bisect.bisect_left(function_starts, token.start) > bisect.bisect_left(
        function_starts, slot.start
    )
    if renamed:
        area.renamed.append((slot.qualified, token.qualified))
        slot.name, slot.qualified = token.name, token.qualified
    if renamed or swallowed:
        slot.span = Span(min(lines.of(token.start), slot.span.end), slot.span.end)
        slot.start = max(slot.start, token.start)


def _spaceless(name: str) -> str:
    """``name`` without its spaces: ``operator Matcher< C>`` is ``operator Matcher<C>``."""
    return name.replace(" ", "")


def _last_word(data: bytes, word: str, start: int, end: int) -> int:
    """Where ``word`` stands last, as a whole word, in ``data[start:end]`` (-1: nowhere)."""
    found = -1
    for match in re.finditer(rb"\b" + re.escape(word.encode()) + rb"\b", data[start:end]):
        found = start + match.start()
    return found


def _area_for(areas: list[Area], slot: FunctionSlot) -> Area:
    """A keyword-named function outside every area: an area of its own."""
    area = Area(slot.start, slot.end, {"keyword"})
    areas.append(area)
    areas.sort(key=lambda a: a.start)
    return area


def _replaced(slot: FunctionSlot, functions: list[TokenFunction]) -> bool:
    """Whether the token reading finds a function overlapping ``slot``'s extent."""
    return any(f.start < slot.end and slot.start < f.end for f in functions)


def _slot(function: TokenFunction, lines: Lines, data: bytes) -> FunctionSlot:
    """A function only the token reading found, as a slot: estimated, its decisions given."""
    first = lines.of(function.start)
    last = lines.of(function.end - 1)
    decisions = [Decision(kind, lines.of(offset)) for kind, offset in function.decisions]
    return FunctionSlot(
        function.name,
        function.qualified,
        Span(first, max(first, last)),
        function.start,
        function.end,
        function.body_start,
        function.end,
        decisions=decisions,
        estimated=True,
        from_tokens=True,
    )


def amend(
    slots: list[FunctionSlot],
    areas: list[Area],
    regions: list[tuple[int, int]],
    pairs: dict[int, TokenFunction],
    lines: Lines,
) -> None:
    """In each function both readings found, the decisions on the lines of a damaged
    ``region`` come from the token reading where it counts more there (an ``if`` inside an
    ``ERROR``); the function is then estimated."""
    starts = [area.start for area in areas]
    for slot in slots:
        token = pairs.get(id(slot))
        if token is None:
            continue
        for start, end in regions:
            if not (slot.body_start < end and start < slot.body_end):
                continue
            first, last = (
                lines.of(max(start, slot.body_start)),
                lines.of(min(end, slot.body_end) - 1),
            )
            tree = [d for d in slot.decisions if first <= d.line <= last]
            tokens = [
                Decision(kind, line)
                for kind, offset in token.decisions
                if first <= (line := lines.of(offset)) <= last
            ]
            if len(tokens) > len(tree):
                kept = [d for d in slot.decisions if not first <= d.line <= last]
                slot.decisions = sorted(kept + tokens, key=lambda d: d.line)
                slot.estimated = True
                index = bisect.bisect_right(starts, start) - 1
                if index >= 0:
                    areas[index].amended.append((slot.qualified, len(tokens) - len(tree)))
