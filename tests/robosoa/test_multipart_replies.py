"""Threat: one multipart reply or broadcast holds a consumer's or a subscriber's memory.

A provider another team runs answers a consumer, and any registered publisher reaches every
subscriber; libzmq assembles a whole multipart message before the application sees its
first frame (test_multipart_memory.py says why). Here a raw ROUTER registered as a provider
(or posing as the location service) answers a real consumer process with one reply of
3,000 frames of 1 MiB, and a raw PUB registered as a publisher sends one such broadcast to
a real subscriber process; each process's address space is capped at what it started with
plus 1 GiB (without a bound libzmq's allocation fails and it dies). The connection is cut
once it is its budget ahead of the process, the peak memory grows by a small multiple of
that budget, the cut is counted, the request fails at once with a clear error instead of
waiting for its timeout, and the subscriber, reconnected, receives later good messages from
both publishers."""

from __future__ import annotations

import json
import textwrap
from collections.abc import Iterator
from pathlib import Path

import pytest
import zmq

import robosoa
from robosoa.transports.zmq_guard import SUPPORTED
from robosoa.transports.zmq_guard import budget as guard_budget
from robosoa.transports.zmq_outlet import META
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import PYTHON, Proc
from tests.robosoa.test_multipart_memory import (
    CAPPED,
    HEADROOM,
    MIB,
    OVERSHOOT,
    cuts,
    peak,
    settled,
    steady_location,
)
from tests.robosoa.util import eventually, raw_publisher

pytestmark = [pytest.mark.timeout(180), pytest.mark.slow,
              pytest.mark.skipif(not SUPPORTED, reason="the guard reads Linux's TCP_INFO")]

FRAMES = 3000  # of 1 MiB: 3 GB if libzmq kept them all
WAIT = 60.0  # seconds the consumer's request may take: a cut must end it long before
OPTIONS = {"max_message": MIB, "hwm": 1}  # a message: 1 MiB in all

CONSUMER = CAPPED + textwrap.dedent('''
    import json, os, signal, sys, threading, time, robosoa
    url, name, options, headroom, wait = sys.argv[1:6]
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    start = time.monotonic()
    bus = None
    try:
        if name:  # a request to a provider; else the location service's reply is the attack
            bus = robosoa.connect(url, heartbeat=0.2, ttl=1.0, **json.loads(options))
            bus.services(name)
            cap(int(headroom))
            print("ready", os.getpid(), flush=True)
            start = time.monotonic()
            bus.request(name, "op", {}, timeout=float(wait))
        else:
            cap(int(headroom))
            print("ready", os.getpid(), flush=True)
            bus = robosoa.connect(url, location_timeout=float(wait), **json.loads(options))
        outcome = "answered"
    except robosoa.RobosoaError as exc:
        outcome = f"{type(exc).__name__}: {exc}"
    seconds = time.monotonic() - start
    drops = {} if bus is None else {f"{f.role}/{f.key}": dict(f.drops) for f in bus.stats()}
    print("done", json.dumps({"outcome": outcome, "seconds": seconds, "drops": drops}),
          flush=True)
    stop.wait()
''')

SUBSCRIBER = CAPPED + textwrap.dedent('''
    import json, os, signal, sys, threading, robosoa
    url, topic, options, headroom = sys.argv[1:5]
    bus = robosoa.connect(url, heartbeat=0.2, ttl=1.0, **json.loads(options))
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    bus.subscribe(topic, lambda msg: print("got", json.dumps(msg.payload), flush=True))
    cap(int(headroom))
    print("ready", os.getpid(), flush=True)
    stop.wait()
    bus.close()
''')


@pytest.fixture(scope="module")
def ctx() -> Iterator[zmq.Context[zmq.Socket[bytes]]]:
    context: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
    yield context
    context.destroy(linger=0)


