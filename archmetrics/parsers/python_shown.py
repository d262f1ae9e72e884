"""Call-site texts for both Python readers, cut as archmetrics/parsers/shown.py says.

Both readers slice the same token list, so both cut at the same place. A text is the tokens
joined by single spaces; it is cut when it is longer than ``shown.LIMIT`` and holds a call
that is itself longer than that (from its callee's first token to its ``)``), which is what
chains and nests of calls are made of. Which calls are long is known only when all are
found, so a reader notes each call as it finds it and turns its token ranges into texts at
the end (:class:`PendingCall`). Inside an f-string, where libcst regenerates each call's
text on its own, both readers use the plain rule instead: a long text holding any call
(a ``(`` after an operand) is cut.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from itertools import accumulate

from archmetrics.facts import Argument, CallSite, Literal, Span
from archmetrics.parsers import shown
from archmetrics.parsers.python_lex import NOT_OPERANDS, Tokens

_FEW = 64  # fewer tokens than this are joined first and measured after
_REACH = shown.LIMIT + 1
_CLOSERS = frozenset(")]}")

Text = str | tuple[int, int]
"""A call site's text: as it stands (a dotted name), or the range of tokens it is made of."""


class Shown:
    """Call-site texts of one token list (which may still grow at its end).

    ``precise``: cut only texts holding a long call, noted with :meth:`note_call` before any
    text is asked for; otherwise texts holding any call."""

    __slots__ = ("_calls", "_cut", "_long", "_precise", "_sorted", "_tokens")

    def __init__(self, tokens: list[str], precise: bool = False):
        self._tokens = tokens
        self._precise = precise
        self._cut: dict[int, str] = {}  # cut texts by first token: a chain's all start alike
        self._calls = [0]  # _calls[i]: call parentheses among tokens[:i]
        self._long: list[int] = []  # the "(" of each long call
        self._sorted = True

    def note_call(self, first: int, open_: int, end: int) -> bool:
        """A call made of tokens ``first:end``, its own ``(`` at ``open_``. True when it is
        long: only then may one of its texts hold a long call and be cut, so only then
        must its texts wait until every call is known."""
        if self._length(first, end) <= shown.LIMIT:
            return False
        if self._precise:
            self._long.append(open_)
            self._sorted = False
        return True

    def text(self, first: int, end: int) -> str:
        """Tokens ``first:end`` joined by single spaces, cut if long and holding a call."""
        tokens = self._tokens
        if end - first < _FEW:
            text = " ".join(tokens[first:end])
            if len(text) <= shown.LIMIT or not self._holds_call(first, end):
                return text
        elif not self._holds_call(first, end):
            return " ".join(tokens[first:end])
        else:
            text = ""
        # a precise text holding a long call is long itself, and its cut is the first LIMIT
        # characters from ``first`` whatever its end: the texts of a chain's calls share one
        found = self._cut.get(first) if self._precise else None
        if found is not None:
            return found
        if not text:  # the first LIMIT + 1 tokens, each cut to LIMIT + 1 characters, decide
            # the result exactly as the whole text would, without building it
            head = tokens[first : min(end, first + _REACH)]
            text = " ".join(token[:_REACH] for token in head)
            if len(text) <= shown.LIMIT:
                return text
        text = shown.cut(text)
        if self._precise:
            self._cut[first] = text
        return text

    def resolve(self, text: Text) -> str:
        return text if isinstance(text, str) else self.text(*text)

    def _holds_call(self, first: int, end: int) -> bool:
        if self._precise:
            if not self._sorted:
                self._long.sort()
                self._sorted = True
            index = bisect.bisect_left(self._long, first)
            return index < len(self._long) and self._long[index] < end
        calls = self._calls
        known = len(calls) - 1
        if end > known:
            tokens = self._tokens
            before = [tokens[known - 1] if known else "", *tokens[known:-1]]
            counts = accumulate(map(_opens_call, before, tokens[known:]), initial=calls[-1])
            next(counts)
            calls.extend(counts)
        return calls[end] > calls[first]

    def _length(self, first: int, end: int) -> int:
        """Characters of tokens ``first:end`` joined by single spaces, or ``LIMIT + 1`` when
        there are more tokens than that (each token and its space are two or more)."""
        if end - first > shown.LIMIT:
            return shown.LIMIT + 1
        return sum(map(len, self._tokens[first:end])) + max(0, end - first - 1)


def _opens_call(before: str, token: str) -> bool:
    """True for a ``(`` after an operand: a call's arguments (``Tokens.opens_call``'s rule,
    without the soft keywords, which never stand inside a call site's texts)."""
    if token != "(" or not before:
        return False
    if before in _CLOSERS:
        return True
    if before in NOT_OPERANDS:
        return False
    head = before[0]
    return head.isalnum() or head in "_'\"" or not head.isascii()


def texts_of(tokens: Tokens) -> Shown:
    """The call-site texts of ``tokens`` (the ``ast`` reader's stream, or a piece of it)."""
    texts = tokens.texts
    if not isinstance(texts, Shown):
        texts = tokens.texts = Shown(tokens.text)
    return texts


@dataclass(slots=True)
class PendingCall:
    """A call site whose texts are still token ranges of ``texts``."""

    texts: Shown
    callee: Text
    name: str | None  # None: the callee's text
    receiver: Text | None
    span: Span
    arguments: tuple[tuple[Text, Literal, bool, str | None], ...]  # text, value, literal?, keyword
    function: str | None
    target: str | None = None

    def site(self) -> CallSite:
        return call_site(
            self.texts,
            self.callee,
            self.name,
            self.receiver,
            self.span,
            self.arguments,
            self.function,
            self.target,
        )


def call_site(
    texts: Shown,
    callee: Text,
    name: str | None,
    receiver: Text | None,
    span: Span,
    arguments: tuple[tuple[Text, Literal, bool, str | None], ...],
    function: str | None,
    target: str | None = None,
) -> CallSite:
    """The call site with these texts made (``name`` None: the callee's text)."""
    resolve = texts.resolve
    callee = resolve(callee)
    made = tuple(
        Argument(resolve(text), value, is_literal, keyword)
        for text, value, is_literal, keyword in arguments
    )
    shown_receiver = None if receiver is None else resolve(receiver)
    name = callee if name is None else name
    return CallSite(callee, name, shown_receiver, span, made, function, (), target)
