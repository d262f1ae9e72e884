"""C and C++ call sites: callee, name, receiver and arguments with their literal values.

Texts of calls nested in long calls are cut (shown.py): they are read by windows from their
start, and a chain's calls, whose texts all start alike, share one cut text.
"""

from __future__ import annotations

import bisect
import re
from collections.abc import Callable, Sequence

from tree_sitter import Node

from archmetrics.facts import Argument, CallSite, Literal, Span
from archmetrics.parsers import shown
from archmetrics.parsers.c_family_names import in_order, text
from archmetrics.parsers.c_family_text import compact, literal, normal, string_value
from archmetrics.parsers.text import collapse

Construction = tuple[Node, str, Node, str | None]
"""A constructor call without a call expression: where, the class as written (compact), the
argument list (or braces) and the target (c_family_constructs.py)."""

_STRINGS = frozenset({"string_literal", "raw_string_literal"})
_CALLEE = re.compile(r"(.*)(\.|->|::)(~?[A-Za-z_$][\w$]*)\Z", re.DOTALL)
_SPACE_OR_COMMENT = re.compile(rb"\s|/[/*]")
_new = tuple.__new__


def without_template_arguments(written: str) -> str:
    """``written`` with its template arguments dropped, inner first, as often as the regular
    expression ``<[^<>()]*>`` would drop them, in one pass: a group goes unless parentheses
    stand in it (which then stand in every group around it too)."""
    kept: list[str] = []
    groups: list[int] = []  # where each open `<` sits in ``kept``
    clean = 0  # groups[clean:] hold no parenthesis
    for char in written:
        if char == "<":
            groups.append(len(kept))
        elif char == ">" and groups:
            where = groups.pop()
            if len(groups) >= clean:
                del kept[where:]
                continue
            clean = len(groups)
        elif char in "()":
            clean = len(groups)
        kept.append(char)
    return "".join(kept)


def template_arguments(written: str) -> tuple[str, ...]:
    """The template arguments of the last part of a callee written ``written`` (compact),
    split at their top-level commas: ``a->f<T, std::map<K, V>>`` gives ``("T",
    "std::map<K,V>")``; none when it does not end in ``>`` (``operator>`` neither)."""
    if not written.endswith(">"):
        return ()
    depth = 0
    for at in range(len(written) - 1, -1, -1):
        char = written[at]
        if char == ">":
            depth += 1
        elif char == "<":
            depth -= 1
            if depth == 0:
                return split_top_level(written[at + 1 : -1])
        elif char in "()" and depth == 1:
            return ()  # `operator()<...>`? a comparison? not a template argument list
    return ()


def split_top_level(text: str) -> tuple[str, ...]:
    """``text`` split at the commas outside brackets, each part stripped (empty parts
    left out)."""
    parts: list[str] = []
    depth, start = 0, 0
    for at, char in enumerate(text):
        if char in "<([{":
            depth += 1
        elif char in ">)]}":
            depth -= 1
        elif char == "," and depth == 0:
            parts.append(text[start:at].strip())
            start = at + 1
    parts.append(text[start:].strip())
    return tuple(part for part in parts if part)


_WINDOW = shown.LIMIT + 256  # bytes first read of a text to be cut
_MARGIN = 16  # characters past the cut that a window's last, partial token may spoil
_TAIL = 256  # bytes at the end of a cut callee read for its name


