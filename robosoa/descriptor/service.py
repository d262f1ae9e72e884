"""The whole service descriptor: its interface, data types and participants, with the
look-ups and payload checkers that code generated from it calls."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

from robosoa.qos import QoS

from .model import Operation, Packaging, Participant, Pattern, TypeDef
from .payload import reply_validator, request_validator


@dataclass(frozen=True, slots=True)
class ServiceDescriptor:
    """A whole service profile: interface, data types and the participants to generate."""

    name: str
    version: str
    definition: str
    pattern: Pattern
    delivery: str
    types: tuple[TypeDef, ...]
    operations: tuple[Operation, ...]
    participants: tuple[Participant, ...]
    source: str
    text: str = field(repr=False)
    line: int = 0

    def operation(self, name: str) -> Operation | None:
        """The operation called ``name``, if any."""
        return next((op for op in self.operations if op.name == name), None)

    def type(self, name: str) -> TypeDef | None:
        """The struct type called ``name``, if any."""
        return next((t for t in self.types if t.name == name), None)

    def participant(self, packaging: Packaging) -> Participant | None:
        """The participant packaged as ``packaging``, if the descriptor declares one."""
        return next((p for p in self.participants if p.packaging == packaging), None)

    def qos(self, operation: str) -> QoS:
        """The QoS of the topic or event ``operation`` (the default without ``<qos>``), for
        ``bus.advertise`` and ``bus.subscribe``; generated code passes it."""
        op = self.operation(operation)
        if op is None:
            raise KeyError(f"service '{self.name}' has no operation '{operation}'")
        return op.qos.settings() if op.qos is not None else QoS()

    def validator(self) -> Callable[[str, Mapping[str, Any]], None]:
        """A request checker ``(operation, payload) -> None`` for ``bus.provide(validator=)``.

        It raises ``robosoa.InvalidMessage`` naming the operation and the offending field.
        """
        return request_validator(self)

    def reply_validator(self) -> Callable[[str, Mapping[str, Any]], None]:
        """Like :meth:`validator`, for reply payloads against the declared return values."""
        return reply_validator(self)
