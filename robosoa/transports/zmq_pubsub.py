"""The subscribing side of a bus over ZeroMQ: SUB sockets connected straight to every
publisher (no broker in between), owned by a thread that fans messages out to the
subscriptions' bounded queues.

Two SUB sockets: one for publishers' best-effort PUBs, one for their reliable XPUBs. When a
reliable subscription refuses a message (its queue is full), the thread keeps that message
and stops reading the reliable socket until the subscription has room: ZeroMQ's queues and
TCP then fill up to the publisher, whose reliable sends fail, so it waits instead of anything
being dropped. The best-effort socket is read on meanwhile.

Which publishers exist is learnt from the location service (``zmq_topics.Discovery``); once
connected, messages flow whether or not the location service is alive. The best-effort SUB is
also connected to the location service's announcements (``a:`` channel): one means "look the
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
from robosoa.message import Message, decode, decode_frames
from robosoa.transports.base import BusOptions, Sink, hand_out
from robosoa.transports.zmq_curve import Curve
from robosoa.transports.zmq_outlet import MARK, META, prefix
from robosoa.transports.zmq_sockets import Waker, keepalive, limit_input, recv_message
from robosoa.wire import LimitExceeded

log = logging.getLogger("robosoa.zmq")

ANNOUNCE = b"a:"  # the location service's channel of publisher-set changes
MAX_TRACKED = 65536  # (publisher, channel) sequence numbers kept; then forgotten (no loss seen)
BATCH = 256  # messages read per wake-up before commands are looked at again
BATCH_BYTES = 256 * 1024  # a batch is handed out once its messages hold this many bytes
Offer = tuple[tuple[Sink, ...], Message, int, float]  # sinks, message, size, expiry
_NOBLOCK = int(zmq.NOBLOCK)


class Feed:
    """The SUB side of one bus; every socket operation happens on its own thread."""

    def __init__(self, ctx: zmq.Context[zmq.Socket[bytes]], options: BusOptions,
                 rejected: Callable[[str], None], lost: Callable[[str, int], None],
                 announce: str, announced: Callable[[], None],
                 curve: Curve | None = None) -> None:
        self._curve = curve
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
        self._held: Offer | None = None  # a reliable message refused, for the sinks that did
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

    def connect(self, endpoints: tuple[dict[str, str], dict[str, str]],
                wait: bool = False) -> None:
        """Be connected to exactly these publishers' best-effort and reliable endpoints
        (each with its CURVE key, "" without CURVE)."""
        self._command("peers", endpoints, wait)

    def room(self) -> None:
        """A reliable subscription has room again: offer the held-back message again."""
        self._command("room", None)

    def move(self, announce: str) -> None:
        """Follow the location service's announcements to a new endpoint."""
        self._command("move", announce)

    def _command(self, op: str, arg: object, wait: bool = False) -> None:
        done = threading.Event() if wait else None
        self._commands.append((op, arg, done))
        self._waker.wake()
        if done is not None and not done.wait(2.0) and not self._stopped.is_set():
            log.warning("subscriber thread is slow to take a command", extra={"op": op})

    def _apply(self, subs: tuple[zmq.Socket[bytes], zmq.Socket[bytes]],
               peers: tuple[set[str], set[str]]) -> None:
        while self._commands:
            op, arg, done = self._commands.popleft()
            try:
                if op in ("sub", "unsub") and isinstance(arg, bytes):
                    for sub in subs:
                        sub.setsockopt(zmq.SUBSCRIBE if op == "sub" else zmq.UNSUBSCRIBE,
                                       arg + b"\0")
                    if op == "unsub":  # a later subscription starts counting afresh
                        self._last = {k: v for k, v in self._last.items() if k[1] != arg}
                elif op == "peers" and isinstance(arg, tuple):
                    for sub, have, want in zip(subs, peers, arg, strict=True):
                        self._follow(sub, have, want)
                elif op == "move" and isinstance(arg, str):
                    _quietly(subs[0].disconnect, self._announce)
                    self._announce = arg
                    self._connect(subs[0], arg, self._curve.location if self._curve else b"")
                elif op == "room":
                    self._retry()
            finally:
                if done is not None:
                    done.set()

    def _retry(self) -> None:
        """Offer the held-back message again to the sinks that refused it (feed thread)."""
        if self._held is not None:
            self._offer(self._held)

    def _offer(self, offer: Offer) -> bool:
        """Offer a reliable message to its sinks; whether all took it. The message stays
        held back for those that refused (offered again at ``room``)."""
        sinks, msg, size, expires = offer
        refused = tuple(sink for sink in sinks if not sink(msg, size, expires, True))
        self._held = (refused, msg, size, expires) if refused else None
        return not refused

    def local(self, channel: str, frames: list[bytes], expires: float,
              block: float | None) -> None:
        """A message this bus published itself: to its own subscriptions, on the caller's
        thread (a bus never listens to its own PUB, so no message comes twice); a reliable
        one waits for room up to ``block`` seconds (PublishTimeout)."""
        sinks = self._sinks.get(prefix(channel)[:-1])
        if sinks:
            hand_out(sinks, frames, expires, block, channel, self._options)

    def _take(self, frames: list[bytes]) -> Offer | None:
        """One message checked and decoded, with the sinks it goes to; None when it goes to
        none (an announcement, a mark, nobody subscribed, or malformed: counted)."""
        head = frames[0]
        cut = head.find(b"\0")
        channel = head[:cut]
        if channel == ANNOUNCE:
            self._announced()
            return None
        if cut < 0 or len(head) < cut + 1 + META.size:
            self._rejected("broadcast")
            return None
        sinks = self._sinks.get(channel)
        if sinks is None:
            return None
        publisher, seq, expires = META.unpack_from(head, cut + 1)
        key = (publisher, channel)
        if expires == MARK or self._last.get(key) != seq - 1:
            self._sequence(publisher, channel, seq, expires == MARK)
            if expires == MARK:
                return None
        else:  # the next message of its stream, the common case: nothing skipped
            self._last[key] = seq
        body = head[cut + 1 + META.size:]
        options = self._options
        try:
            msg = (decode(body, options.max_message, options.max_depth) if len(frames) == 1
                   else decode_frames([body, *frames[1:]], options.max_message,
                                      options.max_depth, options.total))
        except InvalidMessage as exc:
            self._rejected("broadcast")
            log.debug("malformed broadcast dropped", extra={"reason": str(exc)})
            return None
        size = len(head) if len(frames) == 1 else sum(map(len, frames))
        return sinks, msg, size, expires

    def _sequence(self, publisher: int, channel: bytes, seq: int, mark: bool) -> None:
        """Count the messages of ``publisher`` on ``channel`` that were skipped (up to its
        message ``seq``, or up to and with ``seq`` for a mark)."""
        key = (publisher, channel)
        last = self._last.get(key)
        if last is None and len(self._last) >= MAX_TRACKED:
            self._last.clear()
        if last is not None and seq > last:
            missing = seq - last - (0 if mark else 1)
            if missing > 0:
                self._lost(channel.decode(errors="replace"), missing)
        if last is None or seq > last or not mark:
            self._last[key] = seq

    def _socket(self) -> zmq.Socket[bytes]:
        sub = self._ctx.socket(zmq.SUB)
        sub.setsockopt(zmq.LINGER, 0)
        sub.setsockopt(zmq.RCVHWM, self._options.hwm)
        limit_input(sub, self._options.max_message)
        keepalive(sub, self._options.link_heartbeat, self._options.link_timeout)
        return sub

    def _run(self) -> None:
        lossy, reliable = self._socket(), self._socket()
        lossy.setsockopt(zmq.SUBSCRIBE, ANNOUNCE + b"\0")
        self._connect(lossy, self._announce, self._curve.location if self._curve else b"")
        peers: tuple[set[str], set[str]] = (set(), set())
        poller = zmq.Poller()
        for sock in (lossy, reliable, self._waker.rx):
            poller.register(sock, zmq.POLLIN)
        paused = False
        try:
            while not self._stopped.is_set():
                events = dict(poller.poll(500))
                if self._waker.rx in events:
                    self._waker.drain()
                    self._apply((lossy, reliable), peers)
                if lossy in events:
                    self._drain(lossy)
                if reliable in events and self._held is None:
                    self._drain_reliable(reliable)
                if paused != (self._held is not None):  # hold the reliable socket back
                    paused = not paused
                    poller.modify(reliable, 0 if paused else zmq.POLLIN)
        finally:
            lossy.close(0)
            reliable.close(0)
            while self._commands:  # nobody waits on a command that will never run
                done = self._commands.popleft()[2]
                if done is not None:
                    done.set()

    def _drain(self, sub: zmq.Socket[bytes]) -> None:
        """Deliver what the best-effort socket holds in batches, read and decoded first and
        handed out together (a subscription's reader is woken once per batch, not every few
        messages), or as soon as they hold ``BATCH_BYTES`` (so large messages go one by one,
        not several at once past a byte budget). docs/runtime.md, Performance."""
        batch: list[Offer] = []
        gathered = 0
        total = self._options.total
        for _ in range(BATCH):  # then look at commands again
            try:
                frames = recv_message(sub, _NOBLOCK, MAX_BLOBS + 2, total)
            except zmq.Again:
                break
            except LimitExceeded:  # read, not kept
                self._rejected("broadcast")
                continue
            try:
                taken = self._take(frames)
            except Exception:  # never let one message end the subscriber thread
                log.exception("broadcast delivery failed")
                continue
            if taken is not None:
                batch.append(taken)
                gathered += taken[2]
                if gathered >= BATCH_BYTES:
                    _hand_out(batch)
                    gathered = 0
        _hand_out(batch)

    def _drain_reliable(self, sub: zmq.Socket[bytes]) -> None:
        """Deliver what the reliable socket holds, one message at a time; stop at a
        message a subscription refused (held back until it has room)."""
        for _ in range(BATCH):
            try:
                frames = recv_message(sub, _NOBLOCK, MAX_BLOBS + 2, self._options.total)
            except zmq.Again:
                return
            except LimitExceeded:  # read, not kept
                self._rejected("broadcast")
                continue
            try:
                taken = self._take(frames)
                if taken is not None and not self._offer(taken):
                    return
            except Exception:  # never let one message end the subscriber thread
                log.exception("broadcast delivery failed")

    def _follow(self, sub: zmq.Socket[bytes], have: set[str], want: dict[str, str]) -> None:
        """Connect ``sub`` to the endpoints of ``want`` it lacks, disconnect the others."""
        for gone in have - want.keys():
            _quietly(sub.disconnect, gone)
        for new in want.keys() - have:
            self._connect(sub, new, want[new].encode())
        have.clear()
        have.update(want)

    def _connect(self, sub: zmq.Socket[bytes], endpoint: str, key: bytes) -> None:
        """Connect, as a CURVE client of ``key`` when the bus uses CURVE."""
        if self._curve is not None:
            self._curve.client(sub, key)
        _quietly(sub.connect, endpoint)

    def close(self) -> None:
        """Stop the receiving thread and close its socket."""
        self._stopped.set()
        self._waker.wake()
        self._thread.join(timeout=5.0)
        self._waker.close()


def _hand_out(batch: list[Offer]) -> None:
    """Give every message of ``batch`` to its best-effort sinks, in order; empty it. A
    sink that fails loses that message only, as a message that failed alone did before
    batches (never let one message end the subscriber thread)."""
    for sinks, msg, size, expires in batch:
        try:
            for sink in sinks:
                sink(msg, size, expires, False)
        except Exception:
            log.exception("broadcast delivery failed")
    batch.clear()


def _quietly(call: Callable[[str], object], endpoint: str) -> None:
    """Connect or disconnect, logging an endpoint ZeroMQ refuses (a peer's bad entry)."""
    try:
        call(endpoint)
    except zmq.ZMQError as exc:
        log.warning("publisher endpoint refused", extra={"endpoint": endpoint[:200],
                                                         "reason": str(exc)})
