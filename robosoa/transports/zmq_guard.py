"""What one peer connection can make libzmq hold for us: at most a budget of bytes.

libzmq hands a multipart message to the application only once its last frame has arrived
(ZMTP delivers all frames of a message or none), so however the application reads, libzmq
holds every frame of a message meanwhile; ``ZMQ_MAXMSGSIZE`` bounds single frames, not
their number. A peer that sends 3,000 frames of 1 MiB made a provider hold 3 GB before it
could see the first one. The guard bounds it another way: for every TCP connection of a
watched socket (found through the socket's monitor, which gives the connection's file
descriptor) it compares the bytes the kernel has received on it (``TCP_INFO``) with the
bytes the application has taken from it (credited by the receiving thread with each
message, found by ``ZMQ_SRCFD``, with ZMTP's framing), and shuts down a connection that
is more than its budget ahead; libzmq then drops the message it was assembling.

Checked every ``TICK`` seconds while some connection is receiving, every ``QUIET_TICK``
seconds while none is, so a connection can overshoot by what arrives in one check's time.
ZMTP's own commands (heartbeats) are received but never taken: ``ALLOWANCE`` bytes per
second of a connection's life are credited for them. The guard reads a connection through
a duplicate of libzmq's descriptor, which it closes as soon as libzmq has closed its own
(the monitor says so, or the descriptor no longer names the same socket), so the peer sees
the connection end at most a tick late. Linux only (``TCP_INFO``'s layout); elsewhere, and
for ipc connections, nothing is watched.
"""

from __future__ import annotations

import contextlib
import logging
import os
import socket
import struct
import sys
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field

import zmq

log = logging.getLogger("robosoa.guard")

TICK = 0.02  # seconds between checks while a connection is receiving (BUSY bytes a check)
QUIET_TICK = 0.1  # seconds between checks while none is (each check costs a wake-up)
BUSY = 256 * 1024  # bytes one connection received since the last check that make it busy
ALLOWANCE = 256  # bytes a second a connection may receive that nobody takes (ZMTP commands)
FRAMING = 9  # bytes of ZMTP around one frame (its flags and size)
CURVE_FRAMING = 9 + 33  # around one CURVE-encrypted frame (MESSAGE command, nonce, box)
HANDSHAKE = 4096  # bytes of greeting and handshake a connection starts with
FLOOR = 16 * 1024 * 1024  # no budget is smaller: bursts of small messages are not cut


def budget(message: int) -> int:
    """The budget of a connection whose messages have at most ``message`` bytes: two whole
    messages ahead of the application, and never less than ``FLOOR``."""
    return max(2 * message, FLOOR)
_RECEIVED = 128  # offset of tcpi_bytes_received in Linux's struct tcp_info (since 4.1)
_INFO = 136
_EVENTS = int(zmq.EVENT_ACCEPTED | zmq.EVENT_CONNECTED | zmq.EVENT_DISCONNECTED
              | zmq.EVENT_CLOSED | zmq.EVENT_MONITOR_STOPPED)
SUPPORTED = sys.platform.startswith("linux") and hasattr(socket, "TCP_INFO")


@dataclass(slots=True)
class _Connection:
    sock: socket.socket  # a duplicate of libzmq's descriptor, so the connection can be read
    inode: int  # the socket's identity: libzmq's descriptor still names it while equal
    since: float  # monotonic time it was first seen
    adjust: int  # received - taken when first seen, lowered when credit runs ahead
    last: int = 0  # bytes received at the last check

    def received(self, fd: int) -> int | None:
        """Bytes the kernel has received on the connection; None once libzmq has closed
        it (its descriptor is gone or names another file)."""
        try:
            if os.fstat(fd).st_ino != self.inode:
                return None
            info = self.sock.getsockopt(socket.IPPROTO_TCP, socket.TCP_INFO, _INFO)
        except OSError:
            return None
        return int(struct.unpack_from("Q", info, _RECEIVED)[0]) if len(info) >= _INFO else None


def _connection(fd: int) -> _Connection | None:
    """A watch on the TCP connection behind libzmq's ``fd``, or None (gone, not TCP)."""
    try:
        dup = os.dup(fd)
    except OSError:
        return None
    try:
        sock = socket.socket(fileno=dup)
    except OSError:  # the descriptor names something else by now
        os.close(dup)
        return None
    conn = _Connection(sock, os.fstat(dup).st_ino, time.monotonic(), 0)
    if conn.received(fd) is None:
        sock.close()
        return None
    return conn


