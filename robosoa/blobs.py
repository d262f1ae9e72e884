"""Binary values in payloads: carried as ZeroMQ frames of their own, not inside the JSON.

A ``bytes`` value anywhere in a payload (also inside objects and arrays; ``bytearray`` and
``memoryview`` are accepted on sending and copied to ``bytes``) is cut out before the JSON is
written: its place in the JSON holds ``null``, the envelope's ``blobs`` lists the path to
each such place (object keys and array indexes, from the payload down), and the bytes follow
the JSON frame as frames of their own, in the order of ``blobs``. The receiver puts each frame
back at its path. Nothing is base64-encoded and the bytes are never parsed.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

from robosoa.errors import InvalidMessage

BINARY = (bytes, bytearray, memoryview)
MAX_BLOBS = 1024  # binary frames one message may carry
ZERO_COPY = 64 * 1024  # frames at least this large are handed to ZeroMQ without a copy

Path = list[str | int]


def split(payload: Mapping[str, Any],
          max_depth: int = 64) -> tuple[dict[str, Any], list[Path], list[bytes]]:
    """The payload with every binary value replaced by None, the paths and the values.

    Containers on the way to a binary value are copied; the caller's payload is not changed.
    """
    paths: list[Path] = []
    blobs: list[bytes] = []
    out = _cut(payload, [], paths, blobs, max_depth)
    if len(blobs) > MAX_BLOBS:
        raise InvalidMessage(f"payload has {len(blobs)} binary values, more than {MAX_BLOBS}")
    return out, paths, blobs


def _cut(value: Any, path: Path, paths: list[Path], blobs: list[bytes], depth: int) -> Any:
    if isinstance(value, BINARY):
        paths.append(list(path))
        blobs.append(value if type(value) is bytes else bytes(value))
        return None
    if depth <= 0:
        raise InvalidMessage("payload is nested too deeply")
    if isinstance(value, Mapping):
        if not all(type(key) is str for key in value):
            raise InvalidMessage("payload keys must be strings")
        return {key: _cut(item, [*path, key], paths, blobs, depth - 1)
                for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [_cut(item, [*path, n], paths, blobs, depth - 1) for n, item in enumerate(value)]
    return value


def join(payload: dict[str, Any], paths: Any, frames: Sequence[bytes]) -> dict[str, Any]:
    """Put ``frames`` back into a freshly decoded ``payload`` at ``paths`` (from a peer).

    Raises InvalidMessage unless ``paths`` is a list of one path per frame, each leading
    through existing objects (by string key) and arrays (by index) to a null.
    """
    if type(paths) is not list or len(paths) != len(frames):
        raise InvalidMessage(f"message declares {_count(paths)} binary values but carries "
                             f"{len(frames)} binary frames")
    for path, frame in zip(paths, frames, strict=True):
        if type(path) is not list or not path:
            raise InvalidMessage("binary value path is not a non-empty list")
        holder: Any = payload
        for step in path[:-1]:
            holder = _step(holder, step)
        last = path[-1]
        _step(holder, last)  # checks the key or index exists
        if holder[last] is not None:
            raise InvalidMessage("binary value path does not lead to a null")
        holder[last] = frame
    return payload


def _count(paths: Any) -> str:
    return str(len(paths)) if type(paths) is list else "malformed"


def _step(holder: Any, step: Any) -> Any:
    if type(holder) is dict and type(step) is str and step in holder:
        return holder[step]
    if type(holder) is list and type(step) is int and 0 <= step < len(holder):
        return holder[step]
    raise InvalidMessage("binary value path does not match the payload")
