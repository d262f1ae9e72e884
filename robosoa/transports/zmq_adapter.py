"""The ZeroMQ transport: providers and consumers in separate processes or machines.

Topology (see docs/runtime.md): a location-service process binds a ROUTER for the location
protocol and a PUB for announcements. Each provider instance binds its own ROUTER and
registers that endpoint; consumers connect a DEALER per (thread, endpoint) and talk to
providers directly. Each bus that publishes binds its own PUB and registers it; subscribers
connect to every registered PUB directly (``zmq_topics``): there is no broker.
"""

from __future__ import annotations

import contextlib
import itertools
import json
import threading
import time
from collections.abc import Callable
from typing import Any

import zmq
from zmq.auth.thread import ThreadAuthenticator

from robosoa.errors import BusClosed, InvalidMessage, RequestTimeout, RobosoaError
from robosoa.location import ServiceInfo
from robosoa.message import Frames, Message, decode_frames, encode_frames
from robosoa.transports import zmq_curve as curve
from robosoa.transports.base import (
    BusOptions,
    Inbox,
    Lost,
    ProtocolAdapter,
    Sink,
    Unreachable,
)
from robosoa.transports.zmq_dealers import Dealers
from robosoa.transports.zmq_guard import Guard
from robosoa.transports.zmq_inbox import ZmqInbox
from robosoa.transports.zmq_sockets import check_endpoint, public
from robosoa.transports.zmq_topics import Topics
from robosoa.wire import load_object

CONNECT_WAIT = 0.5  # seconds a new connection to a provider gets to come up


