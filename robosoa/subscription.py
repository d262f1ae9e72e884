"""A subscription: a bounded queue fed by the broker, drained by a callback thread or a loop.

When the queue is full the OLDEST message is dropped (a robot wants the latest pose, not a
backlog) and the drop is counted; the broker side never blocks on a slow subscriber.
"""

from __future__ import annotations

import logging
import threading
import time
from collections import deque
from collections.abc import Callable, Iterator
from types import TracebackType

from robosoa.message import Message
from robosoa.stats import Counter

log = logging.getLogger("robosoa.subscription")

Callback = Callable[[Message], None]


class Subscription:
    """Messages of one topic or event; iterate it, or give a callback at creation."""

    def __init__(self, name: str, size: int, counter: Counter,
                 callback: Callback | None = None) -> None:
        self.name = name
        self._queue: deque[Message] = deque()
        self._size = max(1, size)
        self._counter = counter
        self._cond = threading.Condition()
        self._closed = False
        self._cancel: Callable[[], None] | None = None
        self._callback = callback
        self._thread: threading.Thread | None = None
        if callback is not None:
            self._thread = threading.Thread(target=self._deliver, daemon=True,
                                            name=f"robosoa-sub-{name}")
            self._thread.start()

    def attach(self, cancel: Callable[[], None]) -> None:
        """Remember how to detach from the broker (set by the bus)."""
        self._cancel = cancel

    @property
    def dropped(self) -> int:
        """Messages dropped because this subscription's queue was full."""
        return self._counter.figures().dropped

    def sink(self, msg: Message, size: int = 0, expires: float = 0.0) -> bool:
        """Enqueue without blocking; drop the oldest message when full."""
        with self._cond:
            if self._closed:
                return True
            queue = self._queue
            if len(queue) >= self._size:
                queue.popleft()
                self._counter.drop("depth")
            queue.append(msg)
            if len(queue) == 1:  # readers only wait on an empty queue
                self._cond.notify()
        return True

    def get(self, timeout: float | None = None) -> Message | None:
        """The next message, or None on timeout or once closed."""
        deadline = None if timeout is None else time.monotonic() + timeout
        with self._cond:
            while not self._queue and not self._closed:
                remaining = None if deadline is None else deadline - time.monotonic()
                if remaining is not None and remaining <= 0:
                    return None
                self._cond.wait(remaining)
            if not self._queue:
                return None
            msg = self._queue.popleft()
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
        """Detach from the broker, wake readers and stop the callback thread."""
        cancel, self._cancel = self._cancel, None
        if cancel is not None:
            cancel()
        with self._cond:
            self._closed = True
            self._queue.clear()
            self._cond.notify_all()
        thread = self._thread
        if thread is not None and thread is not threading.current_thread():
            thread.join(timeout=5.0)

    def __enter__(self) -> Subscription:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
