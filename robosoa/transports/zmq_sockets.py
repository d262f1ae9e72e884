"""ZeroMQ socket helpers shared by the zmq adapter and the location service process."""

from __future__ import annotations

import contextlib
import ipaddress
import json
import os
import re
import socket
import tempfile
import threading
import uuid
from collections.abc import Sequence
from typing import Any

import zmq

from robosoa.blobs import MAX_BLOBS
from robosoa.errors import RobosoaError
from robosoa.wire import MAX_MESSAGE, LimitExceeded


def split_endpoint(endpoint: str) -> tuple[str, str, int]:
    """``tcp://h:p`` -> ("tcp", h, p); ``ipc:///x`` -> ("ipc", "/x", 0); ``*`` port -> 0."""
    scheme, _, rest = endpoint.partition("://")
    if scheme == "ipc":
        return scheme, rest, 0
    if scheme != "tcp" or ":" not in rest:
        raise RobosoaError(f"bad ZeroMQ endpoint {endpoint!r}: expected tcp://HOST:PORT or "
                           "ipc:///PATH")
    host, _, port = rest.rpartition(":")
    if port.isascii() and port.isdigit() and int(port) <= 65535:
        return scheme, host.strip("[]"), int(port)
    if port == "*":
        return scheme, host.strip("[]"), 0
    raise RobosoaError(f"bad ZeroMQ endpoint {endpoint!r}: port {port!r} is not 0-65535 or *")


_HOST_NAME = re.compile(r"[A-Za-z0-9]([A-Za-z0-9.-]{0,252}[A-Za-z0-9])?")


def check_endpoint(endpoint: str) -> str:
    """``endpoint`` if it can be bound or connected to; else RobosoaError saying why.

    tcp: the host is ``*``, an IP address or a host/interface name, the port 0-65535 or ``*``;
    ipc: the folder of the path exists.
    """
    scheme, host, _ = split_endpoint(endpoint)
    if scheme == "ipc":
        folder = os.path.dirname(host)
        if not host or (not host.startswith("@") and folder and not os.path.isdir(folder)):
            raise RobosoaError(f"bad ZeroMQ endpoint {endpoint!r}: folder {folder!r} does "
                               "not exist")
        return endpoint
    if host == "*" or (_HOST_NAME.fullmatch(host) and not host.replace(".", "").isdigit()):
        return endpoint
    try:
        ipaddress.ip_address(host)
    except ValueError:
        raise RobosoaError(f"bad ZeroMQ endpoint {endpoint!r}: {host!r} is not an IP address "
                           "or host name") from None
    return endpoint


_SNDMORE = int(zmq.SNDMORE)
_RCVMORE = int(zmq.RCVMORE)


def send_frames(sock: zmq.Socket[bytes], frames: Sequence[bytes], flags: int = 0) -> None:
    """Send ``frames`` as one message; large frames without a copy (pyzmq copies frames
    below its ``copy_threshold`` anyway). ZeroMQ takes a multipart message whole or not at
    all, so only the first send can raise ``zmq.Again``."""
    last = len(frames) - 1
    sock.send(frames[0], flags | _SNDMORE if last else flags)
    for n in range(1, last + 1):
        sock.send(frames[n], flags | _SNDMORE if n < last else flags, copy=False)


def recv_rest(sock: zmq.Socket[bytes], first: bytes, limit: int = MAX_BLOBS + 1,
              total: int = MAX_MESSAGE) -> list[bytes]:
    """``first`` and the other frames of the message it began (already arrived, whole),
    read one by one.

    Frames past ``limit`` are read and thrown away, so a message of too many frames comes
    back as ``limit + 1`` frames, which the decoder refuses. Once the frames hold more than
    ``total`` bytes the rest are read without a copy and thrown away, and LimitExceeded says
    so: at most ``total`` bytes and one frame of a message are ever copied out of libzmq
    (which held the whole message before its first frame could be read: see zmq_guard).
    """
    frames = [first]
    size = len(first)
    while sock.getsockopt(_RCVMORE):
        if size > total:
            sock.recv(copy=False)
            continue
        frame = sock.recv()
        size += len(frame)
        if len(frames) <= limit:
            frames.append(frame)
    if size > total:
        raise LimitExceeded(f"message of more than {total} bytes in its frames")
    return frames


def recv_message(sock: zmq.Socket[bytes], flags: int = 0, limit: int = MAX_BLOBS + 1,
                 total: int = MAX_MESSAGE) -> list[bytes]:
    """One whole message, as :func:`recv_rest` gives it. The first frame is taken as a
    ``zmq.Frame``, whose ``more`` flag answers what ``getsockopt(RCVMORE)`` would (that
    costs about 0.75 us in pyzmq, the Frame about 0.35 us): a one-frame message, the common
    case on a subscriber, asks the socket nothing more."""
    first = sock.recv(flags, copy=False)
    head = first.bytes
    return recv_rest(sock, head, limit, total) if first.more else [head]


