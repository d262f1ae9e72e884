"""A TCP relay on the loopback for fault tests: forwards connections to a target and can cut
them off without closing anything (a partition: the relay stops reading, accepting and
writing, so bytes wait in the kernel's buffers and new connections in its backlog, as
packets would be retransmitted across a cut link; neither side sees an error, only
silence), heal (everything still pending then flows, as after a real outage), and record
the bytes it saw.

Network namespaces would need root; any 127.0.0.0/8 address works without: a provider that
binds 127.0.0.1:P and advertises 127.0.0.2 is reached through a relay on 127.0.0.2:P.
"""

from __future__ import annotations

import contextlib
import selectors
import socket
import threading
from types import TracebackType

CHUNK = 65536


class Relay:
    """Forwards ``listen`` (host, port) to ``target`` on a thread until ``close``."""

    def __init__(self, listen: tuple[str, int], target: tuple[str, int],
                 record: bool = False) -> None:
        self.target = target
        self._server = socket.create_server(listen)
        self.address = self._server.getsockname()[:2]
        self._cut = threading.Event()
        self._stop = threading.Event()
        self._record = record
        self._seen = bytearray()
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, daemon=True, name="test-relay")
        self._thread.start()

    @property
    def endpoint(self) -> str:
        """The relay's address as a ZeroMQ tcp endpoint."""
        return f"tcp://{self.address[0]}:{self.address[1]}"

    def partition(self) -> None:
        """Stop forwarding and accepting; nothing is closed, nothing is read."""
        self._cut.set()

    def heal(self) -> None:
        """Forward again."""
        self._cut.clear()

    def seen(self) -> bytes:
        """Every byte forwarded so far, both directions (when recording)."""
        with self._lock:
            return bytes(self._seen)

    def _run(self) -> None:
        selector = selectors.DefaultSelector()
        selector.register(self._server, selectors.EVENT_READ, None)
        try:
            while not self._stop.is_set():
                if self._cut.is_set():  # the link is down: nothing moves
                    self._stop.wait(0.05)
                    continue
                for key, _ in selector.select(timeout=0.1):
                    if key.data is None:
                        self._accept(selector)
                    else:
                        self._forward(selector, key.fileobj, key.data)  # type: ignore[arg-type]
        finally:
            for key in list(selector.get_map().values()):
                with contextlib.suppress(OSError):
                    key.fileobj.close()  # type: ignore[union-attr]
            selector.close()

    def _accept(self, selector: selectors.BaseSelector) -> None:
        client, _ = self._server.accept()
        try:
            upstream = socket.create_connection(self.target, timeout=2.0)
        except OSError:
            client.close()
            return
        for sock, peer in ((client, upstream), (upstream, client)):
            sock.setblocking(False)
            selector.register(sock, selectors.EVENT_READ, peer)

    def _forward(self, selector: selectors.BaseSelector, sock: socket.socket,
                 peer: socket.socket) -> None:
        try:
            data = sock.recv(CHUNK)
        except BlockingIOError:
            return
        except OSError:
            data = b""
        if not data:
            for end in (sock, peer):
                with contextlib.suppress(KeyError, ValueError):
                    selector.unregister(end)
                end.close()
            return
        if self._record:
            with self._lock:
                self._seen += data
        with contextlib.suppress(OSError):
            peer.setblocking(True)
            peer.settimeout(2.0)
            peer.sendall(data)
            peer.setblocking(False)

    def close(self) -> None:
        """Stop the thread and close every connection (bounded)."""
        self._stop.set()
        self._thread.join(timeout=5.0)
        self._server.close()

    def __enter__(self) -> Relay:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
