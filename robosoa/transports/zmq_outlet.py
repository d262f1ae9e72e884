"""The publishing side of a bus over ZeroMQ: its own PUB socket, registered with the location
service as a ``robosoa.pub`` entry so that subscribers connect to it directly.

A bus registers two entries, its PUB and its reliable XPUB (group ``reliable``). A message's
first frame is ``t:NAME`` or ``e:NAME``, a NUL (so ZeroMQ's prefix matching of subscriptions
is exact), ``META`` (this publisher's random id, the message's sequence number on that
channel and its expiry time, 0: none) and the message's JSON; its binary frames follow
(``encode_broadcast``). One frame, not two: a send and a receive less per message.
Subscribers use the numbers to count what ZeroMQ's queues or a lost connection dropped on the
way (reason ``lost``), and the expiry to drop stale messages (reason ``lifespan``). Every
heartbeat a publisher also sends, on each best-effort channel it used since, a mark (expiry
``MARK``, no JSON) with its last sequence number there, so losses at the end of a burst are
counted too.
"""

from __future__ import annotations

import contextlib
import os
import random
import socket
import struct
import threading
import time
import uuid

import zmq

from robosoa.location import PUBLISHERS, ServiceInfo
from robosoa.message import Frames
from robosoa.transports.base import BusOptions
from robosoa.transports.zmq_curve import Curve
from robosoa.transports.zmq_sockets import bind_provider, keepalive, send_frames

META = struct.Struct("!QQd")  # publisher id, sequence number on the channel, expiry (epoch s)
MAX_CHANNELS = 65536  # channels whose sequence numbers are kept; then they start again
MARK = -1.0  # in place of the expiry: no message, only "my last sequence number here is N"
RELIABLE = "reliable"  # group of the publishers' entry for their reliable (XPUB) socket
_MORE_NOBLOCK = int(zmq.SNDMORE | zmq.NOBLOCK)
_NOBLOCK = int(zmq.NOBLOCK)
_EVENTS = int(zmq.EVENTS)
_POLLIN = int(zmq.POLLIN)
_PREFIXES: dict[str, bytes] = {}


def prefix(channel: str) -> bytes:
    """``channel`` and its NUL: what a subscriber subscribes to (cached for channels in use)."""
    found = _PREFIXES.get(channel)
    if found is None:
        found = channel.encode() + b"\0"
        if len(_PREFIXES) < 4096:
            _PREFIXES[channel] = found
    return found


