"""The publishing side of a bus over ZeroMQ: its own PUB socket, registered with the location
service as a ``robosoa.pub`` entry so that subscribers connect to it directly.

A message is the channel frame, then the message's frames (``encode_broadcast``). The channel
frame is ``t:NAME`` or ``e:NAME``, a NUL (so ZeroMQ's prefix matching of subscriptions is
exact), and ``META``: this publisher's random id, the message's sequence number on that
channel and its expiry time (0: none). Subscribers use the numbers to count what ZeroMQ's
queues or a lost connection dropped on the way (reason ``lost``), and the expiry to drop
stale messages (reason ``lifespan``).
"""

from __future__ import annotations

import os
import random
import socket
import struct
import threading
import uuid

import zmq

from robosoa.location import PUBLISHERS, ServiceInfo
from robosoa.message import Frames
from robosoa.transports.base import BusOptions
from robosoa.transports.zmq_sockets import bind_provider, keepalive, send_frames

META = struct.Struct("!QQd")  # publisher id, sequence number on the channel, expiry (epoch s)
MAX_CHANNELS = 65536  # channels whose sequence numbers are kept; then they start again
_MORE_NOBLOCK = int(zmq.SNDMORE | zmq.NOBLOCK)
_NOBLOCK = int(zmq.NOBLOCK)
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
    """A PUB socket bound next to the bus's providers; sends never block (ZeroMQ drops for a
    subscriber whose queue is full, and the subscriber counts the gap)."""

    def __init__(self, ctx: zmq.Context[zmq.Socket[bytes]], location: str,
                 options: BusOptions) -> None:
        self.id = random.getrandbits(64)
        self._pub = ctx.socket(zmq.PUB)
        self._pub.setsockopt(zmq.LINGER, 0)
        self._pub.setsockopt(zmq.SNDHWM, options.hwm)
        keepalive(self._pub, options.link_heartbeat, options.link_timeout)
        try:
            self.endpoint = bind_provider(self._pub, location, options.provider_bind,
                                          options.advertise_host)
        except BaseException:
            self._pub.close(0)
            raise
        host = socket.gethostname()
        self.info = ServiceInfo(PUBLISHERS, "1.0.0", (), "publish-subscribe", self.endpoint,
                                f"pub-{host}-{os.getpid()}-{uuid.uuid4().hex[:8]}", None, host,
                                os.getpid(), options.ttl)
        self._seq: dict[str, int] = {}
        self._lock = threading.Lock()

    def publish(self, channel: str, frames: Frames, expires: float = 0.0) -> None:
        """Send one message on ``channel`` to every subscriber connected now."""
        head = prefix(channel)
        with self._lock:
            seq = self._seq.get(channel, 0) + 1
            if seq == 1 and len(self._seq) >= MAX_CHANNELS:
                self._seq.clear()
            self._seq[channel] = seq
            try:
                self._pub.send(head + META.pack(self.id, seq, expires), _MORE_NOBLOCK)
                send_frames(self._pub, frames, _NOBLOCK)
            except zmq.Again:  # a PUB drops instead; kept for safety
                pass

    def close(self) -> None:
        """Close the socket."""
        with self._lock:
            self._pub.close(0)
