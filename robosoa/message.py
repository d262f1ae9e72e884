"""The message envelope every exchange pattern carries, and its JSON wire form."""

from __future__ import annotations

import itertools
import json
import os
import time
from collections.abc import Callable, Mapping, Sequence
from enum import StrEnum
from typing import Any, NamedTuple

from robosoa import blobs
from robosoa.errors import InvalidMessage
from robosoa.wire import MAX_DEPTH, MAX_MESSAGE, LimitExceeded, load_json

Payload = dict[str, Any]


class Kind(StrEnum):
    """The message exchange pattern a message belongs to (Hestand 2011, p. 62)."""

    REQUEST = "request"
    REPLY = "reply"
    ONEWAY = "oneway"
    PUBLISH = "publish"
    EVENT = "event"


_PREFIX = f"{os.getpid():x}-{int(time.time() * 1000) % 0xFFFFFF:x}-"
_COUNTER = itertools.count(1)


def new_id() -> str:
    """A process-unique, cheap message id (pid, start time, counter)."""
    return f"{_PREFIX}{next(_COUNTER):x}"


class _Envelope(NamedTuple):
    kind: Kind
    service: str
    operation: str
    topic: str
    payload: Payload
    context: Payload
    reply_to: str
    correlation_id: str
    error: str | None
    id: str
    timestamp: float


_TUPLE_NEW = tuple.__new__


class Message(_Envelope):
    """One message on the bus; immutable so handlers cannot change what others see.

    An immutable NamedTuple rather than a frozen dataclass on purpose: four are built per
    request/response round trip and construction is about four times cheaper (see
    docs/runtime.md, Performance). ``id`` and ``timestamp`` are filled in when left empty.
    """

    __slots__ = ()

    def __new__(cls, kind: Kind, service: str = "", operation: str = "", topic: str = "",
                payload: Payload | None = None, context: Payload | None = None,
                reply_to: str = "", correlation_id: str = "", error: str | None = None,
                id: str = "", timestamp: float = 0.0) -> Message:
        return _TUPLE_NEW(cls, (kind, service, operation, topic,
                                {} if payload is None else payload,
                                {} if context is None else context, reply_to, correlation_id,
                                error, id or new_id(), timestamp or time.time()))

    def reply(self, payload: Payload | None = None, error: str | None = None,
              error_type: str = "") -> Message:
        """The reply to this request, correlated by id."""
        context = {"operation": self.operation, "error_type": error_type} if error else {
            "operation": self.operation}
        return Message(Kind.REPLY, self.service, self.operation, "", payload or {}, context,
                       "", self.id, error)

    def with_context(self, **extra: Any) -> Message:
        """A copy with more context entries (used by bridges to mark hops)."""
        return self._replace(context={**self.context, **extra})


_FIELDS = ("kind", "service", "operation", "topic", "payload", "context", "reply_to",
           "correlation_id", "error", "id", "timestamp")


def to_dict(msg: Message) -> Payload:
    """The JSON-compatible dict form of a message (empty fields left out)."""
    out: Payload = {"kind": msg.kind, "id": msg.id, "timestamp": msg.timestamp}  # a str
    if msg.service:
        out["service"] = msg.service
    if msg.operation:
        out["operation"] = msg.operation
    if msg.topic:
        out["topic"] = msg.topic
    if msg.payload:
        out["payload"] = msg.payload
    if msg.context:
        out["context"] = msg.context
    if msg.reply_to:
        out["reply_to"] = msg.reply_to
    if msg.correlation_id:
        out["correlation_id"] = msg.correlation_id
    if msg.error is not None:
        out["error"] = msg.error
    return out


def _refuse(value: object) -> object:
    raise TypeError(f"Object of type {type(value).__name__} is not JSON serializable")


def _encoder() -> Callable[[object], str]:
    """json's C encoder built once, compact, ASCII, NaN and Infinity refused, as
    ``JSONEncoder(separators=(",", ":"), allow_nan=False).encode`` writes; without its
    per-call set-up and its circular-reference check (a payload that contains itself ends in
    RecursionError instead, refused all the same)."""
    make = getattr(json.encoder, "c_make_encoder", None)
    if make is None:  # not CPython's _json: the pure-Python encoder
        return json.JSONEncoder(separators=(",", ":"), allow_nan=False).encode
    iterencode = make(None, _refuse, json.encoder.encode_basestring_ascii, None, ":", ",",
                      False, False, False)
    return lambda value: "".join(iterencode(value, 0))


_ENCODE = _encoder()
_BAD = (TypeError, ValueError, RecursionError)
_FIELD_SET = frozenset(_FIELDS)
_KINDS = {kind.value: kind for kind in Kind}
_TEXT_FIELDS = ("service", "operation", "topic", "reply_to", "correlation_id", "id")


def encode(msg: Message) -> bytes:
    """Serialize to one frame of UTF-8 JSON; raises InvalidMessage if the payload is not
    JSON-compatible (binary values need :func:`encode_frames`)."""
    try:
        return _ENCODE(to_dict(msg)).encode()
    except _BAD as exc:
        raise InvalidMessage(f"payload is not JSON-compatible: {exc}") from None


Frames = list[bytes]


def encode_frames(msg: Message) -> Frames:
    """The wire frames of ``msg``: the JSON envelope, then one frame per binary value
    (``robosoa.blobs``); raises InvalidMessage if the payload cannot be sent."""
    return _frames(to_dict(msg), msg.payload)


