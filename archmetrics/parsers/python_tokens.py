"""Token stream of a libcst tree: significant tokens with their lines, comments dropped.

libcst keeps no positions on its nodes; its own ``PositionProvider`` regenerates the code and
records a range for every node, which costs more than the parse. We ride the same code
generation (``CSTNode._codegen`` with a custom ``CodegenState``, the mechanism libcst's
position providers use) but keep only what the metrics need: each significant token, the
line it starts on and the line it ends on. Any node's span and normalized text are then a
slice of these lists, taken between the node's ``before_codegen`` and ``after_codegen``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager, nullcontext
from typing import Any

import libcst as cst
from libcst._nodes.internal import CodegenState

_BLANK = " \t\f\v\\\r\n"  # whitespace tokens, line continuations included
_NULL_CONTEXT: AbstractContextManager[None] = nullcontext()

Hook = Callable[[Any, Any], None]  # (state, node): an unbound method of a subclass


class TokenState(CodegenState):
    """Collects significant tokens while libcst generates code.

    ``toks[i]`` is the i-th significant token, ``starts[i]``/``ends[i]`` its first and last
    line. Comments never enter the list. An f-string is glued into one token (its literal
    text is not to be re-spaced): from its opening quote to its closing one, without the
    parentheses around it. Subclasses observe nodes through ``enter``/``leave`` tables.
    """

    enter: Mapping[type[cst.CSTNode], Hook] = {}
    leave: Mapping[type[cst.CSTNode], Hook] = {}

    def __init__(self) -> None:
        super().__init__(default_indent="    ", default_newline="\n")
        self.line = 1
        self.toks: list[str] = []
        self.starts: list[int] = []
        self.ends: list[int] = []
        self.fstring_depth = 0  # nested FormattedString nodes we are in
        self.fstring_fresh = False  # the outermost f-string's first token is still to come
        self.fstring_open = False  # its closing quote is still to come
        self.part_depth = 0  # > 0 inside an f-string's text or replacement field
        self.skip_depth = 0  # > 0 inside a node whose tokens are not code (a docstring)
        self.code_lines: set[int] = set()
        self.multiline_code: list[tuple[int, int]] = []  # code tokens spanning lines
        self.waiting: list[list[int]] = []  # cells to receive the next token's line

    # -- CodegenState protocol -------------------------------------------------------------
    def add_indent_tokens(self) -> None:
        """Indentation is whitespace, except inside an f-string, whose text is kept as
        written (a replacement field can run over lines)."""
        if self.part_depth:
            self.toks[-1] += "".join(self.indent_tokens)

    def pop_trailing_newline(self) -> None:
        """We keep no raw token list, so there is no trailing newline to drop."""

    def add_token(self, value: str) -> None:
        start = self.line
        if "\n" in value:
            self.line += value.count("\n")
        if self.waiting and value[:1] != "#" and value.strip(_BLANK):
            for cell in self.waiting:
                cell.append(start)
            self.waiting.clear()
        if self.part_depth or (self.fstring_open and self.fstring_depth):
            self.toks[-1] += value  # inside an f-string: its text, or its closing quote
            self.ends[-1] = self.line
            if not self.part_depth:
                self.fstring_open = False
        elif value[:1] == "#" or not value.strip(_BLANK):
            return  # a comment or whitespace
        else:
            if self.fstring_fresh and value != "(":  # not a parenthesis around the f-string
                self.fstring_fresh = False
                self.fstring_open = True
            self.toks.append(value)
            self.starts.append(start)
            self.ends.append(self.line)
        if self.skip_depth:
            return
        if start == self.line:
            self.code_lines.add(start)
        else:
            self.multiline_code.append((start, self.line))

    def before_codegen(self, node: cst.CSTNode) -> None:
        kind = type(node)
        if kind is cst.FormattedString:
            if not self.fstring_depth:
                self.fstring_fresh = True
            self.fstring_depth += 1
        elif kind is cst.FormattedStringText or kind is cst.FormattedStringExpression:
            self.part_depth += 1
        hook = self.enter.get(kind)
        if hook is not None:
            hook(self, node)

    def after_codegen(self, node: cst.CSTNode) -> None:
        kind = type(node)
        hook = self.leave.get(kind)
        if hook is not None:
            hook(self, node)
        if kind is cst.FormattedString:
            self.fstring_depth -= 1
        elif kind is cst.FormattedStringText or kind is cst.FormattedStringExpression:
            self.part_depth -= 1

    def record_syntactic_position(  # type: ignore[override]  # any context manager will do
        self,
        node: cst.CSTNode,
        *,
        start_node: cst.CSTNode | None = None,
        end_node: cst.CSTNode | None = None,
    ) -> AbstractContextManager[None]:
        self.syntactic_start(node)
        return _NULL_CONTEXT

    def syntactic_start(self, node: cst.CSTNode) -> None:
        """Called where a node's own syntax begins (after its comments and decorators)."""

    # -- reading the stream -----------------------------------------------------------------
    def next_line(self) -> list[int]:
        """A cell that receives the line of the next significant token when it is emitted.

        Inside an f-string the tokens are glued into one, so a token index cannot give the
        line of a construct there; this can."""
        cell: list[int] = []
        self.waiting.append(cell)
        return cell

    def text(self, first: int, last: int) -> str:
        """Normalized text of tokens ``first:last``: joined by single spaces."""
        return " ".join(self.toks[first:last])

    def first_line(self, index: int) -> int:
        """Line of token ``index`` (or of the last token when the node emitted none)."""
        if index < len(self.starts):
            return self.starts[index]
        return self.ends[-1] if self.ends else 1

    def last_line(self, end: int) -> int:
        """Last line of the tokens before index ``end``."""
        return self.ends[end - 1] if end > 0 else 1

    def sloc(self, source: str) -> int:
        """Lines holding code: those of one-line tokens, and non-blank lines of long tokens."""
        counted = set(self.code_lines)
        lines = source.split("\n") if self.multiline_code else []
        for start, end in self.multiline_code:
            counted.update(n for n in range(start, end + 1) if lines[n - 1].strip())
        return len(counted)


def normalized(node: cst.CSTNode) -> str:
    """A node's normalized text on its own (tokens, comments dropped, single spaces)."""
    state = TokenState()
    node._codegen(state)
    return state.text(0, len(state.toks))


def shown_text(node: cst.CSTNode, star: str = "") -> str:
    """A node's normalized text as a call site shows it (python_shown.py), after the
    ``*`` or ``**`` of a starred argument, if any."""
    from archmetrics.parsers.python_shown import Shown

    state = TokenState()
    if star:
        state.toks.append(star)
    node._codegen(state)
    return Shown(state.toks).text(0, len(state.toks))
