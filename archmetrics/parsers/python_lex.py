"""Token stream of Python source for the ``ast`` reader: significant tokens, lines, offsets.

The same stream the libcst reader builds from libcst's code generation (python_tokens.py),
here from the standard library's ``tokenize``: each significant token's text, the line it
starts on and the line it ends on; comments, newlines and indentation dropped; an f-string
(or t-string) is one token holding its exact source text, as libcst's walk glues it. Tokens
are found by character offset, so an ``ast`` node's position (line and UTF-8 column) maps to
the token it starts at and the one after it ends.
"""

from __future__ import annotations

import io
import keyword
import re
import sys
import tokenize
from bisect import bisect_left, bisect_right
from itertools import accumulate, chain, compress, count, repeat
from operator import add, ne

_SKIPPED = frozenset(
    {
        tokenize.NEWLINE,
        tokenize.NL,
        tokenize.COMMENT,
        tokenize.INDENT,
        tokenize.DEDENT,
        tokenize.ENDMARKER,
    }
)
# Python 3.12 splits f-strings into pieces (3.14 t-strings too); they are glued back here.
_GLUE_START = frozenset(getattr(tokenize, n, -1) for n in ("FSTRING_START", "TSTRING_START"))
_GLUE_END = frozenset(getattr(tokenize, n, -1) for n in ("FSTRING_END", "TSTRING_END"))
_OPENERS = {"(": ")", "[": "]", "{": "}"}
_CLOSERS = frozenset(_OPENERS.values())
# A "(" after one of these opens a call's arguments, not parentheses around an expression.
NOT_OPERANDS = frozenset(keyword.kwlist) - {"True", "False", "None"}


class Unreadable(Exception):
    """The token stream does not line up with the tree; the caller reads the file another way."""


class Tokens:
    """Significant tokens of one piece of source.

    ``text[i]``, ``starts[i]``/``ends[i]`` (first and last line) and ``offsets[i]`` (character
    offset of its first character in the piece) describe token ``i``; ``closing[i]`` is the
    index of the bracket that closes the opening bracket ``i``. A piece that is not a whole
    file (an f-string's replacement field, read on its own) has ``base``, its offset in the
    file, and ``first_line``, the file's line it starts on.
    """

    __slots__ = (
        "_at_end",
        "_at_start",
        "base",
        "closing",
        "ends",
        "multiline",
        "offsets",
        "soft_keywords",
        "starts",
        "statement_parens",
        "text",
        "texts",
    )

    def __init__(self, source: str, base: int = 0, first_line: int = 1):
        self.text: list[str] = []
        self.starts: list[int] = []
        self.ends: list[int] = []
        self.offsets: list[int] = []
        self.multiline: list[int] = []  # tokens that span lines (strings)
        self.closing: dict[int, int] = {}
        self.soft_keywords: set[int] = set()  # "match" and "case" where they are keywords
        self.statement_parens: set[int] = set()  # "(" of a statement: `with (a, b):`
        # call-site texts (python_shown.Shown), made and typed there when first asked for
        self.texts: object = None
        self.base = base
        _read(self, source, first_line)
        self._at_start = dict(zip(self.offsets, count()))
        self._at_end = dict(zip(map(add, self.offsets, map(len, self.text)), count(1)))

    def __len__(self) -> int:
        return len(self.text)

    def at(self, offset: int) -> int:
        """Index of the token starting at ``offset`` (a file offset); -1 if none does."""
        return self._at_start.get(offset - self.base, -1)

    def after(self, offset: int) -> int:
        """Index of the first token starting at or after file offset ``offset`` (for a node
        ending there: one past its last token)."""
        found = self._at_end.get(offset - self.base)
        return found if found is not None else bisect_left(self.offsets, offset - self.base)

    def before(self, index: int, word: str) -> int:
        """Index of the nearest token ``word`` before token ``index``."""
        index -= 1
        while self.text[index] != word:
            index -= 1
        return index

    def colon(self, index: int) -> int:
        """The ``:`` that ends a compound statement's header, from token ``index`` on (one
        inside brackets, of a slice or a lambda, is not it)."""
        text, depth = self.text, 0
        while text[index] != ":" or depth > 0:
            token = text[index]
            depth += 1 if token in _OPENERS else -1 if token in _CLOSERS else 0
            index += 1
        return index

    def joined(self, first: int, end: int) -> str:
        """Normalized text of tokens ``first:end``: joined by single spaces."""
        return " ".join(self.text[first:end])

    def opens_call(self, index: int) -> bool:
        """True when the ``(`` at ``index`` follows an operand: it opens call arguments (or a
        class's bases), so it does not belong to the expression inside it."""
        if index == 0:
            return False
        before = self.text[index - 1]
        if before in _CLOSERS:
            return True
        if index - 1 in self.soft_keywords or before in NOT_OPERANDS:
            return False
        head = before[0]
        return head.isalnum() or head in "_'\"" or not head.isascii()

    def widen(self, first: int, end: int) -> tuple[int, int]:
        """Tokens ``first:end`` of an expression, widened over the parentheses around it
        (libcst makes them the node's own ``lpar``/``rpar``; ``ast`` leaves them out)."""
        text, closing = self.text, self.closing
        while (
            first > 0
            and end < len(text)
            and text[first - 1] == "("
            and closing.get(first - 1) == end
            and first - 1 not in self.statement_parens
            and not self.opens_call(first - 1)
        ):
            first -= 1
            end += 1
        return first, end


