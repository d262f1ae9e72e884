"""Federated lookups off the location service's serving thread, and replies within a size.

A lookup that must ask federated peers waits up to ``federation_timeout``; the serving
thread hands it to one of ``WORKERS`` threads and goes on answering, so registrations,
heartbeats and lookups of names known here never wait on peers. At most ``PENDING`` such
lookups wait for a worker; beyond that a lookup is answered from local entries at once and
counted as ``busy``. A worker's finished reply goes back to the serving thread (which owns
the ROUTER socket) through a queue and a wake-up.
"""

from __future__ import annotations

import json
import logging
import queue
import threading
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import orjson

log = logging.getLogger("robosoa.location")

WORKERS = 2  # federated lookups under way at once
PENDING = 8  # federated lookups waiting for a worker; more are answered locally (busy)
PEER_REPLY = 1024 * 1024  # bytes one federated peer's reply may have (ZeroMQ MAXMSGSIZE)


class FederationPool:
    """Runs federated lookups on worker threads; ``finished`` hands their replies back."""

    def __init__(self, wake: Callable[[], None]) -> None:
        self._wake = wake
        self._executor = ThreadPoolExecutor(WORKERS, thread_name_prefix="robosoa-federation")
        self._done: queue.SimpleQueue[tuple[bytes, bytes]] = queue.SimpleQueue()
        self._lock = threading.Lock()
        self._open = 0  # submitted and not yet finished

    def submit(self, identity: bytes, job: Callable[[], bytes]) -> bool:
        """Run ``job`` (which returns the reply frame for ``identity``) on a worker; False,
        doing nothing, when ``WORKERS + PENDING`` lookups are under way or waiting."""
        with self._lock:
            if self._open >= WORKERS + PENDING:
                return False
            self._open += 1
        self._executor.submit(self._run, identity, job)
        return True

    def _run(self, identity: bytes, job: Callable[[], bytes]) -> None:
        try:
            self._done.put((identity, job()))
        except Exception:  # the asker gets no answer (it times out); the service goes on
            log.exception("federated lookup failed")
        finally:
            with self._lock:
                self._open -= 1
            self._wake()

    def finished(self) -> list[tuple[bytes, bytes]]:
        """The replies finished since the last call: (identity, frame)."""
        out = []
        while True:
            try:
                out.append(self._done.get_nowait())
            except queue.Empty:
                return out

    def close(self) -> None:
        """Stop taking work; lookups under way end within their federation timeout."""
        self._executor.shutdown(wait=False, cancel_futures=True)


def _dump(value: Any) -> bytes:
    """JSON of ``value``: orjson's (C, fast), or json's where orjson refuses (an integer
    past 64 bits, which a peer may have registered as a pid or sent as a request id)."""
    try:
        return orjson.dumps(value)
    except TypeError:
        return json.dumps(value).encode()


def encode_reply(reply: Mapping[str, Any], rid: Any, limit: int) -> tuple[bytes, int]:
    """The reply frame, with ``rid``, at most ``limit`` bytes long: a lookup's entries are
    written one by one and those past the limit left out (their number in ``truncated``).
    Returns the frame and how many entries were left out."""
    services = reply.get("services")
    if not isinstance(services, list) or len(reply) != 1:
        return _dump({**reply, "rid": rid}), 0
    tail = b', "rid": ' + _dump(rid) + b"}"
    room = limit - len(tail) - len(b'{"services": [], "truncated": 18446744073709551615')
    parts = []
    for entry in services:
        part = _dump(entry)
        room -= len(part) + 1
        if room < 0:
            break
        parts.append(part)
    left_out = len(services) - len(parts)
    head = b'{"services": [' + b",".join(parts) + b"]"
    if left_out:
        head += b', "truncated": ' + str(left_out).encode()
    return head + tail, left_out