@dataclass(slots=True)
class Watch:
    """One watched socket: the bytes taken from each connection (by descriptor), written by
    the socket's receiving thread only, and what the guard knows of its connections."""

    monitor: zmq.Socket[bytes]
    budget: int
    framing: int
    cut: Callable[[str], None]  # told the remote address of each connection shut down
    taken: dict[int, int] = field(default_factory=dict)
    connections: dict[int, _Connection] = field(default_factory=dict)
    fds: dict[bytes, int] = field(default_factory=dict)  # a ROUTER's peer (routing id) -> fd

    def took(self, peer: bytes, size: int, frames: int, frame: zmq.Frame | None) -> None:
        """The receiving thread took a message of ``frames`` frames, ``size`` bytes in all,
        from ``peer`` (a ROUTER's routing id, b"" for others); ``frame``, one of its
        frames, is needed only while ``peer`` is not in ``fds`` (``ZMQ_SRCFD`` costs about
        1 us in pyzmq: asked once per peer, not per message)."""
        fd = self.fds.get(peer) if peer else None
        if fd is None:
            if frame is None:
                return
            try:
                fd = int(frame.get(zmq.SRCFD))
            except zmq.ZMQError:
                return
            if peer:
                if len(self.fds) >= 65536:
                    self.fds.clear()
                self.fds[peer] = fd
        self.taken[fd] = self.taken.get(fd, 0) + size + frames * self.framing

    def seen(self, fd: int) -> None:
        """A connection was accepted or made on ``fd``."""
        self.forget(fd)
        conn = _connection(fd)
        if conn is not None:
            received = conn.received(fd) or 0
            conn.adjust = received - self.taken.get(fd, 0)  # what came before is taken
            self.connections[fd] = conn

    def forget(self, fd: int) -> None:
        """Stop watching the connection on ``fd`` (closed, cut, or never TCP)."""
        conn = self.connections.pop(fd, None)
        if conn is not None:
            conn.sock.close()
        for peer, known in list(self.fds.items()):  # a routing id may come back on another
            if known == fd:
                self.fds.pop(peer, None)

    def close(self) -> None:
        for fd in list(self.connections):
            self.forget(fd)
        self.monitor.close(0)

    def check(self, now: float) -> int:
        """Shut down every connection more than ``budget`` bytes ahead of what was taken;
        returns the most bytes one connection received since the last check."""
        most = 0
        for fd, conn in list(self.connections.items()):
            received = conn.received(fd)
            if received is None:
                self.forget(fd)
                continue
            most = max(most, received - conn.last)
            conn.last = received
            credit = self.taken.get(fd, 0) + conn.adjust + int(ALLOWANCE * (now - conn.since))
            if credit > received:  # framing over-counted, or quiet heartbeats: never banked
                conn.adjust -= credit - received
            elif received - credit > self.budget + HANDSHAKE:
                self._cut(fd, conn, received - credit)
        return most

    def _cut(self, fd: int, conn: _Connection, ahead: int) -> None:
        try:
            peer = conn.sock.getpeername()
            conn.sock.shutdown(socket.SHUT_RDWR)  # libzmq sees the end and drops its message
        except OSError:
            peer = ("?",)
        self.forget(fd)
        address = str(peer[0]) if isinstance(peer, tuple) else str(peer)
        log.warning("connection cut: more than its budget ahead of the application",
                    extra={"peer": address, "budget": self.budget, "ahead": ahead})
        self.cut(address)


class Guard:
    """One thread checking the connections of every socket handed to :meth:`watch`."""

    def __init__(self) -> None:
        self._watches: list[Watch] = []
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def watch(self, sock: zmq.Socket[bytes], budget: int, framing: int,
              cut: Callable[[str], None]) -> Watch | None:
        """Bound every connection of ``sock`` to ``budget`` bytes ahead of what is taken
        (credit it with :meth:`Watch.took`); None where the guard cannot work."""
        if not SUPPORTED:
            return None
        watch = Watch(sock.get_monitor_socket(_EVENTS), budget, framing, cut)
        with self._lock:
            self._watches.append(watch)
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, daemon=True,
                                                name="robosoa-guard")
                self._thread.start()
        return watch

    def _run(self) -> None:
        try:
            pause = QUIET_TICK
            while not self._stop.is_set():
                time.sleep(pause)  # cheaper than Event.wait with a timeout
                with self._lock:
                    watches = list(self._watches)
                now = time.monotonic()
                pause = QUIET_TICK
                for watch in watches:
                    if self._events(watch):
                        if watch.check(now) >= BUSY:
                            pause = TICK
                    else:  # its socket is closed
                        with self._lock:
                            self._watches.remove(watch)
                        watch.close()
        finally:
            with self._lock:
                for watch in self._watches:
                    watch.close()
                self._watches.clear()

    @staticmethod
    def _events(watch: Watch) -> bool:
        """Take the monitor's news; False once the socket is closed."""
        while True:
            try:
                raw = watch.monitor.recv_multipart(zmq.NOBLOCK)
            except zmq.Again:
                return True
            except zmq.ZMQError:
                return False
            event, fd = struct.unpack("=Hi", raw[0][:6])
            if event == zmq.EVENT_MONITOR_STOPPED:
                return False
            if event in (zmq.EVENT_ACCEPTED, zmq.EVENT_CONNECTED):
                watch.seen(fd)
            elif event in (zmq.EVENT_DISCONNECTED, zmq.EVENT_CLOSED):
                watch.forget(fd)

    def close(self) -> None:
        """Stop the thread; it closes every monitor (before the context is terminated)."""
        self._stop.set()
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=2.0)
        with self._lock, contextlib.suppress(zmq.ZMQError):
            for watch in self._watches:
                watch.close()
            self._watches.clear()
