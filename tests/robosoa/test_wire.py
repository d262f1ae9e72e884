"""robosoa.wire: every frame a peer sends is parsed within size and depth limits."""

from __future__ import annotations

import json
import re

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from robosoa.errors import InvalidMessage
from robosoa.message import decode
from robosoa.wire import MAX_DEPTH, LimitExceeded, depth, load_json, load_object, long_number


def nested(levels: int, inner: str = "1") -> bytes:
    return ("[" * levels + inner + "]" * levels).encode()


@pytest.mark.parametrize("levels", [MAX_DEPTH + 1, 5_000, 200_000])
def test_deep_nesting_is_refused_not_a_recursion_error(levels: int) -> None:
    with pytest.raises(LimitExceeded, match=f"deeper than {MAX_DEPTH}"):
        load_json(nested(levels))
    with pytest.raises(InvalidMessage):
        decode(b'{"kind": "request", "payload": {"x": ' + nested(levels) + b"}}")


def test_the_depth_limit_is_exact() -> None:
    assert load_json(nested(MAX_DEPTH - 1, "{}")) is not None  # MAX_DEPTH levels in all
    with pytest.raises(LimitExceeded):
        load_json(nested(MAX_DEPTH, "{}"))
    assert load_json(b'"[[[[[[[[[[' + b"[" * 100 + b'"') == "[" * 110  # brackets in a string
    assert load_json(nested(3), max_depth=3) == [[[1]]]
    with pytest.raises(LimitExceeded):
        load_json(nested(4), max_depth=3)


def test_size_is_checked_before_parsing() -> None:
    frame = json.dumps({"x": "y" * 1000}).encode()
    assert load_object(frame, max_bytes=len(frame)) == {"x": "y" * 1000}
    with pytest.raises(LimitExceeded, match=f"{len(frame)} bytes exceeds the limit"):
        load_object(frame, max_bytes=len(frame) - 1)


@pytest.mark.parametrize("raw", [b"NaN", b"Infinity", b"-Infinity", b"1e999", b"[1e400]",
                                 b'{"t": -1e309}'])
def test_non_finite_numbers_are_refused(raw: bytes) -> None:
    with pytest.raises(InvalidMessage, match="not valid JSON"):
        load_json(raw)


@pytest.mark.parametrize(("raw", "reason"), [
    (b"\xff\xfe", "not valid JSON"), (b"[1]", "not a JSON object"), (b"", "not valid JSON"),
    (b'{"kind": "request", "timestamp": 1' + b"0" * 400 + b"}", "timestamp is out of range"),
])
def test_bad_frames_raise_only_invalid_message(raw: bytes, reason: str) -> None:
    with pytest.raises(InvalidMessage, match=reason):
        decode(raw)


def test_depth_counts_objects_and_arrays() -> None:
    assert depth({"a": [{"b": 1}], "c": 2}, 10) == 3
    assert depth(5, 10) == 0
    assert depth([[[[[]]]]], 2) == 3  # stops counting past the limit


@settings(max_examples=200, deadline=None, derandomize=True, database=None)
@given(st.recursive(st.none() | st.integers() | st.text(max_size=5),
                    lambda inner: st.lists(inner, max_size=3)
                    | st.dictionaries(st.text(max_size=3), inner, max_size=3),
                    max_leaves=40),
       st.integers(1, 12))
def test_accepts_exactly_what_fits_the_limit(value: object, limit: int) -> None:
    raw = json.dumps(value).encode()
    if depth(value, limit) <= limit:
        assert load_json(raw, max_depth=limit) == value
    else:
        with pytest.raises(LimitExceeded):
            load_json(raw, max_depth=limit)


def _both(raw: bytes) -> tuple[object, object]:
    """What the fast reading and json's own give for ``raw`` (or the error's type)."""
    out: list[object] = []
    for fast in (True, False):
        try:
            out.append(("ok", load_json(raw, fast=fast)))
        except InvalidMessage as exc:
            out.append(("error", type(exc).__name__, str(exc)))
    return out[0], out[1]


JSON_VALUES = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False)
    | st.text(max_size=20),
    lambda inner: st.lists(inner, max_size=5) | st.dictionaries(st.text(max_size=8), inner,
                                                                max_size=5),
    max_leaves=30)


@settings(max_examples=300, deadline=None)
@given(JSON_VALUES)
def test_the_fast_reading_gives_what_json_gives(value: object) -> None:
    raw = json.dumps(value).encode()  # big integers, infinities spelt as json spells them
    fast, standard = _both(raw)
    assert fast == standard


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=60) | st.text(max_size=40).map(str.encode))
def test_the_fast_reading_refuses_what_json_refuses(raw: bytes) -> None:
    fast, standard = _both(raw)
    assert fast == standard


@pytest.mark.parametrize("raw", [b'{"a": 123456789012345678901234567890}', b'{"a": 1e400}',
                                 b'{"a": "\\ud800"}', b'{"a": -9223372036854775809}',
                                 b"\xef\xbb\xbf{}", b'{"a": NaN}', b"[" * 2000 + b"]" * 2000])
def test_where_orjson_and_json_differ_json_decides(raw: bytes) -> None:
    fast, standard = _both(raw)
    assert fast == standard


@settings(max_examples=400, deadline=None)
@given(st.lists(st.sampled_from([b"0", b"7", b"9", b"12345678", b"1234567890", b"/", b":",
                                 b".", b"-", b"e", b"\xb9", b"\x00", b'"']), max_size=40)
       .map(b"".join))
def test_long_number_finds_what_the_regular_expression_finds(raw: bytes) -> None:
    """The spec is ``re`` ``[0-9]{19}``; the ASCII neighbours of the digits ("/" and ":")
    and a superscript digit byte must not count."""
    assert long_number(raw) == bool(re.search(rb"[0-9]{19}", raw))


def test_long_number_on_the_edges() -> None:
    assert long_number(b'{"a":' + b"1" * 19 + b"}")
    assert not long_number(b'{"a":' + b"1" * 18 + b".5}")
    assert long_number(b"0.1234567890123456789")  # a long fraction: json reads it (same value)