class ZmqAdapter(ProtocolAdapter):
    """Protocol adapter for ``zmq://tcp://HOST:PORT`` and ``zmq://ipc:///PATH``."""

    scheme = "zmq"

    def __init__(self, address: str, options: BusOptions) -> None:
        super().__init__(address, options)
        self.endpoint = address.removeprefix("zmq://")
        check_endpoint(self.endpoint)  # validates early, with a readable error
        self._ctx: zmq.Context[zmq.Socket[bytes]] | None = None
        self._dealers: Dealers | None = None
        self._rids = itertools.count(1)
        self._closing = False
        self._in_flight = 0
        self._idle = threading.Condition()
        self._topics: Topics | None = None
        self._curve = curve.load(options.curve_secret, options.curve_allow,
                                 options.curve_location)
        self._auth: ThreadAuthenticator | None = None
        self._keys: dict[str, bytes] = {}  # endpoint -> its server's CURVE key (from lookups)
        self._guard: Guard | None = None  # bounds what each provider connection holds

    # --- SOA_Base ---------------------------------------------------------------------
    def configure(self) -> None:
        if self._ctx is None:
            self._ctx = zmq.Context()
            if self._curve is not None:  # the ZAP handler first: nothing binds without it
                self._auth = self._curve.authenticator(self._ctx)
            setup = self._secure if self._curve is not None else None
            self._dealers = Dealers(self._ctx, self.options, lambda: self._closing, setup)
            self._topics = Topics(self._ctx, self.endpoint, self.options, self.location,
                                  self.rejected, self._lost, self._curve)

    def _secure(self, sock: zmq.Socket[bytes], endpoint: str) -> None:
        """CURVE client set-up of a DEALER: the server key of ``endpoint``."""
        assert self._curve is not None
        key = self._curve.location if endpoint == self.endpoint else self._keys.get(endpoint)
        if not key:
            raise Unreachable(f"no CURVE key known for {endpoint}")
        self._curve.client(sock, key)

    def _learn(self, reply: dict[str, Any]) -> None:
        """Remember the CURVE keys of the endpoints a lookup returned."""
        found = reply.get("services")
        if self._curve is None or not isinstance(found, list):
            return
        if len(self._keys) > 65536:
            self._keys.clear()
        for entry in found:
            if isinstance(entry, dict):
                endpoint, key = entry.get("endpoint"), entry.get("key")
                if isinstance(endpoint, str) and isinstance(key, str) and len(key) == 40:
                    self._keys[endpoint] = key.encode()

    def connect(self) -> None:
        if self._closing:
            raise BusClosed(f"bus {self.address} is closed")
        self.configure()
        self.connected = True
        hello = self.location({"op": "hello"}, self.options.location_timeout)
        announce = public(str(hello.get("announce", "")), self.endpoint)
        if not announce:
            raise RobosoaError(f"location service at {self.endpoint} makes no announcements "
                               "(an older robosoa?)")
        assert self._topics is not None
        self._topics.follow(announce)

    def disconnect(self) -> None:
        self.connected = False

    def shutdown(self) -> None:
        if self.connected and not self._closing:
            for info in self.registrations():  # best effort; otherwise they expire
                with contextlib.suppress(RobosoaError):
                    self.location({"op": "unregister", "instance": info.instance}, 0.5)
        self.connected = False
        with self._idle:
            self._closing = True  # waits in flight end within one SLICE
            self._idle.wait_for(lambda: self._in_flight == 0, timeout=2.0)
        if self._topics is not None:
            self._topics.close()
            self._topics = None
        if self._dealers is not None:
            self._dealers.close()
        if self._guard is not None:  # its monitors close before the context does
            self._guard.close()
            self._guard = None
        if self._auth is not None:
            self._auth.stop()
            self._auth = None
        if self._ctx is not None:
            self._ctx.destroy(linger=0)
            self._ctx = None

    def ping(self, timeout: float) -> float:
        start = time.perf_counter()
        self.location({"op": "ping"}, timeout)
        return time.perf_counter() - start

    def maintain(self) -> None:
        """Follow a restarted location service whose announcement endpoint changed."""
        if self._topics is not None:
            self._topics.tidy()
        self.connect()

    def registrations(self) -> list[ServiceInfo]:
        """This bus's PUB, once it has published."""
        return self._topics.registrations() if self._topics is not None else []

    def _lost(self, channel: str, n: int) -> None:
        """Messages a publisher sent on ``channel`` that never arrived (sequence gap)."""
        self.stats_book.counter(channel[2:], "subscriber").drop("lost", n)

    def location(self, request: dict[str, Any], timeout: float) -> dict[str, Any]:
        self._enter()
        try:
            return self._location(request, timeout)
        finally:
            self._leave()

    def _location(self, request: dict[str, Any], timeout: float) -> dict[str, Any]:
        if not self.connected:
            raise BusClosed(f"bus {self.address} is not connected")
        rid = next(self._rids)
        if request.get("op") == "lookup":  # the reply must fit our frame limit
            request = {**request, "max_bytes": self.options.max_message}
        raw = json.dumps({**request, "rid": rid}).encode()
        deadline = time.monotonic() + timeout
        dealers = self._live_dealers()
        try:
            sock = dealers.send(self.endpoint, [raw], timeout, fail_fast=False)
        except Unreachable:
            raise RobosoaError(f"location service at {self.endpoint} is not reachable") from None

        def accept(frames: list[bytes] | None) -> dict[str, Any] | None:
            try:
                if frames is None or len(frames) != 1:
                    raise InvalidMessage("expected one frame")
                reply = load_object(frames[0], self.options.max_message,
                                    self.options.max_depth)
            except InvalidMessage:
                self.rejected("location")
                return None
            return reply if reply.get("rid") == rid else None

        try:
            reply: dict[str, Any] | None = dealers.receive(sock, self.endpoint, deadline, accept)
        except Lost:
            raise RobosoaError(f"location service at {self.endpoint}: connection lost") from None
        if reply is None:
            dealers.drop(self.endpoint)
            raise RobosoaError(f"location service at {self.endpoint} did not answer "
                               f"within {timeout:g}s")
        if request.get("op") == "lookup":
            self._learn(reply)
        return reply

    def call(self, endpoint: str, msg: Message, timeout: float) -> Message:
        self._enter()
        try:
            return self._call(endpoint, msg, timeout)
        finally:
            self._leave()

    def _call(self, endpoint: str, msg: Message, timeout: float) -> Message:
        deadline = time.monotonic() + timeout
        dealers = self._live_dealers()
        sock = dealers.send(endpoint, encode_frames(msg), min(timeout, CONNECT_WAIT))

        def accept(frames: list[bytes] | None) -> Message | None:
            try:
                if frames is None:
                    raise InvalidMessage("reply too large in all its frames")
                reply = decode_frames(frames, self.options.max_message, self.options.max_depth,
                                      self.options.total)
            except InvalidMessage:
                self.rejected("reply")
                return None
            return reply if reply.correlation_id in (msg.id, "") else None

        reply: Message | None = dealers.receive(sock, endpoint, deadline, accept)
        if reply is None:
            dealers.drop(endpoint)
            if self._closing:
                raise BusClosed(f"bus {self.address} closed during the request")
            raise RequestTimeout(msg.service, msg.operation, timeout)
        return reply

    def post(self, endpoint: str, msg: Message) -> None:
        self._enter()
        try:
            self._live_dealers().send(endpoint, encode_frames(msg), CONNECT_WAIT)
        finally:
            self._leave()

    def _live_dealers(self) -> Dealers:
        if self._dealers is None or self._closing:
            raise BusClosed(f"bus {self.address} is closed")
        return self._dealers

    def _enter(self) -> None:
        """Count a call in flight so ``shutdown`` never closes a socket another thread uses."""
        with self._idle:
            if self._closing:
                raise BusClosed(f"bus {self.address} is closed")
            self._in_flight += 1

    def _leave(self) -> None:
        with self._idle:
            self._in_flight -= 1
            if self._closing:
                self._idle.notify_all()

    # --- provider, broker ---------------------------------------------------------------
    def open_inbox(self, instance: str) -> Inbox:
        if self._ctx is None or not self.connected:
            raise BusClosed(f"bus {self.address} is not connected")
        if self._guard is None:
            self._guard = Guard()
        return ZmqInbox(self._ctx, self.endpoint, self.options, self.rejected, self._curve,
                        self._guard, self._cut)

    def _cut(self, peer: str) -> None:
        """A provider connection from ``peer`` was shut down for holding too much."""
        self.stats_book.counter("inbox", "wire").drop("budget")

    def _live_topics(self) -> Topics:
        if self._topics is None or not self.connected:
            raise BusClosed(f"bus {self.address} is not connected")
        return self._topics

    def advertise(self, channel: str) -> None:
        self._live_topics().outlet()

    def publish(self, channel: str, frames: Frames, expires: float = 0.0,
                block: float | None = None) -> None:
        self._live_topics().publish(channel, frames, expires, block)

    def room(self, channel: str) -> None:
        if self._topics is not None:
            self._topics.room(channel)

    def subscribe(self, channel: str, sink: Sink) -> Callable[[], None]:
        return self._live_topics().subscribe(channel, sink)