class CallSites:
    """The call sites of one file, texts cut where long calls nest (shown.py)."""

    def __init__(
        self, nodes: list[Node], data: bytes, targets: dict[tuple[int, int], str] | None = None
    ) -> None:
        self._nodes = in_order(nodes)
        self._data = data
        self._targets = targets or {}  # a call's byte range -> what its value is assigned to
        # where each long call's argument list starts (none in most files: then no text
        # is checked for one)
        lists = (
            node.child_by_field_name("arguments")
            for node in self._nodes
            if node.end_byte - node.start_byte > shown.LIMIT
        )
        self._opens = sorted(node.start_byte for node in lists if node is not None)
        # cut texts by where they start and how they are read, with the end of the bytes
        # read for them: the calls of a chain share one
        self._cut: dict[tuple[int, Callable[[bytes], str]], tuple[int, str]] = {}

    def sites(
        self,
        owners: Callable[[list[int]], list[str | None]],
        constructed: Sequence[Construction] = (),
        macros: Sequence[tuple[int, int, int]] = (),
    ) -> tuple[CallSite, ...]:
        """Every call site in order; ``owners`` names the function around each offset.
        ``constructed``: constructor calls written without a call expression
        (c_family_constructs.py), each (where, class as written, arguments, target);
        ``macros``: macro calls alone on their line (c_family_macros.macro_calls), kept
        where they stand outside any function."""
        nodes = self._nodes
        functions = owners([node.start_byte for node in nodes])
        calls = tuple(map(self._site, nodes, functions))
        if not constructed and not macros:
            return calls
        places = owners([where.start_byte for where, _, _, _ in constructed])
        keyed = [((n.start_byte, -n.end_byte), c) for n, c in zip(nodes, calls, strict=True)]
        keyed += [
            ((parts[0].start_byte, -parts[0].end_byte), self._constructed(*parts, function))
            for parts, function in zip(constructed, places, strict=True)
        ]
        read = {(c.span.start, c.callee) for c in calls} if macros else set()
        keyed += [
            ((start, 0), site) for start, site in self.macro_sites(macros, owners)
            if site.function is None and (site.span.start, site.callee) not in read
        ]  # fmt: skip
        keyed.sort(key=lambda pair: pair[0])
        return tuple(site for _, site in keyed)

    def macro_sites(
        self, found: Sequence[tuple[int, int, int]], owners: Callable[[list[int]], list[str | None]]
    ) -> list[tuple[int, CallSite]]:
        """Call sites of macros called alone on their line between declarations (``found``:
        where each name, argument list and its end are, c_family_macros.macro_calls), each
        with the byte it starts at."""
        data = self._data
        made = []
        line, counted = 1, 0  # the line of byte ``counted``: lines are counted once, onward
        for (start, open_, close), function in zip(
            found, owners([s for s, _, _ in found]), strict=True
        ):
            name = data[start:open_].decode("utf-8", "replace").strip()
            inner = compact(data[open_ + 1 : close - 1]) if close - open_ > 2 else ""
            arguments = tuple(_macro_argument(part) for part in split_top_level(inner))
            if start < counted:  # not in order (macro_calls gives them in order)
                line, counted = 1, 0
            line, counted = line + data.count(b"\n", counted, start), start
            first = line
            last = first + data.count(b"\n", start, close)
            span = _new(Span, (first, last))
            site = _new(CallSite, (name, name, None, span, arguments, function, (), None))
            made.append((start, site))
        return made

    def _constructed(
        self, where: Node, written: str, arguments: Node, target: str | None, function: str | None
    ) -> CallSite:
        """A constructor call of the class ``written``, with ``arguments``' children."""
        templates: tuple[str, ...] = ()
        called = written
        if "<" in written:
            templates = template_arguments(written)
            called = without_template_arguments(written)
        receiver, _, name = called.rpartition("::")
        values = tuple(
            [self._argument(child) for child in arguments.named_children if child.type != "comment"]
        )
        first = where.start_point.row + 1
        end_point = where.end_point
        last = end_point.row + 1 if end_point.column else max(end_point.row, first)
        span = _new(Span, (first, last))
        return _new(
            CallSite, (called, name, receiver or None, span, values, function, templates, target)
        )

    def _site(self, node: Node, function: str | None) -> CallSite:
        function_node = node.child_by_field_name("function")
        called, templates = self._callee(function_node)
        receiver: str | None = None
        name = called
        if function_node is not None and function_node.type != "identifier":
            if called.endswith(shown.CUT):  # the name ends the callee, past the cut
                end = function_node.end_byte
                tail = compact(self._data[max(function_node.start_byte, end - _TAIL) : end])
                found = _CALLEE.match(tail)
                if found:
                    receiver, name = called, found.group(3)
            elif match := _CALLEE.match(called):
                receiver, name = match.group(1), match.group(3)
        arguments = node.child_by_field_name("arguments")
        values: tuple[Argument, ...] = ()
        if arguments is not None:
            values = tuple(
                [
                    self._argument(child)
                    for child in arguments.named_children
                    if child.type != "comment"
                ]
            )
        # the node's lines, as ``span`` gives them (a valid span: built without its check)
        first = node.start_point.row + 1
        end_point = node.end_point
        last = end_point.row + 1 if end_point.column else max(end_point.row, first)
        where = _new(Span, (first, last))
        target = self._targets.get((node.start_byte, node.end_byte))
        return _new(
            CallSite, (called, name, receiver or None, where, values, function, templates, target)
        )

    def _callee(self, node: Node | None) -> tuple[str, tuple[str, ...]]:
        """The called expression's text, template arguments dropped (`Ice::checkedCast`),
        and the template arguments of its last part."""
        if node is None:
            return "", ()
        if node.type == "identifier":
            return self._data[node.start_byte : node.end_byte].decode("utf-8", "replace"), ()
        written = self._text(node.start_byte, node.end_byte, compact)
        templates: tuple[str, ...] = ()
        if "<" in written and node.type != "parenthesized_expression":
            templates = template_arguments(written)
            written = without_template_arguments(written)
        return written, templates

    def _argument(self, node: Node) -> Argument:
        start, end = node.start_byte, node.end_byte
        if self._opens and self._holds_call(start, end):
            return Argument(self._text(start, end, _argument_text))  # no literal holds a call
        raw = self._data[start:end]
        kind = node.type
        if kind == "identifier":
            return _new(Argument, (raw.decode("utf-8", "replace"), None, False, None))
        written = _argument_text(raw)  # (no long call inside: not cut)
        value: Literal = None
        is_literal = False
        if kind == "concatenated_string":
            parts = [child for child in node.named_children if child.type != "comment"]
            if parts and all(child.type in _STRINGS for child in parts):
                values = [string_value(text(child, self._data)) for child in parts]
                is_literal = all(part is not None for part in values)
                value = "".join(part or "" for part in values) if is_literal else None
        elif kind == "unary_expression" and raw.startswith(b"-"):
            operand = node.child_by_field_name("argument")
            if operand is not None and operand.type == "number_literal":
                is_literal, number = literal("number_literal", text(operand, self._data))
                value = -number if isinstance(number, int | float) else None
        else:
            is_literal, value = literal(kind, raw)
        return _new(Argument, (written, value, is_literal, None))

    def _text(self, start: int, end: int, read: Callable[[bytes], str]) -> str:
        """``read`` of bytes ``start:end``; cut if it holds a long call, and then read by
        growing windows from its start, not whole."""
        if not self._opens or not self._holds_call(start, end):
            return read(self._data[start:end])
        found = self._cut.get((start, read))
        if found is not None and found[0] <= end:
            return found[1]  # the same first window: the same cut
        window = _WINDOW
        while True:
            stop = min(end, start + window)
            written = read(self._data[start:stop])
            if stop == end or len(written) > shown.LIMIT + _MARGIN:
                break
            window *= 2
        if len(written) <= shown.LIMIT:
            return written  # not long once read (blanks and comments dropped)
        written = shown.cut(written)
        self._cut[(start, read)] = (stop, written)
        return written

    def _holds_call(self, start: int, end: int) -> bool:
        """True when bytes ``start:end`` hold a call longer than ``shown.LIMIT`` bytes: its
        argument list opens among them (a call around the range opens its list outside)."""
        opens = self._opens
        index = bisect.bisect_left(opens, start)
        return index < len(opens) and opens[index] < end


def _macro_argument(text: str) -> Argument:
    """A macro's argument as written (a string literal's value read)."""
    if text.startswith('"') and text.endswith('"') and len(text) > 1:
        value = string_value(text.encode("utf-8", "surrogatepass"))
        if value is not None:
            return _new(Argument, (text, value, True, None))
    return _new(Argument, (text, None, False, None))


def _argument_text(raw: bytes) -> str:
    """An argument's text: as written when it has no blanks, else normalized."""
    if _SPACE_OR_COMMENT.search(raw) is None:
        return raw.decode("utf-8", "replace")
    return normal(raw) if b"/" in raw else collapse(raw.decode("utf-8", "replace"))