def keepalive(sock: zmq.Socket[bytes], heartbeat: float, timeout: float) -> None:
    """ZMTP heartbeats: a PING every ``heartbeat`` s; a connection that brings nothing back
    for ``timeout`` s is closed (also asked of the peer, as the TTL), so a dead or cut-off
    peer is noticed by ZeroMQ itself, not at the end of a request's timeout. 0 turns it off."""
    if heartbeat > 0:
        sock.setsockopt(zmq.HEARTBEAT_IVL, max(1, int(heartbeat * 1000)))
        sock.setsockopt(zmq.HEARTBEAT_TIMEOUT, max(1, int(timeout * 1000)))
        sock.setsockopt(zmq.HEARTBEAT_TTL, min(6_553_599, max(100, int(timeout * 1000))))


def limit_input(sock: zmq.Socket[bytes], max_message: int) -> None:
    """Refuse frames larger than ``max_message`` bytes from peers (ZeroMQ drops the peer)."""
    sock.setsockopt(zmq.MAXMSGSIZE, max_message)


def local_ip_towards(host: str) -> str:
    """The local address this machine uses to reach ``host`` (no packet is sent)."""
    if host in ("127.0.0.1", "localhost", "::1"):
        return "127.0.0.1"
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        probe.connect((host, 9))
        return str(probe.getsockname()[0])
    except OSError:
        return socket.gethostname()
    finally:
        probe.close()


def bind_provider(sock: zmq.Socket[bytes], location: str, bind: str, advertise: str) -> str:
    """Bind a provider socket next to the location service; return the endpoint to register."""
    scheme, where, _ = split_endpoint(location)
    if bind.startswith("ipc://") or (not bind and scheme == "ipc"):
        folder = bind.removeprefix("ipc://") or os.path.dirname(where) or tempfile.gettempdir()
        endpoint = f"ipc://{folder}/robosoa-{uuid.uuid4().hex[:12]}.ipc"
        sock.bind(endpoint)
        return endpoint
    reach = local_ip_towards(where)
    address = bind or f"tcp://{reach if reach == '127.0.0.1' else '0.0.0.0'}"
    port = sock.bind_to_random_port(address)
    host = advertise or (split_endpoint(address + ":0")[1] if bind else reach)
    if host in ("0.0.0.0", "*"):
        host = reach
    return f"tcp://{host}:{port}"


def public(endpoint: str, location: str) -> str:
    """Replace a wildcard bind host in ``endpoint`` by the location service's host."""
    scheme, host, port = split_endpoint(endpoint)
    if scheme == "tcp" and host in ("0.0.0.0", "*", ""):
        return f"tcp://{split_endpoint(location)[1]}:{port}"
    return endpoint


def location_frame(ctx: zmq.Context[zmq.Socket[bytes]], endpoint: str,
                   request: dict[str, Any], timeout: float,
                   max_message: int = MAX_MESSAGE) -> bytes:
    """One-shot location-protocol request on a fresh socket (used for federation peers):
    the reply's first frame; TimeoutError when no reply of at most ``max_message`` bytes a
    frame comes within ``timeout`` (ZeroMQ drops a larger one unread)."""
    sock = ctx.socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    limit_input(sock, max_message)
    try:
        sock.connect(endpoint)
        sock.send(json.dumps(request).encode())
        if not sock.poll(int(timeout * 1000), zmq.POLLIN):
            raise TimeoutError(f"location service at {endpoint} did not answer within "
                               f"{timeout:g}s")
        return sock.recv()
    finally:
        sock.close()


class Waker:
    """A thread-safe way to interrupt a poller: an inproc PAIR pair, send guarded by a lock."""

    def __init__(self, ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
        address = f"inproc://robosoa-wake-{uuid.uuid4().hex}"
        self.rx = ctx.socket(zmq.PAIR)
        self.rx.bind(address)
        self._tx = ctx.socket(zmq.PAIR)
        self._tx.connect(address)
        self._lock = threading.Lock()

    def wake(self) -> None:
        """Make the poller owning ``rx`` return."""
        with self._lock, contextlib.suppress(zmq.Again, zmq.ZMQError):
            self._tx.send(b"!", zmq.NOBLOCK)

    def drain(self) -> None:
        """Consume pending wake-ups (from the polling thread)."""
        while True:
            try:
                self.rx.recv(zmq.NOBLOCK)
            except zmq.Again:
                return

    def close(self) -> None:
        """Close both ends."""
        with self._lock:
            self._tx.close(0)
        self.rx.close(0)
