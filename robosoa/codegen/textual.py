"""``bytes`` values in the text encodings of provider executables (json, xml): base64.

On the bus binary values travel as frames of their own (``robosoa.blobs``); a program that
reads its request on stdin and writes its result on stdout gets them as base64 text (RFC 4648,
standard alphabet) and writes them the same way. Which values are bytes is read from the
descriptor's types, so the program writes plain strings.
"""

from __future__ import annotations

import base64
import binascii
from collections.abc import Mapping, Sequence
from typing import Any

from robosoa.descriptor import Parameter, ServiceDescriptor, TypeRef


def to_text(value: object) -> str:
    """``json.dumps(default=...)`` hook: binary values as base64 text."""
    if isinstance(value, bytes | bytearray | memoryview):
        return base64.b64encode(value).decode("ascii")
    raise TypeError(f"Object of type {type(value).__name__} is not JSON serializable")


def from_base64(text: object, path: str) -> bytes:
    """The bytes of base64 ``text``; ValueError naming ``path`` if it is not base64."""
    if not isinstance(text, str):
        raise ValueError(f"{path}: expected base64 text")
    try:
        return base64.b64decode(text, validate=True)
    except (binascii.Error, ValueError):
        raise ValueError(f"{path}: '{text[:40]}' is not base64") from None


def _value(d: ServiceDescriptor, t: TypeRef, value: Any, path: str) -> Any:
    if t.item is not None:
        if not isinstance(value, list):
            return value  # the payload check reports the mismatch
        return [_value(d, t.item, item, f"{path}[{n}]") for n, item in enumerate(value)]
    if t.name == "bytes":
        return from_base64(value, path)
    struct = d.type(t.name)
    if struct is None or not isinstance(value, Mapping):
        return value
    return fields_from_text(d, struct.fields, value, f"{path}.")


def fields_from_text(d: ServiceDescriptor, fields: Sequence[Parameter],
                     data: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """``data`` (decoded JSON of a program's result) with base64 text turned into bytes
    wherever ``fields`` declare ``bytes``."""
    declared = {f.name: f for f in fields}
    out: dict[str, Any] = {}
    for key, value in data.items():
        field = declared.get(key)
        if field is None or value is None:
            out[key] = value
        else:
            out[key] = _value(d, field.type, value, f"{prefix}{key}")
    return out
