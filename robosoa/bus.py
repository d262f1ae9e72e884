"""The bus (the thesis's MessagingProxy): every message exchange pattern, on any transport."""

from __future__ import annotations

import logging
import os
import socket
import threading
import uuid
from collections.abc import Mapping
from concurrent.futures import Future
from types import TracebackType
from typing import Any

from robosoa.calls import Calls
from robosoa.channel import Channel
from robosoa.directory import Directory
from robosoa.dispatch import Builtin, Dispatcher, Handler, Validator
from robosoa.errors import (
    BusClosed,
    RobosoaError,
    ServiceNotFound,
)
from robosoa.location import BUS_ENTRY, INTERNAL, PATTERNS, ServiceInfo
from robosoa.message import (
    Kind,
    Payload,
    check_payload,
    event_channel,
    topic_channel,
)
from robosoa.provider import ERROR_EVENT, ProviderHandle
from robosoa.qos import QoS
from robosoa.registrar import Registrar
from robosoa.stats import ServiceFigures
from robosoa.streams import Streams
from robosoa.subscription import Callback, Subscription
from robosoa.transports.base import BusOptions, ProtocolAdapter

log = logging.getLogger("robosoa.bus")

TARGETS = ("one", "group", "all")


class Bus:
    """One participant's connection to the enterprise service bus."""

    def __init__(self, adapter: ProtocolAdapter, options: BusOptions | None = None) -> None:
        self.adapter = adapter
        self.options = options or adapter.options
        self.stats_book = adapter.stats_book
        self.directory = Directory(adapter, self.options)
        self.streams = Streams(adapter, self.options, self._expose)
        self.calls = Calls(adapter, self.options, self.directory)
        self._lock = threading.Lock()
        self._exposed = False
        self._closed = False
        adapter.configure()
        try:
            adapter.connect()
        except BaseException:
            adapter.shutdown()
            raise
        self.registrar = Registrar(adapter, self.options)

    # --- providers -----------------------------------------------------------------
    def provide(self, name: str, handler: Handler, version: str = "1.0.0",
                operations: tuple[str, ...] | list[str] = (), pattern: str = "request-response",
                group: str | None = None, validator: Validator | None = None,
                idempotent: tuple[str, ...] | list[str] = ()) -> ProviderHandle:
        """Offer a service; the handler runs on the instance's own thread, one message at a
        time. ``idempotent`` names the operations a consumer may retry on another instance
        when this one is lost mid-request."""
        self._check_open()
        if pattern not in PATTERNS:
            raise ValueError(f"unknown pattern {pattern!r}: expected one of {', '.join(PATTERNS)}")
        if name.startswith(INTERNAL):
            raise ValueError(f"service names starting with {INTERNAL!r} are the runtime's own")
        return self._offer(name, handler, version, tuple(operations), pattern, group,
                           validator, tuple(idempotent))

    def _offer(self, name: str, handler: Handler, version: str, operations: tuple[str, ...],
               pattern: str, group: str | None, validator: Validator | None,
               idempotent: tuple[str, ...]) -> ProviderHandle:
        instance = f"{name}-{socket.gethostname()}-{os.getpid()}-{uuid.uuid4().hex[:8]}"
        counter = self.stats_book.counter(name, "provider")
        builtins: dict[str, Builtin] = {
            "_ping": lambda _m: {"ok": True, "instance": instance, "service": name},
            "_stats": lambda _m: {"instance": instance,
                                  "figures": [f.to_dict() for f in self.stats()]},
        }
        dispatcher = Dispatcher(name, handler, operations, validator, builtins)
        unknown = set(idempotent) - set(dispatcher.operations) if dispatcher.operations else ()
        if unknown:
            raise ValueError(f"idempotent names unknown operations: {', '.join(sorted(unknown))}")
        inbox = self.adapter.open_inbox(instance)
        info = ServiceInfo(name, version, dispatcher.operations, pattern, inbox.endpoint,
                           instance, group, socket.gethostname(), os.getpid(), self.options.ttl,
                           idempotent=idempotent, key=inbox.key)
        handle = ProviderHandle(info, dispatcher, inbox, counter,
                                lambda event: self.emit(ERROR_EVENT, event),
                                self.registrar.remove, self.options.deadline_slack)
        self.registrar.add(handle)
        return handle

    def _expose(self) -> None:
        """Once this bus publishes or listens: a hidden ``robosoa.bus`` instance answering
        ``_ping`` and ``_stats``, so ``robosoa stats`` shows its subscribers' and publishers'
        counters even when it provides no service."""
        with self._lock:
            if self._exposed:
                return
            self._exposed = True
        self._offer(BUS_ENTRY, {}, "1.0.0", ("_ping", "_stats"), "request-response", None,
                    None, ())

    # --- lookup ----------------------------------------------------------------------
    def services(self, name: str | None = None, version: str | None = None) -> list[ServiceInfo]:
        """Live service entries known to the location service (and its federation)."""
        self._check_open()
        return self.directory.services(name, version)

    def wait_for(self, name: str, timeout: float = 5.0, version: str | None = None,
                 count: int = 1) -> list[ServiceInfo]:
        """Block until ``count`` instances of the service are registered; ServiceNotFound else."""
        return self.directory.wait_for(name, timeout, version, count)

    # --- request / response, one-way (robosoa.calls) -----------------------------------
    def request(self, service: str, operation: str, payload: Mapping[str, Any] | None = None,
                timeout: float = 5.0, version: str | None = None,
                idempotent: bool | None = None) -> Payload:
        """Blocking request/response; RequestTimeout, ServiceNotFound, RemoteError or
        ProviderLost on failure.

        If the provider's connection is lost after the request went out, the request is
        tried on another instance when it is ``idempotent`` (default: as the provider
        registered the operation), else ProviderLost is raised at once.
        """
        self._check_open()
        return self.calls.request(service, operation, check_payload(payload), timeout,
                                  version, idempotent)

    def request_async(self, service: str, operation: str,
                      payload: Mapping[str, Any] | None = None, timeout: float = 5.0,
                      version: str | None = None,
                      idempotent: bool | None = None) -> Future[Payload]:
        """Asynchronous request/response: a Future resolved with the reply or the error."""
        self._check_open()
        return self.calls.request_async(service, operation, check_payload(payload), timeout,
                                        version, idempotent)

    def send(self, service: str, operation: str, payload: Mapping[str, Any] | None = None,
             to: str = "one", group: str | None = None, version: str | None = None) -> int:
        """Fire-and-forget to one instance, every instance of a group, or all; returns how
        many instances took the message (unreachable ones are counted as dropped)."""
        self._check_open()
        if to not in TARGETS:
            raise ValueError(f"to must be one of {', '.join(TARGETS)}, not {to!r}")
        if to == "group" and group is None:
            raise ValueError("to='group' needs group=")
        return self.calls.send(service, operation, check_payload(payload), to, group, version)

    def channel(self, service: str, instance: str | None = None,
                version: str | None = None) -> Channel:
        """A point-to-point channel to one instance (the given id, or the best match now)."""
        found = self.services(service, version)
        if instance is not None:
            found = [i for i in found if i.instance == instance]
        if not found:
            raise ServiceNotFound(service, f"no instance {instance!r}" if instance else "")
        return Channel(self.calls.call_instance, self.adapter, found[0])

    # --- publish / subscribe, events (robosoa.streams) -------------------------------------
    def advertise(self, topic: str, qos: QoS | None = None, event: bool = False) -> None:
        """Declare that this bus publishes ``topic`` (an event with ``event=True``), with the
        publishing side of ``qos``: ``lifespan`` travels with each message, ``reliable``
        makes publish wait up to ``block`` for a full subscriber. On zmq it also binds and
        registers the bus's PUB now, so subscribers have found it by the first message;
        ``publish`` does that on its first call otherwise."""
        self._check_open()
        self.streams.advertise(event_channel(topic) if event else topic_channel(topic), qos)

    def publish(self, topic: str, payload: Mapping[str, Any] | None = None,
                context: Mapping[str, Any] | None = None) -> None:
        """Publish to every subscriber of ``topic``; never blocks, unless the topic was
        advertised reliable (then PublishTimeout after its ``block`` seconds)."""
        self._check_open()
        self.streams.send(Kind.PUBLISH, topic, payload, context)

    def subscribe(self, topic: str, callback: Callback | None = None,
                  queue_size: int | None = None, qos: QoS | None = None) -> Subscription:
        """Receive ``topic``: with a callback (own thread) or by iterating the subscription.
        ``qos`` bounds and shapes its queue (``queue_size`` overrides its depth)."""
        self._check_open()
        return self.streams.listen(topic_channel(topic), topic, callback, queue_size, qos)

    def emit(self, name: str, payload: Mapping[str, Any] | None = None,
             context: Mapping[str, Any] | None = None) -> None:
        """Emit a lightweight event (no service, no reply, no registration)."""
        self._check_open()
        self.streams.send(Kind.EVENT, name, payload, context)

    def on(self, name: str, callback: Callback | None = None,
           queue_size: int | None = None, qos: QoS | None = None) -> Subscription:
        """Listen to a lightweight event."""
        self._check_open()
        return self.streams.listen(event_channel(name), name, callback, queue_size, qos)

    # --- infrastructure -------------------------------------------------------------------
    def federate(self, address: str) -> None:
        """Ask our location service to also answer for services known at ``address``."""
        address = address.removeprefix("zmq://")
        reply = self.adapter.location({"op": "federate", "address": address},
                                      self.options.location_timeout)
        if "error" in reply:
            raise RobosoaError(f"location service: {reply['error']}")

    def ping(self, timeout: float = 2.0) -> float:
        """Round-trip seconds to the location service."""
        return self.adapter.ping(timeout)

    def stats(self) -> list[ServiceFigures]:
        """Counters and latency figures of this bus, per service and role."""
        return self.stats_book.snapshot()

    @property
    def providers(self) -> list[ProviderHandle]:
        """Provider handles currently served by this bus."""
        return self.registrar.handles()

    def disconnect(self) -> None:
        """Stop communicating (heartbeats stop, so entries expire); ``reconnect`` resumes."""
        self.adapter.disconnect()

    def reconnect(self) -> None:
        """Resume after ``disconnect`` and register every provider again at once."""
        self.adapter.reconnect()
        self.registrar.register_all()

    def _check_open(self) -> None:
        if self._closed:
            raise BusClosed("bus is closed")

    def close(self) -> None:
        """Close providers, subscriptions and the transport; stops every background thread."""
        if self._closed:
            return
        self._closed = True
        self.registrar.stop()
        for handle in self.providers:
            handle.close()
        self.streams.close()
        self.calls.close()
        self.adapter.shutdown()  # in-flight calls (heartbeats too) end within one slice
        self.registrar.join()

    def __enter__(self) -> Bus:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<robosoa.Bus {self.adapter.address}>"