def hostile_router(ctx: zmq.Context[zmq.Socket[bytes]]) -> tuple[zmq.Socket[bytes], str]:
    """A raw ROUTER on 127.0.0.1 that queues without a bound (ROUTER drops past its HWM)."""
    router = ctx.socket(zmq.ROUTER)
    router.setsockopt(zmq.LINGER, 0)
    router.setsockopt(zmq.SNDHWM, 0)
    port = router.bind_to_random_port("tcp://127.0.0.1")
    return router, f"tcp://127.0.0.1:{port}"


def huge(sock: zmq.Socket[bytes], head: list[bytes], frames: int = FRAMES) -> None:
    """``head`` (its last frame a JSON message naming ``frames`` blobs) and ``frames`` frames
    of 1 MiB, the same buffer sent without a copy."""
    data = b"x" * MIB
    for part in head:
        sock.send(part, zmq.SNDMORE)
    for n in range(frames):
        sock.send(data, zmq.SNDMORE if n < frames - 1 else 0, copy=False)


def blobs(frames: int = FRAMES) -> dict[str, object]:
    return {"payload": {"d": [None] * frames}, "blobs": [["d", n] for n in range(frames)]}


def outcome(proc: Proc, pid: int, before: int) -> dict[str, object]:
    """What the consumer printed once its request ended, after checking its memory."""
    bound = 4 * guard_budget(MIB) + OVERSHOOT
    settled(proc, pid, before + bound, lambda: not proc.lines.empty())
    assert proc.popen.poll() is None, "the consumer died"
    grown = peak(pid) - before
    assert grown < bound, f"peak memory grew by {grown / MIB:.0f} MiB"
    done = json.loads(proc.wait_line("done").partition(" ")[2])
    assert isinstance(done, dict)
    return done


