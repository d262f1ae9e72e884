"""Provider-side call proxy: turns one request message into a reply payload or an error.

Pure apart from calling the user's handler; never raises, so a bad message cannot kill a
provider.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, NamedTuple

from robosoa.errors import InvalidMessage
from robosoa.message import Kind, Message, Payload

MessageHandler = Callable[[Message], Mapping[str, Any] | None]
Handler = MessageHandler | Mapping[str, Callable[..., Any]]
Validator = Callable[[str, Mapping[str, Any]], None]
Builtin = Callable[[Message], Payload]

INVALID = "InvalidMessage"
REMOTE = "RemoteError"


class Outcome(NamedTuple):
    """What a dispatch produced: a reply payload, or an error reason and its type.

    A NamedTuple rather than a dataclass: one is built per message on the hot path.
    """

    payload: Payload
    error: str | None = None
    error_type: str = ""


def _fail(reason: str, error_type: str = INVALID) -> Outcome:
    return Outcome({}, reason, error_type)


def as_payload(result: Any) -> Payload:
    """Handler result to reply payload: mappings as is, None as {}, anything else as result."""
    if result is None:
        return {}
    if isinstance(result, Mapping):
        return dict(result)
    return {"result": result}


class Dispatcher:
    """Routes a message to the operation's callable, after validation; catches everything."""

    def __init__(self, service: str, handler: Handler, operations: tuple[str, ...],
                 validator: Validator | None, builtins: Mapping[str, Builtin]) -> None:
        self.service = service
        self._validator = validator
        self._builtins = dict(builtins)
        self._table: dict[str, Callable[..., Any]] | None = None
        self._shapes: dict[str, _Shape] = {}
        if isinstance(handler, Mapping):
            self._table = dict(handler)
            self.operations = operations or tuple(self._table)
            self._message_handler: MessageHandler | None = None
        elif callable(handler):
            self.operations = operations
            self._message_handler = handler
        else:
            raise TypeError("handler must be a callable or a mapping of operation -> callable")

    def _check(self, msg: Message) -> Outcome | None:
        if msg.kind not in (Kind.REQUEST, Kind.ONEWAY):
            return _fail(f"unexpected {msg.kind.value} message sent to a provider")
        if msg.service and msg.service != self.service:
            return _fail(f"message for service {msg.service!r} reached {self.service!r}")
        if self.operations and msg.operation not in self.operations:
            known = ", ".join(self.operations)
            return _fail(f"unknown operation {msg.operation!r} of {self.service!r} "
                         f"(known: {known})")
        if self._validator is not None:
            try:
                self._validator(msg.operation, msg.payload)
            except InvalidMessage as exc:
                return _fail(f"invalid payload for {self.service}.{msg.operation}: {exc}")
        return None

    def _call_table(self, table: Mapping[str, Callable[..., Any]], msg: Message) -> Any:
        function = table.get(msg.operation)
        if function is None:
            raise _Reject(f"unknown operation {msg.operation!r} of {self.service!r}")
        shape = self._shapes.get(msg.operation)
        if shape is None:
            shape = self._shapes[msg.operation] = _shape(function)
        problem = shape.problem(msg.payload)
        if problem:
            raise _Reject(f"bad arguments for {self.service}.{msg.operation}: {problem}")
        return function(**msg.payload)

    def dispatch(self, msg: Message) -> Outcome:
        """Run the handler for ``msg``; every failure becomes an Outcome with a reason."""
        builtin = self._builtins.get(msg.operation)
        if builtin is not None and msg.kind is Kind.REQUEST:
            return Outcome(builtin(msg))
        problem = self._check(msg)
        if problem is not None:
            return problem
        try:
            if self._table is not None:
                return Outcome(as_payload(self._call_table(self._table, msg)))
            assert self._message_handler is not None
            return Outcome(as_payload(self._message_handler(msg)))
        except _Reject as exc:
            return _fail(str(exc))
        except InvalidMessage as exc:
            return _fail(str(exc))
        except Exception as exc:
            return _fail(f"{type(exc).__name__}: {exc}", REMOTE)


@dataclass(frozen=True, slots=True)
class _Shape:
    """Which keyword arguments a callable takes (checked per call without inspect.bind)."""

    names: frozenset[str]
    required: frozenset[str]
    open_ended: bool  # takes **kwargs, or its signature is unknown

    def problem(self, payload: Mapping[str, Any]) -> str:
        """Why ``payload`` cannot be passed as keyword arguments ("" when it can)."""
        keys = payload.keys()
        missing = self.required - keys
        if missing:
            return f"missing required field(s) {', '.join(sorted(missing))}"
        if not self.open_ended and not keys <= self.names:
            return f"unexpected field(s) {', '.join(sorted(keys - self.names))}"
        return ""


def _shape(function: Callable[..., Any]) -> _Shape:
    try:
        params = inspect.signature(function).parameters.values()
    except (TypeError, ValueError):
        return _Shape(frozenset(), frozenset(), True)
    kinds = (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)
    names = frozenset(p.name for p in params if p.kind in kinds)
    required = frozenset(p.name for p in params
                         if p.kind in kinds and p.default is inspect.Parameter.empty)
    open_ended = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params)
    return _Shape(names, required, open_ended)


class _Reject(Exception):
    """Internal: the request is wrong (not the handler)."""
