"""Streams under faults, with real processes on the loopback: a publisher cut off by a
partition and healed, and a flood of 1 MB messages at a slow subscriber. Each asserts what
the QoS promises, with every message accounted for (received or counted as dropped).

The other fault tests: the location service killed (test_no_spof.py), a provider killed
mid-request with a spare running and a provider partitioned mid-request (test_failover.py).
"""

from __future__ import annotations

import threading
import time
import uuid
from pathlib import Path

import pytest

import robosoa
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import start_flooder, start_ticker
from tests.robosoa.relay import Relay
from tests.robosoa.util import eventually

pytestmark = [pytest.mark.timeout(180), pytest.mark.slow]

CUT_FOR = 4.0  # seconds of partition: longer than link_timeout (3 s), as a real outage would be


def _figures(bus: robosoa.Bus, key: str) -> robosoa.ServiceFigures:
    return next(f for f in bus.stats() if (f.key, f.role) == (key, "subscriber"))


def _publisher_port(bus: robosoa.Bus, pid: int) -> int:
    found = bus.adapter.location({"op": "lookup", "name": "robosoa.pub"}, 2.0)["services"]
    [entry] = [s for s in found if s["pid"] == pid and s.get("group") is None]
    return int(str(entry["endpoint"]).rpartition(":")[2])


def test_a_partitioned_publisher_resumes_without_a_stale_burst(zmq_url: str) -> None:
    topic = f"odom-{uuid.uuid4().hex[:8]}"
    lifespan = 0.5
    ticker = start_ticker(zmq_url, topic, every=0.01, lifespan=lifespan, advertise="127.0.0.2")
    relay: Relay | None = None
    try:
        with robosoa.connect(zmq_url, **FAST) as bus:
            got: list[tuple[int, float]] = []  # (n, age when delivered)
            bus.subscribe(topic, lambda m: got.append((m.payload["n"], time.time() - m.timestamp)))
            port = _publisher_port(bus, ticker.popen.pid)
            relay = Relay(("127.0.0.2", port), ("127.0.0.1", port))
            eventually(lambda: len(got) >= 20, timeout=30)
            relay.partition()
            cut = time.monotonic()
            before = len(got)
            eventually(lambda: time.monotonic() > cut + CUT_FOR)
            during = len(got) - before  # at most what was already on its way
            relay.heal()
            last_before = got[before - 1][0] if before else 0
            eventually(lambda: got[-1][0] > last_before + 100, timeout=30)
            first, last = got[0][0], got[-1][0]
            figures = _figures(bus, topic)
            assert len(got) + figures.dropped == last - first + 1  # every message accounted
            assert set(dict(figures.drops)) <= {"lost", "lifespan"}
            assert dict(figures.drops).get("lost", 0) > 0.5 * CUT_FOR / 0.01  # the outage
            assert during < 50
            assert max(age for _, age in got) < lifespan + 0.5  # no stale burst on healing
    finally:
        if relay is not None:
            relay.close()
        ticker.stop()


def test_a_flood_of_large_messages_at_a_slow_subscriber(zmq_url: str, tmp_path: Path) -> None:
    topic = f"camera-{uuid.uuid4().hex[:8]}"
    count, size, budget, lifespan = 300, 1024 * 1024, 32 * 1024 * 1024, 1.0
    go = tmp_path / "go"
    flooder = start_flooder(zmq_url, topic, count, size, str(go))
    try:
        with robosoa.connect(zmq_url, **FAST, hwm=50) as bus:
            qos = robosoa.QoS(max_bytes=budget, lifespan=lifespan)
            ages: list[float] = []
            held: list[int] = []
            sub: list[robosoa.Subscription] = []

            def slow(msg: robosoa.Message) -> None:
                ages.append(time.time() - msg.timestamp)
                held.append(sub[0].queued_bytes)
                assert len(msg.payload["data"]) == size
                threading.Event().wait(0.03)  # a slow consumer: 30 ms a frame

            sub.append(bus.subscribe(topic, slow, qos=qos))
            heard: list[robosoa.Message] = []
            bus.subscribe(topic + "-probe", heard.append)
            eventually(lambda: heard, timeout=30)
            go.touch()
            flooder.wait_line("sent", timeout=60)
            done = eventually(lambda: (f := _figures(bus, topic)).count + f.dropped == count
                              and f, timeout=60)
            drops = dict(done.drops)
            assert done.count == len(ages) and 0 < done.count < count
            assert set(drops) <= {"bytes", "depth", "lifespan", "lost"} and drops.get("bytes")
            assert max(held) <= budget  # the queue never held more than its byte budget
            assert max(ages) < lifespan + 0.5  # nothing older than its lifespan was handed on
    finally:
        flooder.stop()


