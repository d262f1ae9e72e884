"""Byte-level text work for C and C++: token normal forms, literal values, SLOC.

All of it runs as regular expressions over byte ranges that tree-sitter hands us, so no
Python loop ever visits the tokens one by one.
"""

from __future__ import annotations

import re
from collections.abc import Iterable

from archmetrics.facts import Literal

_TOKEN = re.compile(
    rb"\d(?:[eEpP][-+]|'?[\w.])*"  # preprocessing number (first: the commonest tokens)
    rb"""|\w+(?:"(?:\\.|[^"\\\n])*"?|'(?:\\.|[^'\\\n])*'?)?"""  # word, or L"..", u8'..'
    rb'|"(?:\\.|[^"\\\n])*"?'  # string
    rb"|'(?:\\.|[^'\\\n])*'?"  # character
    rb"|/\*.*?(?:\*/|\Z)|//(?:\\\r?\n|[^\n])*|\\\r?\n"  # comments, continuations: dropped
    rb"|\#[ \t]*\w+"  # preprocessor directive name
    rb"|\.\d(?:[eEpP][-+]|'?[\w.])*"
    rb"|->\*|<<=|>>=|<=>|\.\.\.|::|->|\+\+|--|<<|>>|<=|>=|==|!=|&&|\|\||[-+*/%&|^]=|\#\#|\.\*"
    rb"|\S",
    re.DOTALL,
)
_RAW_STRING = re.compile(rb'(?:u8|[uUL])?R"([^(\s"]{0,16})\((.*?)\)\1"', re.DOTALL)
_DROPPED = (b"/*", b"//", b"\\\n", b"\\\r")
_SPECIAL = re.compile(rb'/[/*]|\\\r?\n|R"|\#[ \t]')
_DIRECTIVE_SPACE = re.compile(rb"^#[ \t]+")
_WORD = re.compile(rb"\w")


def _tokens_with_raw_strings(data: bytes) -> list[bytes]:
    found: list[bytes] = []
    position = 0
    for match in _RAW_STRING.finditer(data):
        found.extend(_TOKEN.findall(data, position, match.start()))
        found.append(match.group())
        position = match.end()
    found.extend(_TOKEN.findall(data, position))
    return found


def tokens(data: bytes) -> list[bytes]:
    """The tokens of ``data`` with comments and line continuations dropped."""
    if _SPECIAL.search(data) is None:  # the common case: one regex pass, nothing to clean
        return _TOKEN.findall(data)
    found = _tokens_with_raw_strings(data) if b'R"' in data else _TOKEN.findall(data)
    found = [token for token in found if not token.startswith(_DROPPED)]
    if b"# " in data or b"#\t" in data:
        found = [_DIRECTIVE_SPACE.sub(b"#", token) for token in found]
    return found


def normal(data: bytes) -> str:
    """Tokens joined by single spaces: the statement's form that survives reformatting."""
    return b" ".join(tokens(data)).decode("utf-8", "replace")


_WORD_GAP = re.compile(rb"(?<=\w)\0(?=\w)")


def compact(data: bytes) -> str:
    """Tokens joined with no spaces except between two words: `p->send`, `operator new`.

    One join and one substitution, not a loop over the tokens (a callee can be a chain of
    thousands of calls): the tokens are joined by NUL, and a NUL between two word
    characters becomes a space, the others nothing."""
    found = tokens(data)
    if len(found) == 1:
        return found[0].decode("utf-8", "replace")
    joined = b"\0".join(found)
    if joined.count(b"\0") == len(found) - 1:  # no NUL inside a token
        return _WORD_GAP.sub(b" ", joined).replace(b"\0", b"").decode("utf-8", "replace")
    return compact_slowly(found)


def compact_slowly(found: list[bytes]) -> str:
    """``compact`` of these tokens, one by one."""
    parts: list[bytes] = []
    previous_word = False
    for token in found:
        word = bool(_WORD.match(token[-1:])) if token else False
        starts_word = bool(_WORD.match(token[:1]))
        if previous_word and starts_word:
            parts.append(b" ")
        parts.append(token)
        previous_word = word
    return b"".join(parts).decode("utf-8", "replace")


_ESCAPE = re.compile(r"\\(x[0-9a-fA-F]+|[0-7]{1,3}|u[0-9a-fA-F]{4}|U[0-9a-fA-F]{8}|.)", re.DOTALL)
_SIMPLE_ESCAPES = {
    "n": "\n",
    "t": "\t",
    "r": "\r",
    "a": "\a",
    "b": "\b",
    "f": "\f",
    "v": "\v",
    "\n": "",
}


def _unescape_one(match: re.Match[str]) -> str:
    body = match.group(1)
    if body[0] in "xuU" and len(body) > 1:
        return chr(min(int(body[1:], 16), 0x10FFFF))
    if body[0] in "01234567":
        return chr(int(body, 8))
    return _SIMPLE_ESCAPES.get(body, body)


def unescape(text: str) -> str:
    """C escape sequences decoded simply (``\\n``, ``\\x41``, ``\\101``, ``\\u00e9``)."""
    return _ESCAPE.sub(_unescape_one, text) if "\\" in text else text


def string_value(data: bytes) -> str | None:
    """The value of one string or character literal (prefix and quotes dropped)."""
    text = data.decode("utf-8", "replace")
    raw = re.match(r'(?:u8|[uUL])?R"([^(]*)\((.*)\)\1"\Z', text, re.DOTALL)
    if raw:
        return raw.group(2)
    quote = '"' if '"' in text else "'"
    first, last = text.find(quote), text.rfind(quote)
    if first < 0 or last <= first:
        return None
    return unescape(text[first + 1 : last])


