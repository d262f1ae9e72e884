"""The ZeroMQ transport: providers and consumers in separate processes or machines.

Topology (see docs/runtime.md): a location-service process binds a ROUTER for the location
protocol and runs an XSUB/XPUB forwarder (the message broker) for topics and events. Each
provider instance binds its own ROUTER and registers that endpoint; consumers connect a
DEALER per (thread, endpoint) and talk to providers directly.
"""

from __future__ import annotations

import itertools
import json
import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from typing import Any

import zmq

from robosoa.errors import BusClosed, InvalidMessage, RequestTimeout, RobosoaError
from robosoa.message import Frames, Message, decode_frames, encode_frames
from robosoa.transports.base import (
    BusOptions,
    Inbox,
    ProtocolAdapter,
    Sink,
    Unreachable,
)
from robosoa.transports.zmq_inbox import ZmqInbox
from robosoa.transports.zmq_pubsub import Feed
from robosoa.transports.zmq_sockets import (
    check_endpoint,
    limit_input,
    public,
    recv_rest,
    send_frames,
)
from robosoa.wire import load_object

SLICE = 0.1  # seconds: blocking waits are cut in slices so closing the bus is prompt
SLICE_MS = int(SLICE * 1000) + 1
_NOBLOCK = int(zmq.NOBLOCK)  # plain ints: pyzmq's flag enums cost a little on every send
_RCVMORE = int(zmq.RCVMORE)
SOCKETS_PER_THREAD = 64  # consumer DEALERs kept per thread (least recently used closed)