class Outlet:
    """Two PUB sockets bound next to the bus's providers: a PUB for best-effort streams, whose
    sends never block (ZeroMQ drops for a subscriber whose queue is full, and the subscriber
    counts the gap), and an XPUB with ``XPUB_NODROP`` for reliable ones, whose sends fail
    while a subscriber's queue is full, so the publisher waits instead of dropping."""

    def __init__(self, ctx: zmq.Context[zmq.Socket[bytes]], location: str,
                 options: BusOptions, curve: Curve | None = None) -> None:
        self.id = random.getrandbits(64)
        self._pub = self._socket(ctx, zmq.PUB, options)
        self._reliable = self._socket(ctx, zmq.XPUB, options)
        self._reliable.setsockopt(zmq.XPUB_NODROP, 1)
        key = ""
        if curve is not None:
            curve.serve(self._pub)
            curve.serve(self._reliable)
            key = curve.public.decode()
        try:
            self.endpoint = self._bind(self._pub, location, options)
            self.reliable_endpoint = self._bind(self._reliable, location, options)
        except BaseException:
            self.close()
            raise
        host, pid, tag = socket.gethostname(), os.getpid(), uuid.uuid4().hex[:8]
        self.infos = tuple(
            ServiceInfo(PUBLISHERS, "1.0.0", (), "publish-subscribe", endpoint,
                        f"pub-{host}-{pid}-{tag}{suffix}", group, host, pid, options.ttl,
                        key=key)
            for endpoint, group, suffix in ((self.endpoint, None, ""),
                                            (self.reliable_endpoint, RELIABLE, "-r")))
        self._seq: dict[str, int] = {}
        self._reliable_seq: dict[str, int] = {}
        self._marked: dict[str, int] = {}  # channel -> last sequence number told in a MARK
        self._lock = threading.Lock()
        self._reliable_lock = threading.Lock()

    @staticmethod
    def _socket(ctx: zmq.Context[zmq.Socket[bytes]], kind: int,
                options: BusOptions) -> zmq.Socket[bytes]:
        sock = ctx.socket(kind)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.SNDHWM, options.hwm)
        keepalive(sock, options.link_heartbeat, options.link_timeout)
        return sock

    @staticmethod
    def _bind(sock: zmq.Socket[bytes], location: str, options: BusOptions) -> str:
        return bind_provider(sock, location, options.provider_bind, options.advertise_host)

    def _head(self, channel: str, expires: float) -> bytes:
        """The channel frame of a reliable message (own numbering: nothing to mark)."""
        seq = self._reliable_seq.get(channel, 0) + 1
        if seq == 1 and len(self._reliable_seq) >= MAX_CHANNELS:
            self._reliable_seq.clear()
        self._reliable_seq[channel] = seq
        return prefix(channel) + META.pack(self.id, seq, expires)

    def publish(self, channel: str, frames: Frames, expires: float = 0.0) -> None:
        """Send one best-effort message on ``channel`` to every subscriber connected now."""
        head = prefix(channel)
        with self._lock:
            seq = self._seq.get(channel, 0) + 1
            if seq == 1 and len(self._seq) >= MAX_CHANNELS:
                self._seq.clear()
                self._marked.clear()
            self._seq[channel] = seq
            try:
                if len(frames) == 1:
                    self._pub.send(head + META.pack(self.id, seq, expires) + frames[0], _NOBLOCK)
                else:
                    send_frames(self._pub, [head + META.pack(self.id, seq, expires) + frames[0],
                                            *frames[1:]], _NOBLOCK)
            except zmq.Again:  # a PUB drops instead; kept for safety
                pass

    def publish_reliably(self, channel: str, frames: Frames, expires: float,
                         block: float) -> bool:
        """Send one message when every subscriber of ``channel`` has room, waiting up to
        ``block`` seconds; False if one had none by then (nobody got it)."""
        deadline = time.monotonic() + block
        pause = 0.0005
        with self._reliable_lock:
            first = [self._head(channel, expires) + frames[0], *frames[1:]]
            while True:
                self._drain()
                try:
                    send_frames(self._reliable, first, _NOBLOCK)
                    return True
                except zmq.Again:
                    if time.monotonic() >= deadline:
                        return False
                time.sleep(pause)  # an XPUB cannot be polled for room: back off
                pause = min(pause * 2, 0.01)

    def tidy(self) -> None:
        """Every heartbeat: say how far each best-effort channel has gone (so subscribers
        count the messages lost at the end of a burst too), and drop the XPUB's
        subscription notices."""
        with self._lock:
            news = [(c, n) for c, n in self._seq.items() if self._marked.get(c) != n]
            for channel, seq in news:
                self._marked[channel] = seq
                with contextlib.suppress(zmq.Again):
                    self._pub.send(prefix(channel) + META.pack(self.id, seq, MARK), _NOBLOCK)
        with self._reliable_lock:
            self._drain()

    def _drain(self) -> None:
        """Read the subscription notices an XPUB queues for its owner (they are not used)."""
        sock = self._reliable
        while int(sock.getsockopt(_EVENTS)) & _POLLIN:
            sock.recv(_NOBLOCK)

    def close(self) -> None:
        """Close both sockets."""
        with self._lock, self._reliable_lock:
            self._pub.close(0)
            self._reliable.close(0)
