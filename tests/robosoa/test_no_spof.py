"""No single point of failure: with the location service killed, topics keep flowing and
requests keep reaching their providers between live processes; a restarted location service
learns every entry back from heart-beats, and new publishers are found through it again."""

from __future__ import annotations

import time
import uuid
from collections.abc import Iterator

import pytest

import robosoa
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import Proc, start_provider, start_ticker, tcp_location
from tests.robosoa.util import eventually

pytestmark = [pytest.mark.timeout(120), pytest.mark.slow]

GONE_FOR = 4.0  # seconds of work without the location service: past lookup_cache and the TTL


@pytest.fixture
def location() -> Iterator[tuple[Proc, str]]:
    proc, url = tcp_location()
    yield proc, url
    proc.stop()


def _numbers(got: list[robosoa.Message]) -> list[int]:
    return [int(m.payload["n"]) for m in list(got)]


def test_topics_and_requests_outlive_the_location_service(
        location: tuple[Proc, str]) -> None:
    proc, url = location
    name, topic = f"svc-{uuid.uuid4().hex[:8]}", f"tick-{uuid.uuid4().hex[:8]}"
    provider = start_provider(url, name)
    ticker = start_ticker(url, topic)
    restarted: Proc | None = None
    try:
        with robosoa.connect(url, **FAST) as bus:
            got: list[robosoa.Message] = []
            bus.subscribe(topic, got.append)
            eventually(lambda: len(got) >= 5, timeout=20)
            assert bus.request(name, "echo", {"n": 0})["echo"] == {"n": 0}
            proc.kill()
            killed_at, seen_then = time.monotonic(), max(_numbers(got))
            calls = 0
            while time.monotonic() - killed_at < GONE_FOR:  # every call in that time works
                calls += 1
                assert bus.request(name, "echo", {"n": calls}, timeout=5)["echo"] == {"n": calls}
            assert calls >= 10
            eventually(lambda: max(_numbers(got)) > seen_then + 50, timeout=20)
            numbers = _numbers(got)
            assert numbers == sorted(numbers)
            with pytest.raises(robosoa.RobosoaError):
                bus.adapter.location({"op": "ping"}, 0.5)  # it really is gone

            restarted = Proc(proc.args)
            restarted.wait_line("robosoa location service on")
            eventually(lambda: {i.name for i in _services(bus)} >= {name}, timeout=20)
            eventually(lambda: ticker.popen.pid in _publishers(bus), timeout=20)
            late = start_ticker(url, topic + "-late")
            try:
                more: list[robosoa.Message] = []
                bus.subscribe(topic + "-late", more.append)
                eventually(lambda: more, timeout=20)
            finally:
                late.stop()
    finally:
        if restarted is not None:
            restarted.stop()
        ticker.stop()
        provider.stop()


def _publishers(bus: robosoa.Bus) -> set[int]:
    """Process ids of the publishers the location service knows."""
    found = bus.adapter.location({"op": "lookup", "name": "robosoa.pub"}, 2.0)["services"]
    return {int(s["pid"]) for s in found}


def _services(bus: robosoa.Bus) -> list[robosoa.ServiceInfo]:
    try:
        return bus.services()
    except robosoa.RobosoaError:
        return []


def test_announcements_find_a_new_publisher_at_once(zmq_url: str) -> None:
    topic = f"news-{uuid.uuid4().hex[:8]}"
    rare = {**FAST, "heartbeat": 60.0}  # no periodic look-up within the test
    with robosoa.connect(zmq_url, **rare) as listener:
        got: list[robosoa.Message] = []
        listener.subscribe(topic, got.append)
        ticker = start_ticker(zmq_url, topic)  # appears after the subscription
        try:
            eventually(lambda: got, timeout=20)
        finally:
            ticker.stop()
