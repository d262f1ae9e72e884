"""A subscription: a bounded queue fed by the transport, drained by a callback thread or a loop.

Its QoS (``robosoa.qos``) bounds the queue in messages (history depth; 1 for keep-latest)
and in bytes; when either is exceeded the OLDEST messages are dropped (a robot wants the
latest pose, not a backlog), except for a reliable subscription, which refuses the new
message instead so the transport holds it back and the publisher waits. Messages older than
their lifespan are dropped on arrival and when they reach the head of the queue. Every drop
is counted with its reason; the transport side never blocks on a slow subscriber.
"""

from __future__ import annotations

import logging
import math
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator
from types import TracebackType

from robosoa.message import Message
from robosoa.qos import QoS
from robosoa.stats import Counter

log = logging.getLogger("robosoa.subscription")

Callback = Callable[[Message], None]
Held = tuple[Message, int, float]  # message, its size in bytes, stale from (epoch s)
_NEVER = math.inf


class Subscription:
    """Messages of one topic or event; iterate it, or give a callback at creation."""

    def __init__(self, name: str, qos: QoS, counter: Counter,
                 callback: Callback | None = None,
                 on_room: Callable[[], None] | None = None) -> None:
        self.name = name
        self.qos = qos
        self._queue: deque[Held] = deque()
        self._bytes = 0
        self._held = qos.held
        self._counter = counter
        self._on_room = on_room  # told when a refused (reliable) message may be offered again
        self._refused = False
        self._max_bytes = qos.max_bytes
        self._lifespan = qos.lifespan
        self._reliable = qos.reliable
        self._lock = threading.Lock()  # a plain lock: taken in C on the hot path
        self._cond = threading.Condition(self._lock)  # only to wait and to wake
        self._closed = False
        self._cancel: Callable[[], None] | None = None
        self._callback = callback
        self._thread: threading.Thread | None = None
        if callback is not None:
            self._thread = threading.Thread(target=self._deliver, daemon=True,
                                            name=f"robosoa-sub-{name}")
            self._thread.start()

    def attach(self, cancel: Callable[[], None]) -> None:
        """Remember how to detach from the transport (set by the bus)."""
        self._cancel = cancel

    @property
    def dropped(self) -> int:
        """Messages of this topic dropped on this bus, for any reason (see ``bus.stats()``)."""
        return self._counter.figures().dropped

    @property
    def queued_bytes(self) -> int:
        """Bytes of the messages waiting in the queue now (at most ``qos.max_bytes``, or one
        message larger than that)."""
        return self._bytes

    def _stale_at(self, msg: Message, expires: float) -> float:
        lifespan = self._lifespan
        own = msg.timestamp + lifespan if lifespan else _NEVER
        return min(own, expires) if expires else own

    def sink(self, msg: Message, size: int = 0, expires: float = 0.0,
             hold: bool = False) -> bool:
        """Take a message from the transport without blocking; False when a reliable
        subscription has no room and the transport can ``hold`` the message back (offer it
        again after ``on_room``). Without ``hold`` (a best-effort stream) the oldest go."""
        stale = self._stale_at(msg, expires) if expires or self._lifespan else _NEVER
        with self._lock:
            if self._closed:
                return True
            if stale != _NEVER and stale <= time.time():
                self._counter.drop("lifespan")
                return True
            queue = self._queue
            if hold and self._reliable and queue and (
                    len(queue) >= self._held or self._bytes + size > self._max_bytes):
                self._refused = True
                return False
            queue.append((msg, size, stale))
            self._bytes += size
            if len(queue) > self._held or self._bytes > self._max_bytes:
                self._trim(queue)
            if len(queue) == 1:  # readers only wait on an empty queue
                self._cond.notify()
        return True

    def _trim(self, queue: deque[Held]) -> None:
        """Drop the oldest messages past the depth, then past the byte budget (lock held)."""
        while len(queue) > self._held:
            self._bytes -= queue.popleft()[1]
            self._counter.drop("depth")
        while self._bytes > self._max_bytes and len(queue) > 1:
            self._bytes -= queue.popleft()[1]
            self._counter.drop("bytes")

    def get(self, timeout: float | None = None) -> Message | None:
        """The next message that is not stale, or None on timeout or once closed."""
        deadline = None if timeout is None else time.monotonic() + timeout
        with self._lock:
            while True:
                while not self._queue and not self._closed:
                    remaining = None if deadline is None else deadline - time.monotonic()
                    if remaining is not None and remaining <= 0:
                        return None
                    self._cond.wait(remaining)
                if not self._queue:
                    return None
                msg, size, stale = self._queue.popleft()
                self._bytes -= size
                if stale == _NEVER or stale > time.time():
                    break
                self._counter.drop("lifespan")  # went stale while it waited
            refused, self._refused = self._refused, False
        if refused and self._on_room is not None:
            self._on_room()
        self._counter.record(time.time() - msg.timestamp)
        return msg

    def __iter__(self) -> Iterator[Message]:
        """Blocking iteration until the subscription is closed."""
        while True:
            msg = self.get()
            if msg is None:
                return
            yield msg

    def _deliver(self) -> None:
        assert self._callback is not None
        while True:
            msg = self.get()
            if msg is None:
                return
            try:
                self._callback(msg)
            except Exception:  # a failing callback must not end the subscription
                self._counter.fail()
                log.exception("subscriber callback failed", extra={"topic": self.name})

    def close(self) -> None:
        """Detach from the transport, wake readers and stop the callback thread."""
        cancel, self._cancel = self._cancel, None
        if cancel is not None:
            cancel()
        with self._cond:
            self._closed = True
            self._queue.clear()
            self._bytes = 0
            self._cond.notify_all()
        if self._on_room is not None:
            self._on_room()  # a transport holding a message back for us lets it go
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=5.0)

    def __enter__(self) -> Subscription:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