# Before Python 3.12 an f-string cannot hold its own quote, so every string, f-strings
# included, is one regular token, and one regular expression over the whole source finds the
# same tokens as ``tokenize`` (the tests check it on real code), with the per-token work done
# in C: ``findall`` splits the source into (blanks, token) pairs, and offsets and lines are
# running sums of their lengths and newlines.
_STRING = (
    r"(?:[rR][bBfF]?|[bBfF][rR]?|[uU])?"
    r"(?:'''[^'\\]*(?:(?:\\.|'(?!''))[^'\\]*)*'''"
    r'|"""[^"\\]*(?:(?:\\.|"(?!""))[^"\\]*)*"""'
    r"|'[^\n'\\]*(?:\\.[^\n'\\]*)*'"
    r'|"[^\n"\\]*(?:\\.[^\n"\\]*)*")'
)
_BLANKS = r"(?:[ \t\f\n]|\\\n|#[^\n]*)*+"  # blanks, newlines, continuations, comments
# Tried in order of frequency: names (not a string's prefix), brackets and commas, numbers,
# the other operators (longest first where one is the start of another), strings.
_NAME = r"(?![rRbBfFuU]{1,2}['\"])[^\W\d]\w*"
_NUMBER = "(?=[0-9.])" + re.sub(r"(?<!\\)\((?!\?)", "(?:", tokenize.Number)  # groups dropped
_OPERATOR = r"\.\.\.|\.|:=?|->|\*\*=?|//=?|<<=?|>>=?|[-+*/%&|^=<>!@]=?|[;{}~]"
LEXEME = re.compile(
    f"({_BLANKS})({_NAME}|[()\\[\\],]|{_NUMBER}|{_OPERATOR}|(?=[\\'\"rRbBfFuU]){_STRING}|\\Z)",
    re.DOTALL,
)
_ONE_REGEX = sys.version_info < (3, 12)
_BRACKETS = frozenset("()[]{}")


def _read(tokens: Tokens, source: str, first_line: int) -> None:
    """Fill ``tokens`` from ``source`` (lines numbered from ``first_line``)."""
    if not (_ONE_REGEX and _scan(tokens, source, first_line)):
        _read_tokenize(tokens, source, first_line)
    _finish(tokens)


