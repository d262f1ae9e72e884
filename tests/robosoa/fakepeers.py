"""Fake federated location services for the tests: raw ROUTER sockets on 127.0.0.1 that
answer every location request with the same entries after a delay, as a hostile or slow peer
added with ``federate`` would. One thread serves them all."""

from __future__ import annotations

import contextlib
import heapq
import json
import threading
import time
from collections.abc import Callable
from types import TracebackType

import zmq


def entries(count: int, prefix: str, size: int = 300, key: str = "") -> list[dict[str, object]]:
    """``count`` well-formed registrations of service ``prefix``, each about ``size``
    characters of JSON (the operations list pads it), with distinct instances."""
    pad = max(1, (size - 200) // 12)
    return [{"name": prefix, "version": "1.0.0", "operations": [f"op{n:08d}" for n in range(pad)],
             "endpoint": f"tcp://127.0.0.1:{1 + i % 65000}", "instance": f"{prefix}-{i}",
             "ttl": 30, "key": key} for i in range(count)]


class FakePeers:
    """``count`` location services answering after ``delay`` seconds; each peer's entries
    come from ``make(n)``. ``asked[n]`` counts the requests peer ``n`` received."""

    def __init__(self, count: int, delay: float,
                 make: Callable[[int], list[dict[str, object]]]) -> None:
        self._ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
        self._sockets: list[zmq.Socket[bytes]] = []
        self.endpoints: list[str] = []
        self._services: list[bytes] = []
        for n in range(count):
            sock = self._ctx.socket(zmq.ROUTER)
            sock.setsockopt(zmq.LINGER, 0)
            port = sock.bind_to_random_port("tcp://127.0.0.1")
            self._sockets.append(sock)
            self.endpoints.append(f"tcp://127.0.0.1:{port}")
            self._services.append(json.dumps(make(n)).encode())
        self.delay = delay
        self.asked = [0] * count
        self.requests: list[dict[str, object]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True)
        self._thread.start()

    def _serve(self) -> None:
        poller = zmq.Poller()
        for sock in self._sockets:
            poller.register(sock, zmq.POLLIN)
        due: list[tuple[float, int, int, list[bytes]]] = []
        order = 0
        while not self._stop.is_set():
            wait = 50 if not due else max(0, min(50, int((due[0][0] - time.monotonic()) * 1000)))
            for sock, _ in poller.poll(wait):
                frames = sock.recv_multipart()
                n = self._sockets.index(sock)
                self.asked[n] += 1
                request = json.loads(frames[-1])
                self.requests.append(request)
                reply = b'{"services": ' + self._services[n] + b', "rid": ' + json.dumps(
                    request.get("rid")).encode() + b"}"
                order += 1
                heapq.heappush(due, (time.monotonic() + self.delay, order, n,
                                     [frames[0], reply]))
            while due and due[0][0] <= time.monotonic():
                _, _, n, out = heapq.heappop(due)
                with contextlib.suppress(zmq.ZMQError):  # the asker is gone
                    self._sockets[n].send_multipart(out, zmq.NOBLOCK)

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)
        for sock in self._sockets:
            sock.close(0)
        self._ctx.term()

    def __enter__(self) -> FakePeers:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


class Listings:
    """A client keeping ``depth`` federated listings (``lookup`` of every name) in flight
    at a location service until stopped; counts the answers and their largest size."""

    def __init__(self, endpoint: str, depth: int) -> None:
        self._ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
        self._endpoint, self._depth = endpoint, depth
        self._stop = threading.Event()
        self.answered = 0
        self.largest = 0  # bytes of the largest reply
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        sock = self._ctx.socket(zmq.DEALER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.connect(self._endpoint)
        listing = json.dumps({"op": "lookup", "name": None}).encode()
        for _ in range(self._depth):
            sock.send(listing)
        while not self._stop.is_set():
            if sock.poll(100):
                self.largest = max(self.largest, len(sock.recv()))
                self.answered += 1
                sock.send(listing)
        sock.close(0)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=10)
        self._ctx.term()
