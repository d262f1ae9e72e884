"""Reading what a peer sent: one JSON frame in, a checked object out, or InvalidMessage.

Every socket that receives from peers (provider inboxes, consumer replies, the location
service, federation peers, subscribers) goes through :func:`load_object`, so a frame that is
too large, not UTF-8, not JSON, nested too deeply or not an object is refused the same way
everywhere, and never raises anything but :class:`~robosoa.errors.InvalidMessage`.
"""

from __future__ import annotations

import json
import math
from typing import Any

import orjson

from robosoa.errors import InvalidMessage

MAX_MESSAGE = 64 * 1024 * 1024  # bytes per frame: ZeroMQ MAXMSGSIZE and the decoder's check
MAX_DEPTH = 64  # nesting of JSON objects and arrays in one frame (the envelope counts as 1)


class LimitExceeded(InvalidMessage):
    """A frame is larger or nested deeper than the limits allow."""


def _no_constant(name: str) -> Any:
    raise ValueError(f"{name} is not a JSON number")


def _finite(text: str) -> float:
    value = float(text)
    if not math.isfinite(value):
        raise ValueError(f"{text[:20]} is out of range")
    return value


# built once: json.loads(..., parse_constant=...) would build a decoder per call
_DECODE = json.JSONDecoder(parse_constant=_no_constant, parse_float=_finite).decode
_ZEROS = bytes.maketrans(b"123456789", b"000000000")  # every ASCII digit becomes "0"
_LONG_RUN = b"0" * 19  # 19 digits in a row: maybe an integer orjson cannot keep exact
_UNREAD = object()


def long_number(raw: bytes) -> bool:
    """Whether ``raw`` holds 19 or more ASCII digits in a row (``re`` ``[0-9]{19}``): every
    digit turned into "0" by ``bytes.translate``, then one substring search, both in C;
    about a fifth of the time of the regular expression on an envelope, which tries its
    character class at every byte."""
    return _LONG_RUN in raw.translate(_ZEROS)


def depth(value: Any, limit: int) -> int:
    """Nesting depth of objects and arrays in ``value``, counted up to ``limit + 1``."""
    deepest = 0
    stack: list[tuple[Any, int]] = [(value, 1)]
    while stack:
        item, level = stack.pop()
        if isinstance(item, dict):
            children: Any = item.values()
        elif isinstance(item, list):
            children = item
        else:
            continue
        deepest = max(deepest, level)
        if deepest > limit:
            return deepest
        stack.extend((child, level + 1) for child in children)
    return deepest


def _orjson(raw: bytes) -> Any:
    """orjson's reading, or ``_UNREAD`` where it refuses (json then reads it and says why);
    a plain ``try``, not ``contextlib.suppress``, which builds an object per call."""
    try:
        return orjson.loads(raw)
    except orjson.JSONDecodeError:
        return _UNREAD


def _standard(raw: bytes | str, max_depth: int) -> Any:
    """The reference reading (json from the standard library, configured as above)."""
    try:
        text = raw.decode() if isinstance(raw, bytes) else raw
        return _DECODE(text)
    except RecursionError:
        raise LimitExceeded(f"message is nested deeper than {max_depth} levels") from None
    except (UnicodeDecodeError, ValueError) as exc:
        raise InvalidMessage(f"message is not valid JSON: {exc}") from None


def load_json(raw: bytes | str, max_bytes: int = MAX_MESSAGE, max_depth: int = MAX_DEPTH,
              fast: bool = True) -> Any:
    """Parse untrusted JSON within the limits; raises InvalidMessage naming what is wrong.

    NaN, Infinity and numbers that overflow a float are refused (the encoder never writes
    them either). Bytes are read by orjson (in C, several times faster) when it is sure to
    give what json gives: not when an integer of 19 or more digits may be there (orjson
    makes a float of one past 64 bits); anything orjson refuses is read again by json, so
    what is accepted, what it becomes and every error are json's (``fast=False`` reads with
    json only; tests/robosoa/test_wire.py holds the two to each other).
    """
    if len(raw) > max_bytes:
        raise LimitExceeded(f"message of {len(raw)} bytes exceeds the limit of {max_bytes}")
    data: Any = _UNREAD
    if fast and isinstance(raw, bytes) and not long_number(raw):
        data = _orjson(raw)
    if data is _UNREAD:
        data = _standard(raw, max_depth)
    if isinstance(raw, bytes):  # cheap bound first: depth <= number of opening brackets
        brackets = raw.count(b"[") + raw.count(b"{")
    else:
        brackets = raw.count("[") + raw.count("{")
    if brackets > max_depth and depth(data, max_depth) > max_depth:
        raise LimitExceeded(f"message is nested deeper than {max_depth} levels")
    return data


def load_object(raw: bytes | str, max_bytes: int = MAX_MESSAGE,
                max_depth: int = MAX_DEPTH) -> dict[str, Any]:
    """Like :func:`load_json`, and the result must be a JSON object."""
    data = load_json(raw, max_bytes, max_depth)
    if type(data) is not dict:
        raise InvalidMessage("message is not a JSON object")
    return data