_INT = re.compile(r"(0[xX][0-9a-fA-F]+|0[bB][01]+|0[0-7]*|[1-9][0-9]*)(?:[uU]|[lL]{1,2}|[zZ])*\Z")


def number_value(data: bytes) -> int | float | None:
    """The value of a number literal (hex, octal, binary, float, suffixes), None if unknown."""
    text = data.decode("ascii", "replace").replace("'", "")
    sign = -1 if text.startswith("-") else 1
    text = text.lstrip("-+")
    match = _INT.match(text)
    if match:
        digits = match.group(1)
        if digits[:2].lower() in ("0x", "0b"):
            return sign * int(digits, 0)
        return sign * (int(digits, 8) if digits.startswith("0") else int(digits))
    body = text.rstrip("fFlL")
    try:
        if body[:2].lower() == "0x":
            return sign * float.fromhex(body)
        return sign * float(body)
    except ValueError:
        return None


def literal(kind: str, data: bytes) -> tuple[bool, Literal]:
    """(is it a literal, its value) for a leaf-ish expression node of type ``kind``."""
    if kind in ("string_literal", "raw_string_literal", "char_literal"):
        value = string_value(data)
        return value is not None, value
    if kind == "number_literal":
        number = number_value(data)
        return number is not None, number
    if kind in ("true", "false"):
        return True, kind == "true"
    if kind in ("null", "nullptr"):
        return True, None
    return False, None


_BLANK = bytes(byte if byte in b"\r\n" else 0x20 for byte in range(256))


def blank(out: bytearray, start: int, end: int) -> None:
    """Overwrite ``out[start:end]`` with spaces, line ends kept (every offset and line stays)."""
    out[start:end] = bytes(out[start:end]).translate(_BLANK)


def blank_spans(data: bytes, spans: list[tuple[int, int]]) -> bytes:
    """``data`` with ``spans`` overwritten by spaces, line ends kept."""
    out = bytearray(data)
    for start, end in spans:
        blank(out, start, end)
    return bytes(out)


def whole_lines(data: bytes, start: int, end: int) -> tuple[int, int]:
    """``[start, end)`` grown to whole lines (the last one's newline excluded)."""
    after = data.find(b"\n", end)
    return data.rfind(b"\n", 0, start) + 1, len(data) if after < 0 else after


def blank_comments(data: bytes, comments: Iterable[tuple[int, int]]) -> bytes:
    """``data`` with comments and line continuations turned to spaces; offsets and lines kept."""
    parts: list[bytes] = []
    position = 0
    for start, end in comments:
        if start < position:
            continue
        parts.append(data[position:start])
        parts.append(data[start:end].translate(_BLANK))
        position = end
    parts.append(data[position:])
    return b"".join(parts).replace(b"\\\n", b" \n").replace(b"\\\r\n", b"  \n")


def sloc(clean: bytes) -> int:
    """Physical lines holding at least one character that is not blank (comments blanked)."""
    lines = clean.translate(None, b" \t\r\f\v").split(b"\n")
    return len(lines) - lines.count(b"")


# The tokenizer for many statements at once: separated by NUL, which only `\S` may match.
# White space is skipped by one possessive run and the commonest tokens come first (words,
# then brackets and separators): the alternatives are tried at token starts only.
_BATCH_TOKEN = re.compile(
    rb"\s*+("
    rb"""[^\W\d]\w*+(?:"(?:\\[^\0]|[^"\\\n\0])*+"?|'(?:\\[^\0]|[^'\\\n\0])*+'?)?"""
    rb"|[(),;{}\[\]]"
    rb"|\d(?:[eEpP][-+]|'?[\w.])*+"
    rb'|"(?:\\[^\0]|[^"\\\n\0])*+"?'
    rb"|'(?:\\[^\0]|[^'\\\n\0])*+'?"
    rb"|\#[ \t]*+\w+"
    rb"|\.\d(?:[eEpP][-+]|'?[\w.])*+"
    rb"|->\*|<<=|>>=|<=>|\.\.\.|::|->|\+\+|--|<<|>>|<=|>=|==|!=|&&|\|\||[-+*/%&|^]=|\#\#|\.\*"
    rb"|\S)"
)


def normal_many(pieces: list[bytes]) -> list[str]:
    """``normal`` of each piece (comments already blanked), in one regex pass for all of
    them. A file repeats many of its statements (``break;``, ``return 0;``, ``i++;``: on
    numpy's C/C++, 45% of the pieces of a file are another's copy): each distinct piece is
    read once."""
    distinct = list(dict.fromkeys(pieces))
    if len(distinct) == len(pieces):
        return _normal_each(pieces)
    texts = dict(zip(distinct, _normal_each(distinct), strict=True))
    return [texts[piece] for piece in pieces]


def _normal_each(pieces: list[bytes]) -> list[str]:
    """``normal`` of each piece, in one regex pass for all of them."""
    special = [index for index, piece in enumerate(pieces) if b'R"' in piece]
    batch = list(pieces)
    for index in special:
        batch[index] = b""
    joined = b"\0".join(batch)
    if joined.count(b"\0") != len(pieces) - 1:
        return [normal(piece) for piece in pieces]  # NUL bytes in the source itself
    texts = b" ".join(_BATCH_TOKEN.findall(joined)).decode("utf-8", "replace").split("\0")
    if len(texts) != len(pieces):
        return [normal(piece) for piece in pieces]
    found = [text.strip() for text in texts]
    for index in special:
        found[index] = normal(pieces[index])
    return found
