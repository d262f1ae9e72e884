"""Check message payloads against a descriptor's operations and data types.

``request_validator(d)`` is what ``bus.provide(validator=...)`` and generated skeletons use;
failures raise ``robosoa.InvalidMessage`` with a reason naming the operation and field.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any, Protocol

from robosoa.errors import InvalidMessage

from .model import Operation, Parameter, TypeDef, TypeRef

Validator = Callable[[str, Mapping[str, Any]], None]

_PRIMITIVE_TYPES: dict[str, tuple[type, ...]] = {
    "int": (int,),
    "float": (float, int),
    "bool": (bool,),
    "string": (str,),
    "bytes": (bytes, bytearray, memoryview),
}


class PayloadError(Exception):
    """A value does not match its declared type; ``path`` names the field inside the payload."""

    def __init__(self, path: str, message: str) -> None:
        self.path = path
        self.message = message
        super().__init__(f"{path}: {message}" if path else message)


def _invalid(reason: str) -> InvalidMessage:
    return InvalidMessage(reason)


class Declared(Protocol):
    """What payload checking reads of a service descriptor (``service.ServiceDescriptor``)."""

    @property
    def name(self) -> str: ...

    def operation(self, name: str) -> Operation | None: ...

    def type(self, name: str) -> TypeDef | None: ...


def _kind(value: object) -> str:
    names: dict[type, str] = {dict: "struct", list: "list", tuple: "list", str: "string",
                              bytearray: "bytes", memoryview: "bytes"}
    return names.get(type(value), type(value).__name__)


def check_value(d: Declared, t: TypeRef, value: object, path: str) -> None:
    """Raise :class:`PayloadError` unless ``value`` (wire form) matches type ``t``."""
    if t.item is not None:
        if not isinstance(value, list | tuple):
            raise PayloadError(path, f"expected {t}, got {_kind(value)}")
        for index, item in enumerate(value):
            check_value(d, t.item, item, f"{path}[{index}]")
        return
    if t.name in _PRIMITIVE_TYPES:
        allowed = _PRIMITIVE_TYPES[t.name]
        if (isinstance(value, bool) and t.name != "bool") or not isinstance(value, allowed):
            raise PayloadError(path, f"expected {t.name}, got {_kind(value)}")
        return
    struct = d.type(t.name)
    if struct is None:
        raise PayloadError(path, f"unknown type '{t.name}'")
    if not isinstance(value, Mapping):
        raise PayloadError(path, f"expected {t.name}, got {_kind(value)}")
    check_fields(d, struct.fields, value, f"{path}.")


def check_fields(
    d: Declared, fields: Sequence[Parameter], value: Mapping[str, Any], prefix: str
) -> None:
    """Check a mapping against declared ``fields``: unknown, missing and mistyped ones."""
    declared = {f.name: f for f in fields}
    for key in value:
        if key not in declared:
            raise PayloadError(f"{prefix}{key}", "unexpected field")
    for f in fields:
        if f.name not in value or value[f.name] is None:
            if f.required:
                raise PayloadError(f"{prefix}{f.name}", "missing required field")
            continue
        check_value(d, f.type, value[f.name], f"{prefix}{f.name}")


def _operation(d: Declared, name: str) -> Operation:
    op = d.operation(name)
    if op is None:
        raise _invalid(f"service '{d.name}' has no operation '{name}'")
    return op


def _checker(d: Declared, replies: bool) -> Validator:
    def validate(operation: str, payload: Mapping[str, Any]) -> None:
        op = _operation(d, operation)
        what, fields = ("return", op.returns) if replies else ("parameter", op.parameters)
        if not isinstance(payload, Mapping):
            raise _invalid(f"operation '{operation}': payload must be a mapping")
        try:
            check_fields(d, fields, payload, "")
        except PayloadError as exc:
            raise _invalid(f"operation '{operation}' {what} '{exc.path}': {exc.message}") from None

    return validate


def request_validator(d: Declared) -> Validator:
    """A callable ``(operation, payload) -> None`` checking requests against ``d``."""
    return _checker(d, replies=False)


def reply_validator(d: Declared) -> Validator:
    """A callable ``(operation, payload) -> None`` checking replies against the returns of ``d``."""
    return _checker(d, replies=True)
