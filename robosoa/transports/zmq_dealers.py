"""The consumer's sockets: one DEALER per (thread, endpoint), and the two ways a call fails.

``Unreachable``: the message could not be handed over (no connection within the wait, or a
connection that was up is gone). ``Lost``: it was handed over, and the connection went away
before the reply came (the peer died, or ZMTP heartbeats stopped coming back). DEALERs use
``IMMEDIATE``, so ZeroMQ keeps an outgoing pipe only while its connection is up: a DEALER
that cannot be written to has no live connection, which is how both are noticed.
"""

from __future__ import annotations

import threading
import time
from collections import OrderedDict
from collections.abc import Callable
from typing import Any

import zmq

from robosoa.errors import BusClosed
from robosoa.message import Frames
from robosoa.transports.base import BusOptions, Lost, Unreachable
from robosoa.transports.zmq_sockets import keepalive, limit_input, recv_rest, send_frames
from robosoa.wire import LimitExceeded

SLICE = 0.1  # seconds: blocking waits are cut in slices so closing the bus is prompt
SLICE_MS = int(SLICE * 1000) + 1
SOCKETS_PER_THREAD = 64  # consumer DEALERs kept per thread (least recently used closed)
_NOBLOCK = int(zmq.NOBLOCK)  # plain ints: pyzmq's flag enums cost a little on every send
_RCVMORE = int(zmq.RCVMORE)
_EVENTS = int(zmq.EVENTS)
_POLLOUT = int(zmq.POLLOUT)

Setup = Callable[[zmq.Socket[bytes], str], None]  # e.g. CURVE keys for the endpoint


class Dealers:
    """DEALER sockets of one bus, per thread; ``closing`` ends every wait within a slice."""

    def __init__(self, ctx: zmq.Context[zmq.Socket[bytes]], options: BusOptions,
                 closing: Callable[[], bool], setup: Setup | None = None) -> None:
        self._ctx = ctx
        self._options = options
        self._closing = closing
        self._setup = setup
        self._local = threading.local()
        self._sockets: set[zmq.Socket[bytes]] = set()
        self._lock = threading.Lock()

    def _cache(self) -> OrderedDict[str, zmq.Socket[bytes]]:
        cache: OrderedDict[str, zmq.Socket[bytes]] | None = getattr(self._local, "dealers", None)
        if cache is None:
            cache = self._local.dealers = OrderedDict()
            self._local.live = set()
        return cache

    def _dealer(self, endpoint: str) -> zmq.Socket[bytes]:
        if self._closing():
            raise BusClosed("bus is closed")
        cache = self._cache()
        sock = cache.get(endpoint)
        if sock is not None:
            cache.move_to_end(endpoint)
            return sock
        options = self._options
        sock = self._ctx.socket(zmq.DEALER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.IMMEDIATE, 1)  # never queue for a peer that is not connected
        sock.setsockopt(zmq.SNDHWM, options.hwm)
        sock.setsockopt(zmq.RCVHWM, options.hwm)
        sock.setsockopt(zmq.RCVTIMEO, SLICE_MS)
        limit_input(sock, options.max_message)
        keepalive(sock, options.link_heartbeat, options.link_timeout)
        if self._setup is not None:
            self._setup(sock, endpoint)
        sock.connect(endpoint)
        cache[endpoint] = sock
        with self._lock:
            self._sockets.add(sock)
        if len(cache) > SOCKETS_PER_THREAD:
            self.drop(next(iter(cache)))
        return sock

    def drop(self, endpoint: str) -> None:
        """Close this thread's socket to ``endpoint`` (after a failure, or to make room)."""
        sock = self._cache().pop(endpoint, None)
        self._local.live.discard(endpoint)
        if sock is not None:
            with self._lock:
                self._sockets.discard(sock)
            sock.close(0)

    def send(self, endpoint: str, frames: Frames, wait: float,
             fail_fast: bool = True) -> zmq.Socket[bytes]:
        """Hand ``frames`` to ``endpoint`` within ``wait`` seconds, or raise Unreachable.

        With ``fail_fast``, a connection that was up and is gone fails at once (a provider
        that restarts binds a new endpoint); else it gets ``wait`` to come back (the
        location service restarts on its endpoint)."""
        sock = self._dealer(endpoint)
        live: set[str] = self._local.live
        deadline = time.monotonic() + wait
        while True:
            try:
                send_frames(sock, frames, _NOBLOCK)
                if endpoint not in live:
                    live.add(endpoint)
                return sock
            except zmq.Again:
                remaining = deadline - time.monotonic()
                if remaining <= 0 or self._closing() or (fail_fast and endpoint in live):
                    self.drop(endpoint)
                    raise Unreachable(f"no connection to {endpoint}") from None
                sock.poll(int(min(remaining, SLICE) * 1000) + 1, zmq.POLLOUT)

    def receive(self, sock: zmq.Socket[bytes], endpoint: str, deadline: float,
                accept: Callable[[list[bytes] | None], Any]) -> Any:
        """Wait for the reply ``accept`` recognises (stale replies are skipped; a reply too
        large in all its frames is handed to it as None); None at the deadline or on
        closing; Lost when the connection goes away meanwhile.

        Blocks in ``recv`` with a receive timeout (no poller: cheaper on the hot path), in
        slices; after each empty slice the socket is asked whether its connection is up.
        """
        while True:
            remaining = deadline - time.monotonic()
            if remaining <= 0 or self._closing():
                return None
            wait = int(min(remaining, SLICE) * 1000) + 1
            if wait != SLICE_MS:  # the socket is created with SLICE; shorter waits set it
                sock.setsockopt(zmq.RCVTIMEO, wait)
            try:
                data = sock.recv()
            except zmq.Again:
                if not int(sock.getsockopt(_EVENTS)) & _POLLOUT:  # no pipe: connection gone
                    self.drop(endpoint)
                    raise Lost(f"connection to {endpoint} lost") from None
                continue
            finally:
                if wait != SLICE_MS:
                    sock.setsockopt(zmq.RCVTIMEO, SLICE_MS)
            try:
                frames: list[bytes] | None = (recv_rest(sock, data, total=self._options.total)
                                              if sock.getsockopt(_RCVMORE) else [data])
            except LimitExceeded:  # more than max_total in all its frames: read, not kept
                frames = None
            found = accept(frames)
            if found is not None:
                return found

    def close(self) -> None:
        """Close every socket of every thread (the bus is shutting down)."""
        with self._lock:
            sockets = list(self._sockets)
            self._sockets.clear()
        for sock in sockets:
            sock.close(0)