def test_a_3000_frame_reply_cannot_hold_a_consumers_memory(
        zmq_url: str, name: str, ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
    router, endpoint = hostile_router(ctx)
    with robosoa.connect(zmq_url, **FAST) as bus:
        bus.adapter.location({"op": "register", "service": {
            "name": name, "version": "1.0.0", "endpoint": endpoint,
            "instance": f"{name}-hostile", "ttl": 30}}, 2.0)
        proc = Proc([PYTHON, "-c", CONSUMER, zmq_url, name, json.dumps(OPTIONS),
                     str(HEADROOM), str(WAIT)])
        try:
            pid = int(proc.wait_line("ready").split()[1])
            before = peak(pid)
            assert router.poll(10_000)
            identity, request = router.recv_multipart()
            reply = {"kind": "reply", "correlation_id": json.loads(request)["id"], **blobs()}
            huge(router, [identity, json.dumps(reply).encode()])
            done = outcome(proc, pid, before)
            # not idempotent, so not tried elsewhere: the provider is lost, at once
            assert str(done["outcome"]).startswith("ProviderLost"), done
            assert float(done["seconds"]) < WAIT / 2, done  # type: ignore[arg-type]
            drops = done["drops"]
            assert isinstance(drops, dict) and drops.get("wire/reply") == {"budget": 1}, done
        finally:
            proc.stop()
            router.close(0)


def test_a_3000_frame_location_reply_cannot_hold_a_consumers_memory(
        ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
    router, endpoint = hostile_router(ctx)
    proc = Proc([PYTHON, "-c", CONSUMER, f"zmq://{endpoint}", "", json.dumps(OPTIONS),
                 str(HEADROOM), str(WAIT)])
    try:
        pid = int(proc.wait_line("ready").split()[1])
        before = peak(pid)
        assert router.poll(10_000)
        identity, request = router.recv_multipart()
        reply = {"rid": json.loads(request)["rid"], "announce": "tcp://127.0.0.1:9", **blobs()}
        huge(router, [identity, json.dumps(reply).encode()])
        done = outcome(proc, pid, before)
        assert done["outcome"] == (f"RobosoaError: location service at {endpoint}: "
                                   "connection lost"), done
        assert float(done["seconds"]) < WAIT / 2, done  # type: ignore[arg-type]
    finally:
        proc.stop()
        router.close(0)


def test_a_3000_frame_broadcast_cannot_hold_a_subscribers_memory(
        zmq_url: str, name: str, ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
    proc = Proc([PYTHON, "-c", SUBSCRIBER, zmq_url, name, json.dumps(OPTIONS),
                 str(HEADROOM)])
    seen: list[str] = []

    def got(text: str) -> bool:
        while not proc.lines.empty():
            seen.append(proc.lines.get())
        return f"got {text}" in seen

    try:
        pid = int(proc.wait_line("ready").split()[1])
        with robosoa.connect(zmq_url, **FAST) as bus:
            bus.advertise(name)
            pub = raw_publisher(ctx, bus, f"big-{name}")
            pub.setsockopt(zmq.SNDHWM, 0)  # before the subscriber connects: no drop
            channel = f"t:{name}\0".encode()
            seq = iter(range(1, 1_000_000))

            def raw(payload: dict[str, object]) -> bool:
                body = json.dumps({"kind": "publish", "payload": payload}).encode()
                pub.send(channel + META.pack(7, next(seq), 0.0) + body)
                return got(json.dumps(payload))

            def good(payload: dict[str, object]) -> bool:
                bus.publish(name, payload)
                return got(json.dumps(payload))

            eventually(lambda: raw({"from": "raw"}) and good({"from": "good"}), timeout=20)
            before = peak(pid)
            head = {"kind": "publish", **blobs()}
            huge(pub, [channel + META.pack(7, next(seq), 0.0) + json.dumps(head).encode()])
            bound = 4 * guard_budget(MIB) + OVERSHOOT
            settled(proc, pid, before + bound, lambda: cuts(zmq_url, "wire", "broadcast"))
            assert proc.popen.poll() is None, "the subscriber died"
            grown = peak(pid) - before
            assert grown < bound, f"peak memory grew by {grown / MIB:.0f} MiB"
            assert cuts(zmq_url, "wire", "broadcast") == 1
            eventually(lambda: good({"n": 3}), timeout=10)
            eventually(lambda: raw({"n": 4}), timeout=10)  # ZeroMQ reconnected to it
            assert not [line for line in seen if '"d"' in line]
            pub.close(0)
    finally:
        proc.stop()


@pytest.mark.parametrize("curve", [False, True])
def test_steady_replies_and_broadcasts_near_the_budget_are_never_cut(keys: Path,
                                                                     curve: bool) -> None:
    """What the guard credits a consumer's and a subscriber's connections with must keep up
    with what arrives: 150 replies and 200 broadcasts of 900 KiB (135 MB and 180 MB through
    one connection each, 8 and 11 times its 16 MiB budget), broadcasts in bursts of four,
    none cut, with and without CURVE."""
    proc, url, options = steady_location(keys, curve)
    blob = b"y" * (900 * 1024)
    try:
        with robosoa.connect(url, **options) as provider, \
                robosoa.connect(url, **options) as consumer:
            provider.provide("source", {"blob": lambda: {"d": blob}})
            for _ in range(150):
                assert consumer.request("source", "blob", {}) == {"d": blob}
            got: list[robosoa.Message] = []
            consumer.subscribe("blobs", got.append)
            eventually(lambda: provider.publish("blobs", {"n": -1}) or got, timeout=20)
            for n in range(0, 200, 4):
                for k in range(n, n + 4):
                    provider.publish("blobs", {"n": k, "d": blob})
                eventually(lambda n=n: got[-1].payload["n"] == n + 3, timeout=30)  # type: ignore[misc]
            assert [m.payload["n"] for m in got if m.payload["n"] >= 0] == list(range(200))
            drops = {(f.role, f.key): dict(f.drops) for f in consumer.stats()}
            assert drops.get(("wire", "reply"), {}).get("budget", 0) == 0
            assert drops.get(("wire", "broadcast"), {}).get("budget", 0) == 0
    finally:
        proc.stop()
