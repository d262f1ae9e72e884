"""The subscribing side of a bus over ZeroMQ: one SUB socket connected straight to every
publisher's PUB (no broker in between), owned by a thread that fans messages out to the
subscriptions' bounded queues.

Which publishers exist is learnt from the location service (``zmq_topics.Discovery``); once
connected, messages flow whether or not the location service is alive. The SUB socket is also
connected to the location service's announcements (``a:`` channel): one means "look the
publishers up again".
"""

from __future__ import annotations

import logging
import threading
from collections import deque
from collections.abc import Callable

import zmq

from robosoa.blobs import MAX_BLOBS
from robosoa.errors import InvalidMessage
from robosoa.message import decode_frames
from robosoa.transports.base import BusOptions, Sink
from robosoa.transports.zmq_outlet import META, prefix
from robosoa.transports.zmq_sockets import Waker, keepalive, limit_input, recv_rest

log = logging.getLogger("robosoa.zmq")

ANNOUNCE = b"a:"  # the location service's channel of publisher-set changes
MAX_TRACKED = 65536  # (publisher, channel) sequence numbers kept; then forgotten (no loss seen)
_NOBLOCK = int(zmq.NOBLOCK)


class Feed:
    """The SUB side of one bus; every socket operation happens on its own thread."""

    def __init__(self, ctx: zmq.Context[zmq.Socket[bytes]], options: BusOptions,
                 rejected: Callable[[str], None], lost: Callable[[str, int], None],
                 announce: str, announced: Callable[[], None]) -> None:
        self._ctx = ctx
        self._options = options
        self._rejected = rejected  # counts malformed broadcasts (dropped: nobody to answer)
        self._lost = lost  # (channel, n): messages a publisher sent that never arrived
        self._announced = announced
        self._sinks: dict[bytes, tuple[Sink, ...]] = {}  # replaced, never mutated: lock-free
        self._lock = threading.Lock()
        self._commands: deque[tuple[str, object, threading.Event | None]] = deque()
        self._waker = Waker(ctx)
        self._last: dict[tuple[int, bytes], int] = {}
        self._stopped = threading.Event()
        self._announce = announce
        self._thread = threading.Thread(target=self._run, daemon=True, name="robosoa-sub")
        self._thread.start()

    def subscribe(self, channel: str, sink: Sink) -> Callable[[], None]:
        """Add ``sink`` for ``channel``; returns once the SUB socket subscribes to it."""
        key = prefix(channel)[:-1]
        with self._lock:
            sinks = self._sinks.get(key, ())
            first = not sinks
            self._sinks[key] = (*sinks, sink)
        if first:
            self._command("sub", key, wait=True)

        def cancel() -> None:
            with self._lock:
                sinks = tuple(s for s in self._sinks.get(key, ()) if s is not sink)
                last = not sinks
                if last:
                    self._sinks.pop(key, None)
                else:
                    self._sinks[key] = sinks
            if last:
                self._command("unsub", key)

        return cancel

    def connect(self, endpoints: frozenset[str], wait: bool = False) -> None:
        """Be connected to exactly these publisher endpoints (others are disconnected)."""
        self._command("peers", endpoints, wait)

    def move(self, announce: str) -> None:
        """Follow the location service's announcements to a new endpoint."""
        self._command("move", announce)

    def _command(self, op: str, arg: object, wait: bool = False) -> None:
        done = threading.Event() if wait else None
        self._commands.append((op, arg, done))
        self._waker.wake()
        if done is not None and not done.wait(2.0) and not self._stopped.is_set():
            log.warning("subscriber thread is slow to take a command", extra={"op": op})

    def _apply(self, sub: zmq.Socket[bytes], peers: set[str]) -> None:
        while self._commands:
            op, arg, done = self._commands.popleft()
            try:
                if op in ("sub", "unsub"):
                    channel = arg if isinstance(arg, bytes) else b""
                    sub.setsockopt(zmq.SUBSCRIBE if op == "sub" else zmq.UNSUBSCRIBE,
                                   channel + b"\0")
                    if op == "unsub":  # a later subscription starts counting afresh
                        self._last = {k: v for k, v in self._last.items() if k[1] != channel}
                elif op == "peers" and isinstance(arg, frozenset):
                    for gone in peers - arg:
                        _quietly(sub.disconnect, gone)
                    for new in arg - peers:
                        _quietly(sub.connect, new)
                    peers.clear()
                    peers.update(arg)
                elif op == "move" and isinstance(arg, str):
                    _quietly(sub.disconnect, self._announce)
                    self._announce = arg
                    _quietly(sub.connect, arg)
            finally:
                if done is not None:
                    done.set()

    def local(self, channel: str, frames: list[bytes], expires: float) -> None:
        """A message this bus published itself: to its own subscriptions, on the caller's
        thread (a bus never listens to its own PUB, so no message comes twice)."""
        sinks = self._sinks.get(prefix(channel)[:-1])
        if sinks:
            msg = decode_frames(frames, self._options.max_message, self._options.max_depth)
            size = sum(map(len, frames))
            for sink in sinks:
                sink(msg, size, expires)

    def _deliver(self, frames: list[bytes]) -> None:
        head = frames[0]
        cut = head.find(b"\0")
        if cut < 0 or len(frames) < 2:
            self._rejected("broadcast")
            return
        channel = head[:cut]
        if channel == ANNOUNCE:
            self._announced()
            return
        sinks = self._sinks.get(channel)
        if sinks is None:
            return
        expires = 0.0
        if len(head) - cut - 1 == META.size:
            publisher, seq, expires = META.unpack_from(head, cut + 1)
            self._sequence(publisher, channel, seq)
        try:
            msg = decode_frames(frames[1:], self._options.max_message, self._options.max_depth)
        except InvalidMessage as exc:
            self._rejected("broadcast")
            log.debug("malformed broadcast dropped", extra={"reason": str(exc)})
            return
        size = sum(map(len, frames))
        for sink in sinks:
            sink(msg, size, expires)

    def _sequence(self, publisher: int, channel: bytes, seq: int) -> None:
        """Count the messages of ``publisher`` on ``channel`` that were skipped."""
        key = (publisher, channel)
        last = self._last.get(key)
        if last is None and len(self._last) >= MAX_TRACKED:
            self._last.clear()
        self._last[key] = seq
        if last is not None and seq > last + 1:
            self._lost(channel.decode(errors="replace"), seq - last - 1)

    def _socket(self) -> zmq.Socket[bytes]:
        sub = self._ctx.socket(zmq.SUB)
        sub.setsockopt(zmq.LINGER, 0)
        sub.setsockopt(zmq.RCVHWM, self._options.hwm)
        limit_input(sub, self._options.max_message)
        keepalive(sub, self._options.link_heartbeat, self._options.link_timeout)
        sub.setsockopt(zmq.SUBSCRIBE, ANNOUNCE + b"\0")
        _quietly(sub.connect, self._announce)
        return sub

    def _run(self) -> None:
        sub = self._socket()
        peers: set[str] = set()
        poller = zmq.Poller()
        poller.register(sub, zmq.POLLIN)
        poller.register(self._waker.rx, zmq.POLLIN)
        try:
            while not self._stopped.is_set():
                events = dict(poller.poll(500))
                if self._waker.rx in events:
                    self._waker.drain()
                    self._apply(sub, peers)
                if sub in events:
                    for _ in range(256):  # drain a batch, then look at commands again
                        try:
                            frames = recv_rest(sub, sub.recv(_NOBLOCK), MAX_BLOBS + 2)
                        except zmq.Again:
                            break
                        try:
                            self._deliver(frames)
                        except Exception:  # never let one message end the subscriber thread
                            log.exception("broadcast delivery failed")
        finally:
            sub.close(0)
            while self._commands:  # nobody waits on a command that will never run
                done = self._commands.popleft()[2]
                if done is not None:
                    done.set()

    def close(self) -> None:
        """Stop the receiving thread and close its socket."""
        self._stopped.set()
        self._waker.wake()
        self._thread.join(timeout=5.0)
        self._waker.close()


def _quietly(call: Callable[[str], object], endpoint: str) -> None:
    """Connect or disconnect, logging an endpoint ZeroMQ refuses (a peer's bad entry)."""
    try:
        call(endpoint)
    except zmq.ZMQError as exc:
        log.warning("publisher endpoint refused", extra={"endpoint": endpoint[:200],
                                                         "reason": str(exc)})