def _frames(data: Payload, payload: Payload) -> Frames:
    """JSON of ``data`` (whose payload is ``payload``); binary values cut out on the slow path."""
    try:
        return [_ENCODE(data).encode()]
    except (ValueError, RecursionError) as exc:
        raise InvalidMessage(f"payload is not JSON-compatible: {exc}") from None
    except TypeError as exc:  # maybe bytes, which json cannot write: cut them out
        problem = exc
    plain, paths, values = blobs.split(payload)
    if not paths:
        raise InvalidMessage(f"payload is not JSON-compatible: {problem}") from None
    data["payload"], data["blobs"] = plain, paths
    try:
        return [_ENCODE(data).encode(), *values]
    except _BAD as exc:
        raise InvalidMessage(f"payload is not JSON-compatible: {exc}") from None


def _why(data: dict[str, Any]) -> str:
    """The reason a message dict is malformed (slow path of ``from_dict``)."""
    if not data.keys() <= _FIELD_SET:
        return f"unknown message fields: {', '.join(sorted(set(data) - _FIELD_SET))}"
    if type(data.get("kind")) is not str or data["kind"] not in _KINDS:
        return f"unknown message kind {data.get('kind')!r}"
    for name in ("payload", "context"):
        if type(data.get(name, {})) is not dict:
            return f"message {name} is not an object"
    for name in _TEXT_FIELDS:
        if type(data.get(name, "")) is not str:
            return f"message {name} is not a string"
    if data.get("error") is not None and type(data["error"]) is not str:
        return "message error is not a string"
    return "message timestamp is not a number"


def encode_broadcast(kind: Kind, topic: str, payload: Payload,
                     context: Payload | None = None) -> Frames:
    """Wire frames of a publish or event message, without building a Message first (hot
    path)."""
    out: Payload = {"kind": kind, "id": new_id(), "timestamp": time.time(), "topic": topic}
    if payload:
        out["payload"] = payload
    if context:
        out["context"] = context
    return _frames(out, payload)


def from_dict(data: Any) -> Message:
    """Build and check a message from its dict form; raises InvalidMessage with a reason."""
    if type(data) is not dict:
        raise InvalidMessage("message is not a JSON object")
    get = data.get
    name = get("kind")
    kind = _KINDS.get(name) if type(name) is str else None
    service, operation, topic = get("service", ""), get("operation", ""), get("topic", "")
    payload, context = get("payload", {}), get("context", {})
    reply_to, correlation, error = get("reply_to", ""), get("correlation_id", ""), get("error")
    ident, stamp = get("id") or new_id(), get("timestamp", 0.0)
    if (kind is None or len(data) > 11 or type(payload) is not dict
            or type(context) is not dict or type(stamp) not in (int, float)
            or (error is not None and type(error) is not str)
            or not (type(service) is str and type(operation) is str and type(topic) is str
                    and type(reply_to) is str and type(correlation) is str
                    and type(ident) is str)
            or not data.keys() <= _FIELD_SET):
        raise InvalidMessage(_why(data))
    try:
        when = float(stamp)
    except OverflowError:  # an integer of hundreds of digits
        raise InvalidMessage("message timestamp is out of range") from None
    return Message(kind, service, operation, topic, payload, context, reply_to, correlation,
                   error, ident, when)


def decode(raw: bytes, max_bytes: int = MAX_MESSAGE, max_depth: int = MAX_DEPTH) -> Message:
    """Parse one wire frame from a peer within the size and depth limits (``robosoa.wire``);
    raises InvalidMessage naming what is wrong."""
    return from_dict(load_json(raw, max_bytes, max_depth))


def decode_frames(frames: Sequence[bytes], max_bytes: int = MAX_MESSAGE,
                  max_depth: int = MAX_DEPTH, max_total: int = 0) -> Message:
    """Parse a message of one JSON frame and its binary frames (``robosoa.blobs``); each
    frame at most ``max_bytes``, all of them at most ``max_total`` (0: ``max_bytes``)."""
    if len(frames) == 1:
        return decode(frames[0], max_bytes, max_depth)
    if not frames or len(frames) > blobs.MAX_BLOBS + 1:
        raise InvalidMessage(f"message of {len(frames)} frames (at most "
                             f"{blobs.MAX_BLOBS + 1})")
    total = max_total or max_bytes
    if sum(map(len, frames)) > total:
        raise LimitExceeded(f"message of more than {total} bytes in its frames")
    data = load_json(frames[0], max_bytes, max_depth)
    if type(data) is not dict:
        raise InvalidMessage("message is not a JSON object")
    paths = data.pop("blobs", None)
    msg = from_dict(data)
    blobs.join(msg.payload, paths, frames[1:])
    return msg


def check_payload(payload: Mapping[str, Any] | None) -> Payload:
    """Coerce a caller's payload to a plain dict, refusing non-mappings and non-str keys."""
    if payload is None:
        return {}
    if type(payload) is dict:  # the common case, without the ABC check
        for key in payload:
            if type(key) is not str:
                raise InvalidMessage("payload keys must be strings")
        return payload.copy()
    if not isinstance(payload, Mapping):
        raise InvalidMessage(f"payload must be a mapping, not {type(payload).__name__}")
    for key in payload:
        if not isinstance(key, str):
            raise InvalidMessage("payload keys must be strings")
    return dict(payload)


def topic_channel(topic: str) -> str:
    """Broker channel name of a publish/subscribe topic."""
    return f"t:{topic}"


def event_channel(name: str) -> str:
    """Broker channel name of a lightweight event."""
    return f"e:{name}"