def _finish(tokens: Tokens) -> None:
    """What follows from the tokens read: which span lines, which bracket closes which."""
    text = tokens.text
    tokens.multiline = list(compress(count(), map(ne, tokens.starts, tokens.ends)))
    opened: list[int] = []
    for index in compress(count(), map(_BRACKETS.__contains__, text)):
        if text[index] in _OPENERS:
            opened.append(index)
        elif opened:
            tokens.closing[opened.pop()] = index


def _scan(tokens: Tokens, source: str, first_line: int) -> bool:
    """``_read`` by one regular expression; False, ``tokens`` untouched, where it meets
    something it does not know (an identifier character outside ``\\w``, say)."""
    pieces = LEXEME.findall(source)
    trailing = 0  # blanks after the last token (matched before the end, \Z)
    while pieces and not pieces[-1][1]:
        trailing += len(pieces.pop()[0])
    flat = list(chain.from_iterable(pieces))
    lengths = list(accumulate(map(len, flat)))
    if (lengths[-1] if lengths else 0) + trailing != len(source):
        return False  # a character no pattern matched was skipped
    lines = list(accumulate(map(str.count, flat, repeat("\n")), initial=first_line))
    tokens.text = flat[1::2]
    tokens.offsets = lengths[0::2]
    tokens.starts = lines[1::2]
    tokens.ends = lines[2::2]
    return True


def _read_tokenize(tokens: Tokens, source: str, first_line: int) -> None:
    """``_read`` by the standard library's tokenizer."""
    line_offsets = [0]
    for line in source.split("\n"):
        line_offsets.append(line_offsets[-1] + len(line) + 1)
    shift = first_line - 1
    offsets = tokens.offsets
    glue_depth = 0
    glue_from = (0, 0)
    try:
        for kind, value, start, end, _ in tokenize.generate_tokens(io.StringIO(source).readline):
            if glue_depth:
                if kind in _GLUE_START:
                    glue_depth += 1
                elif kind in _GLUE_END:
                    glue_depth -= 1
                    if not glue_depth:
                        offset = line_offsets[glue_from[0] - 1] + glue_from[1]
                        stop = line_offsets[end[0] - 1] + end[1]
                        _add(tokens, source[offset:stop], glue_from[0] + shift, end[0] + shift)
                        offsets.append(offset)
                continue
            if kind in _SKIPPED:
                continue
            if kind in _GLUE_START:
                glue_depth, glue_from = 1, start
                continue
            if kind == tokenize.ERRORTOKEN:
                if value.isspace():
                    continue
                raise Unreadable(f"unexpected token {value!r} at line {start[0] + shift}")
            _add(tokens, value, start[0] + shift, end[0] + shift)
            offsets.append(line_offsets[start[0] - 1] + start[1])
    except (tokenize.TokenError, SyntaxError) as error:
        raise Unreadable(str(error)) from error


def _add(tokens: Tokens, value: str, start: int, end: int) -> None:
    tokens.text.append(value)
    tokens.starts.append(start)
    tokens.ends.append(end)


class LineOffsets:
    """Converts ``ast`` positions (1-based line, UTF-8 byte column) to character offsets."""

    __slots__ = ("_ascii", "_lines", "_starts")

    def __init__(self, source: str):
        self._lines = source.split("\n")
        self._starts = [0]
        for line in self._lines:
            self._starts.append(self._starts[-1] + len(line) + 1)
        self._ascii = source.isascii()

    def __call__(self, line: int, column: int) -> int:
        if not self._ascii:
            text = self._lines[line - 1]
            if not text.isascii():
                column = len(text.encode("utf-8")[:column].decode("utf-8", "replace"))
        return self._starts[line - 1] + column

    def line_of(self, offset: int) -> int:
        """The 1-based line holding character offset ``offset``."""
        return bisect_right(self._starts, offset)

    def line_text(self, line: int) -> str:
        return self._lines[line - 1]
