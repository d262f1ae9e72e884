"""The embedded transport: one in-process broker per bus name, zero set-up.

Messages still travel as JSON bytes (encoded by the sender, decoded by the receiver), so a
payload that works here works over ZeroMQ, and no two components share a mutable dict.
"""

from __future__ import annotations

import contextlib
import queue
import threading
import time
from collections.abc import Callable
from typing import Any

from robosoa.errors import BusClosed, RequestTimeout
from robosoa.location import LocationService, Peer, Registry, ServiceInfo
from robosoa.message import Frames, Message, decode_frames, encode_frames
from robosoa.transports.base import (
    BusOptions,
    Inbox,
    Incoming,
    ProtocolAdapter,
    Sink,
    Unreachable,
    hand_out,
)

DEFAULT_NAME = "default"


class _Broker:
    """Shared state of one named in-process bus: location service, inboxes, channels."""

    def __init__(self, name: str, ttl: float) -> None:
        self.name = name
        self.location = LocationService(Registry(default_ttl=ttl), _peer,
                                        {"transport": "inproc"}, name=f"inproc://{name}")
        self.inboxes: dict[str, _InprocInbox] = {}
        self.channels: dict[str, list[Sink]] = {}
        self.lock = threading.Lock()
        self.users = 0


_BROKERS: dict[str, _Broker] = {}
_BROKERS_LOCK = threading.Lock()


def _broker_name(address: str) -> str:
    rest = address.removeprefix("inproc").removeprefix("://").strip("/")
    return rest.split("/", 1)[0] or DEFAULT_NAME


def _peer(address: str) -> Peer:
    """Federation peer: another named in-process location service."""
    name = _broker_name(address)

    def lookup(service: str | None) -> list[ServiceInfo]:
        with _BROKERS_LOCK:
            other = _BROKERS.get(name)
        if other is None:
            return []
        return other.location.lookup(service, local=True)

    return lookup


class _InprocInbox(Inbox):
    def __init__(self, broker: _Broker, endpoint: str, size: int) -> None:
        self.endpoint = endpoint
        self._broker = broker
        self._queue: queue.Queue[Incoming | None] = queue.Queue(maxsize=size)

    def put(self, incoming: Incoming) -> None:
        try:
            self._queue.put_nowait(incoming)
        except queue.Full:
            raise Unreachable(f"inbox {self.endpoint} is full") from None

    def receive(self, timeout: float) -> Incoming | None:
        try:
            return self._queue.get(timeout=timeout)
        except queue.Empty:
            return None

    def wake(self) -> None:
        # if full, the receiver is busy and notices the close flag within its timeout
        with contextlib.suppress(queue.Full):
            self._queue.put_nowait(None)

    def close(self) -> None:
        with self._broker.lock:
            self._broker.inboxes.pop(self.endpoint, None)


class _ReplySlot:
    __slots__ = ("event", "message", "options")

    def __init__(self, options: BusOptions) -> None:
        self.event = threading.Event()
        self.message: Message | None = None
        self.options = options

    def set(self, message: Message) -> None:
        options = self.options
        self.message = decode_frames(encode_frames(message), options.max_message,
                                     options.max_depth, options.total)
        self.event.set()


class InprocAdapter(ProtocolAdapter):
    """Protocol adapter for ``inproc`` and ``inproc://NAME`` buses."""

    scheme = "inproc"

    def __init__(self, address: str, options: BusOptions) -> None:
        super().__init__(address, options)
        self.name = _broker_name(address)
        self._broker: _Broker | None = None

    def configure(self) -> None:
        with _BROKERS_LOCK:
            broker = _BROKERS.get(self.name)
            if broker is None:
                broker = _BROKERS[self.name] = _Broker(self.name, self.options.ttl)
            broker.users += 1
        self._broker = broker

    def connect(self) -> None:
        if self._broker is None:
            self.configure()
        self.connected = True

    def disconnect(self) -> None:
        self.connected = False

    def shutdown(self) -> None:
        self.connected = False
        broker, self._broker = self._broker, None
        if broker is None:
            return
        with _BROKERS_LOCK:
            broker.users -= 1
            if broker.users <= 0 and _BROKERS.get(self.name) is broker:
                del _BROKERS[self.name]

    def _live(self) -> _Broker:
        if self._broker is None or not self.connected:
            raise BusClosed(f"bus {self.address} is not connected")
        return self._broker

    def ping(self, timeout: float) -> float:
        start = time.perf_counter()
        self.location({"op": "ping"}, timeout)
        return time.perf_counter() - start

    def location(self, request: dict[str, Any], timeout: float) -> dict[str, Any]:
        return self._live().location.handle(request)

    def _inbox(self, endpoint: str) -> _InprocInbox:
        self._live()
        with _BROKERS_LOCK:
            broker = _BROKERS.get(_broker_name(endpoint))
        inbox = None if broker is None else broker.inboxes.get(endpoint)
        if inbox is None:
            raise Unreachable(f"no provider at {endpoint}")
        return inbox

    def call(self, endpoint: str, msg: Message, timeout: float) -> Message:
        inbox = self._inbox(endpoint)
        slot = _ReplySlot(self.options)
        inbox.put(Incoming(self._copy(msg), "", slot.set))
        if not slot.event.wait(timeout) or slot.message is None:
            raise RequestTimeout(msg.service, msg.operation, timeout)
        return slot.message

    def post(self, endpoint: str, msg: Message) -> None:
        self._inbox(endpoint).put(Incoming(self._copy(msg), "", None))

    def _copy(self, msg: Message) -> Message:
        """The message as the receiver gets it: encoded and decoded within the same limits."""
        return decode_frames(encode_frames(msg), self.options.max_message,
                             self.options.max_depth, self.options.total)

    def open_inbox(self, instance: str) -> Inbox:
        broker = self._live()
        endpoint = f"inproc://{self.name}/{instance}"
        inbox = _InprocInbox(broker, endpoint, self.options.inbox_size)
        with broker.lock:
            broker.inboxes[endpoint] = inbox
        return inbox

    def publish(self, channel: str, frames: Frames, expires: float = 0.0,
                block: float | None = None) -> None:
        broker = self._live()
        with broker.lock:
            sinks = list(broker.channels.get(channel, ()))
        if sinks:
            hand_out(sinks, frames, expires, block, channel, self.options)

    def subscribe(self, channel: str, sink: Sink) -> Callable[[], None]:
        broker = self._live()
        with broker.lock:
            broker.channels.setdefault(channel, []).append(sink)

        def cancel() -> None:
            with broker.lock:
                sinks = broker.channels.get(channel, [])
                if sink in sinks:
                    sinks.remove(sink)
                if not sinks:
                    broker.channels.pop(channel, None)

        return cancel


def known_buses() -> list[str]:
    """Names of live in-process buses (for diagnostics)."""
    with _BROKERS_LOCK:
        return sorted(_BROKERS)


__all__ = ["InprocAdapter", "known_buses"]
