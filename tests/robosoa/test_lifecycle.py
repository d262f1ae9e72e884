"""Shutdown and bounded provider inboxes: no thread outlives its bus, no queue grows."""

from __future__ import annotations

import threading

import pytest

import robosoa
from tests.robosoa.conftest import FAST
from tests.robosoa.util import eventually

pytestmark = pytest.mark.timeout(60)


def _robosoa_threads() -> list[str]:
    return [t.name for t in threading.enumerate() if t.name.startswith("robosoa-")]


def test_close_stops_every_background_thread(url: str, name: str) -> None:
    before = set(_robosoa_threads())
    with robosoa.connect(url, **FAST) as a, robosoa.connect(url, **FAST) as b:
        a.provide(name, {"op": lambda: None})
        b.subscribe(name, lambda m: None)
        b.on(name, lambda m: None)
        b.request_async(name, "op").result(timeout=10)
        assert len(set(_robosoa_threads()) - before) >= 4
    eventually(lambda: not [t for t in _robosoa_threads() if t not in before
                            and not t.startswith("robosoa-async")])
    with pytest.raises(robosoa.BusClosed):
        a.request(name, "op")


def test_a_full_inproc_inbox_refuses_and_counts(name: str) -> None:
    release = threading.Event()
    with robosoa.connect("inproc://inbox-" + name, inbox_size=2, **FAST) as bus:
        bus.provide(name, {"block": lambda: release.wait(10)}, pattern="oneway")
        delivered = sum(bus.send(name, "block") for _ in range(10))
        # one in the handler, two queued; the rest refused without blocking
        assert 2 <= delivered <= 3
        sender = {(f.key, f.role): f for f in bus.stats()}[(name, "sender")]
        assert sender.dropped == 10 - delivered
        with pytest.raises(robosoa.RequestTimeout, match=name):
            bus.request(name, "block", timeout=0.3)
        release.set()


def test_async_requests_are_bounded(name: str) -> None:
    release = threading.Event()
    with robosoa.connect("inproc://async-" + name, queue_size=3, **FAST) as bus:
        bus.provide(name, {"block": lambda: release.wait(10)})
        futures = [bus.request_async(name, "block", timeout=10) for _ in range(5)]
        refused = [f for f in futures if f.done() and f.exception() is not None]
        assert len(refused) == 2 and "already pending" in str(refused[0].exception())
        release.set()
        assert all(f.result(timeout=10) == {"result": True} for f in futures[:3])
        consumer = {(f.key, f.role): f for f in bus.stats()}[(name, "consumer")]
        assert consumer.dropped == 2
