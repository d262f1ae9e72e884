"""Topics and events over the location service's XSUB/XPUB forwarder (the message broker).

One PUB socket per bus (sends serialised by a lock; PUB never blocks: at its high-water mark
ZeroMQ drops) and one SUB socket owned by a receiving thread that fans messages out to the
subscriptions' bounded queues.
"""

from __future__ import annotations

import logging
import threading
import uuid
from collections import deque
from collections.abc import Callable

import zmq

from robosoa.blobs import MAX_BLOBS
from robosoa.errors import InvalidMessage
from robosoa.message import Frames, Kind, Message, decode_frames, encode
from robosoa.transports.base import BusOptions, Sink
from robosoa.transports.zmq_sockets import (
    Waker,
    keepalive,
    limit_input,
    recv_rest,
    send_frames,
)

log = logging.getLogger("robosoa.zmq")

PROBE = "robosoa.probe"  # context key of subscription-sync probes; never delivered to sinks
SYNC_TIMEOUT = 2.0


_NOBLOCK = int(zmq.NOBLOCK)  # plain ints: pyzmq's flag enums cost a little on every call
_MORE_NOBLOCK = int(zmq.SNDMORE | zmq.NOBLOCK)
_RCVMORE = int(zmq.RCVMORE)
_FRAMES: dict[str, bytes] = {}


def _frame(channel: str) -> bytes:
    """The channel frame; the terminator turns ZeroMQ prefix matching into exact matching."""
    frame = _FRAMES.get(channel)
    if frame is None:
        frame = channel.encode() + b"\0"
        if len(_FRAMES) < 4096:  # a bounded cache of the channels in use
            _FRAMES[channel] = frame
    return frame


def _receive(sub: zmq.Socket[bytes]) -> list[bytes]:
    """One multipart message without pyzmq's generic loop (raises zmq.Again when empty)."""
    return recv_rest(sub, sub.recv(_NOBLOCK), MAX_BLOBS + 2)


class Feed:
    """The publish and subscribe side of one bus."""

    def __init__(self, ctx: zmq.Context[zmq.Socket[bytes]], broker: tuple[str, str],
                 options: BusOptions, rejected: Callable[[str], None]) -> None:
        self._ctx = ctx
        self._broker = broker
        self._options = options
        self._rejected = rejected  # counts malformed broadcasts (dropped: nobody to answer)
        self._pub = ctx.socket(zmq.PUB)
        self._pub.setsockopt(zmq.LINGER, 0)
        self._pub.setsockopt(zmq.SNDHWM, options.hwm)
        keepalive(self._pub, options.link_heartbeat, options.link_timeout)
        self._pub.connect(broker[0])
        self._pub_lock = threading.Lock()
        self._sinks: dict[str, tuple[Sink, ...]] = {}  # replaced, never mutated: lock-free reads
        self._lock = threading.Lock()
        self._commands: deque[tuple[str, str]] = deque()
        self._probes: dict[str, threading.Event] = {}
        self._waker = Waker(ctx)
        self.unsent = 0  # publishes refused locally (never happens for PUB, kept for stats)
        self._stopped = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True, name="robosoa-sub")
        self._thread.start()

    def publish(self, channel: str, frames: Frames) -> None:
        """Send one message; ZeroMQ drops it for subscribers whose queues are full."""
        with self._pub_lock:
            try:
                self._pub.send(_frame(channel), _MORE_NOBLOCK)
                send_frames(self._pub, frames, _NOBLOCK)
            except zmq.Again:
                self.unsent += 1

    def subscribe(self, channel: str, sink: Sink) -> Callable[[], None]:
        """Add ``sink`` for ``channel``; returns once the broker forwards the channel to us."""
        with self._lock:
            sinks = self._sinks.get(channel, ())
            first = not sinks
            self._sinks[channel] = (*sinks, sink)
        if first:
            self._command("sub", channel)
            self._sync(channel)

        def cancel() -> None:
            with self._lock:
                sinks = tuple(s for s in self._sinks.get(channel, ()) if s is not sink)
                last = not sinks
                if last:
                    self._sinks.pop(channel, None)
                else:
                    self._sinks[channel] = sinks
            if last:
                self._command("unsub", channel)

        return cancel

    def _sync(self, channel: str) -> None:
        """Publish probes on ``channel`` until one comes back through the broker."""
        token = uuid.uuid4().hex
        arrived = self._probes[token] = threading.Event()
        probe = [encode(Message(Kind.EVENT, topic=channel, context={PROBE: token}))]
        try:
            for _ in range(int(SYNC_TIMEOUT / 0.02)):
                self.publish(channel, probe)
                if arrived.wait(0.02) or self._stopped.is_set():
                    return
            log.warning("subscription not confirmed by the broker", extra={"channel": channel})
        finally:
            self._probes.pop(token, None)

    def move(self, broker: tuple[str, str]) -> None:
        """Reconnect to a broker at new endpoints (restarted location service)."""
        with self._pub_lock:
            self._pub.disconnect(self._broker[0])
            self._pub.connect(broker[0])
        self._command("move", broker[1])
        self._broker = broker

    def _command(self, op: str, arg: str) -> None:
        self._commands.append((op, arg))
        self._waker.wake()

    def _apply(self, sub: zmq.Socket[bytes], endpoint: str) -> str:
        while self._commands:
            op, arg = self._commands.popleft()
            if op == "sub":
                sub.setsockopt(zmq.SUBSCRIBE, _frame(arg))
            elif op == "unsub":
                sub.setsockopt(zmq.UNSUBSCRIBE, _frame(arg))
            elif op == "move":
                sub.disconnect(endpoint)
                sub.connect(arg)
                endpoint = arg
        return endpoint

    def _deliver(self, frames: list[bytes]) -> None:
        if len(frames) < 2:
            self._rejected("broadcast")
            return
        try:
            msg = decode_frames(frames[1:], self._options.max_message, self._options.max_depth)
        except InvalidMessage as exc:
            self._rejected("broadcast")
            log.debug("malformed broadcast dropped", extra={"reason": str(exc)})
            return
        token = msg.context.get(PROBE)
        if token is not None:
            event = self._probes.get(str(token))
            if event is not None:
                event.set()
            return
        for sink in self._sinks.get(frames[0][:-1].decode(errors="replace"), ()):
            sink(msg)

    def _run(self) -> None:
        sub = self._ctx.socket(zmq.SUB)
        sub.setsockopt(zmq.LINGER, 0)
        sub.setsockopt(zmq.RCVHWM, self._options.hwm)
        limit_input(sub, self._options.max_message)
        keepalive(sub, self._options.link_heartbeat, self._options.link_timeout)
        endpoint = self._broker[1]
        sub.connect(endpoint)
        poller = zmq.Poller()
        poller.register(sub, zmq.POLLIN)
        poller.register(self._waker.rx, zmq.POLLIN)
        try:
            while not self._stopped.is_set():
                events = dict(poller.poll(500))
                if self._waker.rx in events:
                    self._waker.drain()
                    endpoint = self._apply(sub, endpoint)
                if sub in events:
                    for _ in range(256):  # drain a batch, then look at commands again
                        try:
                            frames = _receive(sub)
                        except zmq.Again:
                            break
                        try:
                            self._deliver(frames)
                        except Exception:  # never let one message end the subscriber thread
                            log.exception("broadcast delivery failed")
        finally:
            sub.close(0)

    def close(self) -> None:
        """Stop the receiving thread and close both sockets."""
        self._stopped.set()
        self._waker.wake()
        self._thread.join(timeout=5.0)
        with self._pub_lock:
            self._pub.close(0)
        self._waker.close()