class ZmqAdapter(ProtocolAdapter):
    """Protocol adapter for ``zmq://tcp://HOST:PORT`` and ``zmq://ipc:///PATH``."""

    scheme = "zmq"

    def __init__(self, address: str, options: BusOptions) -> None:
        super().__init__(address, options)
        self.endpoint = address.removeprefix("zmq://")
        check_endpoint(self.endpoint)  # validates early, with a readable error
        self._ctx: zmq.Context[zmq.Socket[bytes]] | None = None
        self._local = threading.local()
        self._sockets: set[zmq.Socket[bytes]] = set()
        self._lock = threading.Lock()
        self._rids = itertools.count(1)
        self._closing = False
        self._in_flight = 0
        self._idle = threading.Condition()
        self._feed: Feed | None = None
        self._broker: tuple[str, str] = ("", "")

    # --- SOA_Base ---------------------------------------------------------------------
    def configure(self) -> None:
        if self._ctx is None:
            self._ctx = zmq.Context()

    def connect(self) -> None:
        if self._closing:
            raise BusClosed(f"bus {self.address} is closed")
        self.configure()
        self.connected = True
        hello = self.location({"op": "hello"}, self.options.location_timeout)
        broker = (public(str(hello.get("xsub", "")), self.endpoint),
                  public(str(hello.get("xpub", "")), self.endpoint))
        if not all(broker):
            raise RobosoaError(f"location service at {self.endpoint} has no message broker")
        if self._feed is None:
            assert self._ctx is not None
            self._feed = Feed(self._ctx, broker, self.options, self.rejected)
        elif broker != self._broker:
            self._feed.move(broker)
        self._broker = broker

    def disconnect(self) -> None:
        self.connected = False

    def shutdown(self) -> None:
        self.connected = False
        with self._idle:
            self._closing = True  # waits in flight end within one SLICE
            self._idle.wait_for(lambda: self._in_flight == 0, timeout=2.0)
        if self._feed is not None:
            self._feed.close()
            self._feed = None
        with self._lock:
            sockets = list(self._sockets)
            self._sockets.clear()
        for sock in sockets:
            sock.close(0)
        if self._ctx is not None:
            self._ctx.destroy(linger=0)
            self._ctx = None

    def ping(self, timeout: float) -> float:
        start = time.perf_counter()
        self.location({"op": "ping"}, timeout)
        return time.perf_counter() - start

    def maintain(self) -> None:
        """Follow a restarted location service whose broker endpoints changed."""
        self.connect()

    # --- consumer sockets (one DEALER per thread and endpoint) -------------------------
    def _dealer(self, endpoint: str) -> zmq.Socket[bytes]:
        if self._closing or self._ctx is None:
            raise BusClosed(f"bus {self.address} is closed")
        cache: OrderedDict[str, zmq.Socket[bytes]] | None = getattr(self._local, "dealers", None)
        if cache is None:
            cache = self._local.dealers = OrderedDict()
        sock = cache.get(endpoint)
        if sock is not None:
            cache.move_to_end(endpoint)
            return sock
        sock = self._ctx.socket(zmq.DEALER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.IMMEDIATE, 1)  # never queue for a peer that is not connected
        sock.setsockopt(zmq.SNDHWM, self.options.hwm)
        sock.setsockopt(zmq.RCVHWM, self.options.hwm)
        sock.setsockopt(zmq.RCVTIMEO, SLICE_MS)
        limit_input(sock, self.options.max_message)
        sock.connect(endpoint)
        cache[endpoint] = sock
        with self._lock:
            self._sockets.add(sock)
        if len(cache) > SOCKETS_PER_THREAD:
            self._drop(cache.popitem(last=False)[0], cache)
        return sock

    def _drop(self, endpoint: str, cache: OrderedDict[str, zmq.Socket[bytes]] | None = None
              ) -> None:
        cache = cache if cache is not None else getattr(self._local, "dealers", None)
        sock = None if cache is None else cache.pop(endpoint, None)
        if sock is not None:
            with self._lock:
                self._sockets.discard(sock)
            sock.close(0)

    def _send(self, endpoint: str, frames: Frames, wait: float) -> zmq.Socket[bytes]:
        sock = self._dealer(endpoint)
        deadline = time.monotonic() + wait
        while True:
            try:
                send_frames(sock, frames, _NOBLOCK)
                return sock
            except zmq.Again:
                remaining = deadline - time.monotonic()
                if remaining <= 0 or self._closing:
                    self._drop(endpoint)
                    raise Unreachable(f"no connection to {endpoint}") from None
                sock.poll(int(min(remaining, SLICE) * 1000) + 1, zmq.POLLOUT)

    def _receive(self, sock: zmq.Socket[bytes], deadline: float,
                 accept: Callable[[list[bytes]], Any]) -> Any:
        """Wait for the reply ``accept`` recognises (stale replies are skipped).

        Blocks in ``recv`` with a receive timeout (no poller: cheaper on the hot path), in
        slices so that closing the bus ends the wait promptly.
        """
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0 or self._closing:
                return None
            wait = int(min(remaining, SLICE) * 1000) + 1
            if wait != SLICE_MS:  # the socket is created with SLICE; shorter waits set it
                sock.setsockopt(zmq.RCVTIMEO, wait)
            try:
                data = sock.recv()
            except zmq.Again:
                continue
            finally:
                if wait != SLICE_MS:
                    sock.setsockopt(zmq.RCVTIMEO, SLICE_MS)
            found = accept(recv_rest(sock, data) if sock.getsockopt(_RCVMORE) else [data])
            if found is not None:
                return found

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
        raw = json.dumps({**request, "rid": rid}).encode()
        deadline = time.monotonic() + timeout
        try:
            sock = self._send(self.endpoint, [raw], timeout)
        except Unreachable:
            raise RobosoaError(f"location service at {self.endpoint} is not reachable") from None

        def accept(frames: list[bytes]) -> dict[str, Any] | None:
            try:
                if len(frames) != 1:
                    raise InvalidMessage(f"expected one frame, got {len(frames)}")
                reply = load_object(frames[0], self.options.max_message,
                                    self.options.max_depth)
            except InvalidMessage:
                self.rejected("location")
                return None
            return reply if reply.get("rid") == rid else None

        reply: dict[str, Any] | None = self._receive(sock, deadline, accept)
        if reply is None:
            self._drop(self.endpoint)
            raise RobosoaError(f"location service at {self.endpoint} did not answer "
                               f"within {timeout:g}s")
        return reply

    def call(self, endpoint: str, msg: Message, timeout: float) -> Message:
        self._enter()
        try:
            return self._call(endpoint, msg, timeout)
        finally:
            self._leave()

    def _call(self, endpoint: str, msg: Message, timeout: float) -> Message:
        deadline = time.monotonic() + timeout
        sock = self._send(endpoint, encode_frames(msg), min(timeout, 0.5))

        def accept(frames: list[bytes]) -> Message | None:
            try:
                reply = decode_frames(frames, self.options.max_message, self.options.max_depth)
            except InvalidMessage:
                self.rejected("reply")
                return None
            return reply if reply.correlation_id in (msg.id, "") else None

        reply: Message | None = self._receive(sock, deadline, accept)
        if reply is None:
            self._drop(endpoint)
            if self._closing:
                raise BusClosed(f"bus {self.address} closed during the request")
            raise RequestTimeout(msg.service, msg.operation, timeout)
        return reply

    def post(self, endpoint: str, msg: Message) -> None:
        self._enter()
        try:
            self._send(endpoint, encode_frames(msg), 0.5)
        finally:
            self._leave()

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
        return ZmqInbox(self._ctx, self.endpoint, self.options, self.rejected)

    def _live_feed(self) -> Feed:
        if self._feed is None or not self.connected:
            raise BusClosed(f"bus {self.address} is not connected")
        return self._feed

    def publish(self, channel: str, frames: Frames) -> None:
        self._live_feed().publish(channel, frames)

    def subscribe(self, channel: str, sink: Sink) -> Callable[[], None]:
        return self._live_feed().subscribe(channel, sink)
