"""Small polling helpers: wait for a condition with a deadline instead of sleeping blindly."""

from __future__ import annotations

import time
from collections.abc import Callable
from typing import TypeVar

import zmq

import robosoa

T = TypeVar("T")


def eventually(probe: Callable[[], T], timeout: float = 5.0, every: float = 0.02) -> T:
    """Call ``probe`` until it returns something truthy; fail after ``timeout`` seconds."""
    deadline = time.monotonic() + timeout
    while True:
        value = probe()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"condition not met within {timeout}s (last value {value!r})")
        time.sleep(every)


def raw_publisher(ctx: zmq.Context[zmq.Socket[bytes]], bus: robosoa.Bus,
                  instance: str) -> zmq.Socket[bytes]:
    """A bare PUB socket on 127.0.0.1, registered as a publisher (``robosoa.pub``) through
    ``bus``'s location service, so every subscriber connects to it: a hostile publisher."""
    pub = ctx.socket(zmq.PUB)
    pub.setsockopt(zmq.LINGER, 0)
    port = pub.bind_to_random_port("tcp://127.0.0.1")
    entry = {"name": "robosoa.pub", "version": "1.0.0", "pattern": "publish-subscribe",
             "endpoint": f"tcp://127.0.0.1:{port}", "instance": instance, "ttl": 30}
    reply = bus.adapter.location({"op": "register", "service": entry}, 2.0)
    assert reply.get("ok"), reply
    return pub
