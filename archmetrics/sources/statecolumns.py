"""The checked columns of a tree state's cache record (sources/statecodec.py): each list read
back is checked whole, its type and range, so that reading a numpy-sized state is a few
list checks in C; anything else is a :class:`~archmetrics.sources.codec.CodecError`."""

from __future__ import annotations

import json
from collections.abc import Iterator, Sequence
from itertools import accumulate
from typing import Any

from archmetrics.sources.codec import CodecError


def loads(text: bytes) -> Any:
    import orjson

    try:
        return orjson.loads(text)
    except orjson.JSONDecodeError:  # an escaped lone surrogate: orjson refuses it, json reads it
        return json.loads(text)


def bad(what: str) -> CodecError:
    return CodecError(f"a tree state with {what}")


def ints(value: object, low: int, high: int, count: int | None = None) -> list[int]:
    """A list of integers in [low, high) (``count`` of them, if given)."""
    if not isinstance(value, list) or not set(map(type, value)) <= {int}:
        raise bad("a list that is not integers")
    if value and (min(value) < low or max(value) >= high):
        raise bad("a number out of range")
    if count is not None and len(value) != count:
        raise bad("columns of different lengths")
    return value


def texts(value: object, count: int | None = None, none: bool = False) -> list[Any]:
    """A list of texts (``none``: or nulls)."""
    allowed = {str, type(None)} if none else {str}
    if not isinstance(value, list) or not set(map(type, value)) <= allowed:
        raise bad("a list that is not texts")
    if count is not None and len(value) != count:
        raise bad("columns of different lengths")
    return value


def lists(value: object, count: int) -> list[Any]:
    if not isinstance(value, list) or len(value) != count:
        raise bad("a malformed section")
    return value


def split(flat: Sequence[Any], sizes: Sequence[int]) -> Iterator[Sequence[Any]]:
    if sum(sizes) != len(flat):
        raise bad("lengths that do not add up")
    start = 0
    for end in accumulate(sizes):
        yield flat[start:end]
        start = end


def lists_of(value: object) -> list[Any]:
    if not isinstance(value, list) or not all(isinstance(v, list) for v in value):
        raise bad("a malformed section")
    return value
