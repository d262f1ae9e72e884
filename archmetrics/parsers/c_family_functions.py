"""The functions of a C/C++ file being measured, and which one holds a byte offset: what
the statements, decisions and call sites the walker finds are counted in (c_family.py)."""

from __future__ import annotations

import bisect
import re
from dataclasses import dataclass, field

from tree_sitter import Node

from archmetrics.facts import Decision, Span
from archmetrics.parsers import c_tables
from archmetrics.parsers.c_family_definitions import Definition
from archmetrics.parsers.c_family_names import Scopes, function_name, function_parameters, in_order


@dataclass(slots=True)
class FunctionSlot:
    """A function being measured: where it is and what has been found inside it.
    ``estimated``: the syntax tree did not read all of it, and its decisions (all of them,
    if ``from_tokens``) come from the token reading (c_family_trust.py)."""

    name: str
    qualified: str
    span: Span
    start: int
    end: int
    body_start: int
    body_end: int
    decisions: list[Decision] = field(default_factory=list)
    statements: int = 0
    parameters: tuple[str, ...] = ()
    estimated: bool = False
    from_tokens: bool = False


class Owners:
    """Which measured function encloses a byte offset (functions do not overlap)."""

    def __init__(self, slots: list[FunctionSlot]) -> None:
        self.slots = slots
        self._starts = [slot.start for slot in slots]

    def at(self, offset: int) -> FunctionSlot | None:
        """The function whose definition holds byte ``offset``, if any."""
        index = bisect.bisect_right(self._starts, offset) - 1
        if index >= 0 and offset < self.slots[index].end:
            return self.slots[index]
        return None

    def claim(self, offsets: list[int]) -> list[str | None]:
        """The enclosing function's name at each offset; counts one more statement in each."""
        names: list[str | None] = []
        for slot in self._slots_at(offsets):
            if slot is None:
                names.append(None)
            else:
                slot.statements += 1
                names.append(slot.qualified)
        return names

    def names(self, offsets: list[int]) -> list[str | None]:
        """The enclosing function's name at each offset."""
        return [None if slot is None else slot.qualified for slot in self._slots_at(offsets)]

    def _slots_at(self, offsets: list[int]) -> list[FunctionSlot | None]:
        """The function holding each offset (one bisection each: the file's statements are
        claimed all at once)."""
        slots, starts = self.slots, self._starts
        if not slots:
            return [None] * len(offsets)
        found: list[FunctionSlot | None] = []
        for offset in offsets:
            index = bisect.bisect_right(starts, offset) - 1
            found.append(slots[index] if index >= 0 and offset < slots[index].end else None)
        return found


# `HEAP_EXPORT(void heap_init(struct heap* h))`: a type, a name, its parameters, nothing else
_WRAPPED = re.compile(
    rb"\(\s*+(?:[A-Za-z_][\w:]*+[\s*&]++)++([A-Za-z_]\w*+)\s*+\((?:[^(),]|,|\([^()]*+\))*+\)\s*+\)\Z"
)


def wrapped_name(head: Node, data: bytes) -> str | None:
    """The name a wrapper macro's argument declares, for a macro-made definition whose
    head is such a call (``UV_UNUSED(static void uv__update_time(uv_loop_t* loop)) {``):
    the function is that one, named as the code names it."""
    call = head.named_child(0) if head.named_child_count else None
    arguments = call.child_by_field_name("arguments") if call is not None else None
    if arguments is None:
        return None
    found = _WRAPPED.match(data, arguments.start_byte, arguments.end_byte)
    return found.group(1).decode("utf-8", "replace") if found else None


def function_slots(
    definitions: list[Definition], data: bytes, scopes: Scopes
) -> tuple[list[FunctionSlot], list[Definition]]:
    """Function definitions with a body that are not inside another function (as lizard),
    and the definitions found inside another's body (a method of a class defined in it, or
    a shape read as a definition that is none: c_family_trust.py tells them apart)."""
    slots: list[FunctionSlot] = []
    nested: list[Definition] = []
    last_end = -1
    prefixes = scopes.prefixes([definition.node for definition in definitions])
    for definition in definitions:
        node, body = definition.node, definition.body
        if node.start_byte < last_end:
            nested.append(definition)
            continue
        prefix = prefixes[node.id]
        parameters: tuple[str, ...] = ()
        if definition.macro is None:
            name, qualified = function_name(node, data, prefix)
            parameters = function_parameters(node, data)
        else:
            name = wrapped_name(node, data) or definition.macro
            qualified = f"{prefix}::{name}".lstrip(":")
        slots.append(
            FunctionSlot(
                name,
                qualified,
                definition.span,
                definition.start,
                definition.end,
                body.start_byte,
                body.end_byte,
                parameters=parameters,
            )
        )
        last_end = definition.end
    return slots, nested


def add_decisions(
    found: dict[str, list[Node]], owner: Owners, directives_read: list[tuple[int, str, int]]
) -> None:
    """Add each decision token inside a function body to that function, and each decision
    of ``directives_read`` ((offset, kind, line) of directives a spelling blanked). A
    function read from tokens alone has its decisions already."""
    not_decisions = {node.id for node in found.get("nodecision", [])}
    directives = sorted((node.start_byte, node.end_byte) for node in found.get("directive", []))
    directive_starts = [start for start, _ in directives]
    for node in in_order(found.get("decision", []) + found.get("catch", [])):
        offset = node.start_byte
        slot = owner.at(offset)
        if slot is None or slot.from_tokens or node.id in not_decisions:
            continue
        index = bisect.bisect_right(directive_starts, offset) - 1
        if index >= 0 and offset < directives[index][1]:
            continue  # inside `#if A && B`
        if slot.body_start <= offset < slot.body_end:
            kind = c_tables.DECISIONS.get(node.type, "catch")  # an identifier `catch`
            slot.decisions.append(Decision(kind, node.start_point.row + 1))
    for offset, kind, line in directives_read:
        slot = owner.at(offset)
        if slot is not None and not slot.from_tokens and slot.body_start <= offset < slot.body_end:
            slot.decisions.append(Decision(kind, line))
    for slot in owner.slots:
        slot.decisions.sort(key=lambda decision: decision.line)
