"""Threat: one multipart message holds a provider's (or the location service's) memory.

libzmq assembles every frame of a message before the application sees the first, and
``MAXMSGSIZE`` bounds single frames only: 3,000 frames of 1 MiB from an unauthenticated peer
made a provider with ``max_message`` 1 MiB, ``inbox_size`` 1 and ``hwm`` 1 reach 3.1 GB.
Here the same message goes to a real provider process whose address space is capped at what
it started with plus 1 GiB (without a bound, libzmq's allocation fails and the process
dies): the connection is cut once it is a message and a frame ahead of the provider, the
provider's peak memory grows by a small multiple of that budget, the cut is counted, and the
provider keeps serving. Frames past ``max_total`` are refused as they are read."""

from __future__ import annotations

import json
import textwrap
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
import zmq

import robosoa
from robosoa.transports.zmq_guard import SUPPORTED
from robosoa.transports.zmq_guard import budget as guard_budget
from robosoa.transports.zmq_outlet import META
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import PYTHON, Proc, free_port, start_location
from tests.robosoa.test_hostile_peers import robosoa_stats
from tests.robosoa.util import eventually, raw_publisher

pytestmark = [pytest.mark.timeout(180), pytest.mark.slow,
              pytest.mark.skipif(not SUPPORTED, reason="the guard reads Linux's TCP_INFO")]

MIB = 1024 * 1024
HEADROOM = 1024 * MIB  # address space a process may add to what it has when attacked
OVERSHOOT = 192 * MIB  # what may arrive between two checks of a loaded machine's guard

CAPPED = textwrap.dedent('''
    import resource
    def cap(headroom):
        """Limit this process's address space to what it uses now plus ``headroom``."""
        size = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
        resource.setrlimit(resource.RLIMIT_AS, (size + headroom, size + headroom))
''')

PROVIDER = CAPPED + textwrap.dedent('''
    import json, os, signal, sys, threading, robosoa
    url, name, options = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
    bus = robosoa.connect(url, heartbeat=0.2, ttl=1.0, **options)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    handle = bus.provide(name, {"size": lambda d: {"n": sum(map(len, d))}})
    cap(int(sys.argv[4]))
    print("ready", handle.endpoint, os.getpid(), flush=True)
    stop.wait()
    bus.close()
''')

LOCATION = CAPPED + textwrap.dedent('''
    import runpy, sys
    headroom = int(sys.argv.pop(1))
    sys.argv[0] = "robosoa"
    cap(headroom)
    runpy.run_module("robosoa", run_name="__main__")
''')


def peak(pid: int) -> int:
    """The peak resident memory of process ``pid`` so far, in bytes (VmHWM)."""
    with open(f"/proc/{pid}/status") as status:
        line = next(line for line in status if line.startswith("VmHWM:"))
    return int(line.split()[1]) * 1024


def settled(proc: Proc, pid: int, highest: int, cut: Callable[[], int]) -> None:
    """Wait until the connection is cut, the process died or its peak memory passed
    ``highest`` bytes (whichever comes first; the test then says which)."""
    eventually(lambda: proc.popen.poll() is not None or peak(pid) > highest or cut(),
               timeout=60, every=0.1)


@pytest.fixture(scope="module")
def ctx() -> Iterator[zmq.Context[zmq.Socket[bytes]]]:
    context: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
    yield context
    context.destroy(linger=0)


def provider(url: str, name: str, **options: int) -> tuple[Proc, str, int]:
    proc = Proc([PYTHON, "-c", PROVIDER, url, name, json.dumps(options), str(HEADROOM)])
    _, endpoint, pid = proc.wait_line("ready").split()
    return proc, endpoint, int(pid)


def flood(ctx: zmq.Context[zmq.Socket[bytes]], endpoint: str, frames: int, size: int,
          service: str = "victim") -> zmq.Socket[bytes]:
    """One message of a JSON frame and ``frames`` frames of ``size`` bytes (the same buffer,
    sent without a copy), on a fresh DEALER that queues without a bound."""
    sock = ctx.socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.setsockopt(zmq.SNDHWM, 0)
    sock.connect(endpoint)
    data = b"x" * size
    head = {"kind": "request", "service": service, "operation": "size",
            "payload": {"d": [None] * frames}, "blobs": [["d", n] for n in range(frames)]}
    sock.send(json.dumps(head).encode(), zmq.SNDMORE)
    for n in range(frames):
        sock.send(data, zmq.SNDMORE if n < frames - 1 else 0, copy=False)
    return sock


def cuts(url: str, role: str, key: str) -> int:
    # an instance that did not answer in time is a row with an "error" and no counters
    rows = [r for r in robosoa_stats(url) if r.get("role") == role and r.get("key") == key]
    return sum(int(r["drops"].get("budget", 0)) for r in rows)  # type: ignore[union-attr]


def test_a_3000_frame_message_cannot_hold_gigabytes(zmq_url: str, name: str,
                                                    ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
    options = {"max_message": MIB, "inbox_size": 1, "hwm": 1}  # a message: 1 MiB in all
    budget = guard_budget(MIB)  # two whole messages ahead of the provider, at least 16 MiB
    proc, endpoint, pid = provider(zmq_url, name, **options)
    try:
        before = peak(pid)
        attacker = flood(ctx, endpoint, 3000, MIB)  # 3 GB if libzmq kept it all
        bound = 4 * budget + OVERSHOOT
        settled(proc, pid, before + bound, lambda: cuts(zmq_url, "wire", "inbox"))
        attacker.close(0)
        assert proc.popen.poll() is None, "the provider died"
        grown = peak(pid) - before
        assert grown < bound, f"peak memory grew by {grown / MIB:.0f} MiB"
        with robosoa.connect(zmq_url, **FAST) as consumer:  # still serving
            assert consumer.request(name, "size", {"d": [b"abc", b"de"]}) == {"n": 5}
    finally:
        proc.stop()


def test_frames_past_max_total_are_refused_as_they_are_read(
        zmq_url: str, name: str, ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
    proc, endpoint, _ = provider(zmq_url, name, max_message=MIB, max_total=4 * MIB)
    try:
        fits = flood(ctx, endpoint, 3, 900 * 1024, name)  # 2.7 MB in all: taken
        assert fits.poll(30_000)
        assert json.loads(fits.recv())["payload"] == {"n": 3 * 900 * 1024}
        over = flood(ctx, endpoint, 5, 900 * 1024, name)  # 4.5 MB: within the budget
        assert over.poll(30_000)
        reply = json.loads(over.recv())
        assert reply["context"]["error_type"] == "InvalidMessage", reply
        assert f"more than {4 * MIB} bytes in its frames" in reply["error"]
        fits.close(0)
        over.close(0)
    finally:
        proc.stop()


def test_the_location_service_is_bounded_too(ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
    bind = f"tcp://127.0.0.1:{free_port()}"
    proc = Proc([PYTHON, "-c", LOCATION, str(HEADROOM), "location", "--bind", bind,
                 "--announce", f"tcp://127.0.0.1:{free_port()}", "--max-message", str(MIB)])
    proc.wait_line("robosoa location service on")
    url = f"zmq://{bind}"
    try:
        pid = proc.popen.pid
        before = peak(pid)
        bound = 4 * guard_budget(MIB) + OVERSHOOT  # a request is one frame
        attacker = flood(ctx, bind, 3000, MIB)
        settled(proc, pid, before + bound, lambda: cuts(url, "location", "requests"))
        attacker.close(0)
        assert proc.popen.poll() is None, "the location service died"
        grown = peak(pid) - before
        assert grown < bound, f"peak memory grew by {grown / MIB:.0f} MiB"
        start = time.monotonic()
        with robosoa.connect(url, **FAST) as bus:
            assert bus.services("nothing") == []
        assert time.monotonic() - start < 10
    finally:
        proc.stop()



def _blobs(n: int) -> dict[str, object]:
    return {"payload": {"d": [None] * n}, "blobs": [["d", i] for i in range(n)]}


def test_consumers_and_subscribers_refuse_frames_past_max_total(
        zmq_url: str, name: str, ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
    """What a hostile provider or publisher sends is read frame by frame too: a reply or a
    broadcast of more than ``max_total`` bytes in its frames is dropped and counted."""
    data = b"x" * (900 * 1024)  # five of them: 4.5 MB, over the 4 MiB below
    router = ctx.socket(zmq.ROUTER)
    router.setsockopt(zmq.LINGER, 0)
    port = router.bind_to_random_port("tcp://127.0.0.1")
    with robosoa.connect(zmq_url, **FAST, max_message=MIB, max_total=4 * MIB) as bus:
        bus.adapter.location({"op": "register", "service": {
            "name": name, "version": "1.0.0", "endpoint": f"tcp://127.0.0.1:{port}",
            "instance": f"{name}-fake", "ttl": 10}}, 2.0)
        pending = bus.request_async(name, "op", {}, timeout=3.0)
        assert router.poll(10_000)
        identity, request = router.recv_multipart()
        reply = {"kind": "reply", "correlation_id": json.loads(request)["id"], **_blobs(5)}
        router.send_multipart([identity, json.dumps(reply).encode(), *[data] * 5])
        with pytest.raises(robosoa.RequestTimeout):
            pending.result(timeout=10)
        got: list[robosoa.Message] = []
        bus.subscribe(name, got.append)
        pub = raw_publisher(ctx, bus, f"big-{name}")
        channel = f"t:{name}\0".encode()

        def probe() -> list[robosoa.Message]:
            pub.send(channel + META.pack(7, 1, 0.0) + b'{"kind":"publish","payload":{}}')
            return got

        eventually(probe)  # the subscriber has joined the raw PUB
        big = {"kind": "publish", **_blobs(5)}
        pub.send_multipart([channel + META.pack(7, 2, 0.0) + json.dumps(big).encode(),
                            *[data] * 5])
        pub.send(channel + META.pack(7, 3, 0.0) + b'{"kind":"publish","payload":{"n":3}}')
        eventually(lambda: got[-1].payload == {"n": 3})
        assert all("d" not in m.payload for m in got)
        figures = {(f.role, f.key): f for f in bus.stats()}
        assert figures[("wire", "reply")].errors == 1
        assert figures[("wire", "broadcast")].errors == 1
        pub.close(0)
    router.close(0)


def steady_location(keys: Path, curve: bool) -> tuple[Proc, str, dict[str, object]]:
    """A location service on loopback (CurveZMQ with ``curve``) and the bus options of the
    steady-traffic tests: 1 MiB messages, the bus under test's keys."""
    secure = ["--curve-secret", str(keys / "location.key_secret"),
              "--curve-allow", str(keys / "allow")] if curve else []
    proc, url = start_location(f"tcp://127.0.0.1:{free_port()}",
                               "--announce", f"tcp://127.0.0.1:{free_port()}", *secure)
    options: dict[str, object] = {**FAST, "max_message": MIB}
    if curve:
        options |= {"curve_secret": str(keys / "alice.key_secret"),
                    "curve_allow": str(keys / "allow")}
    return proc, url, options


@pytest.mark.parametrize("curve", [False, True])
def test_steady_traffic_near_the_budget_is_never_cut(keys: Path, curve: bool) -> None:
    """The guard's count of what was taken must keep up with what arrived: 150 requests and
    200 one-way messages of 900 KiB (315 MB through one connection, 19 times its 16 MiB
    budget), the one-way ones in bursts of four, none cut, with and without CURVE."""
    proc, url, options = steady_location(keys, curve)
    blob = b"y" * (900 * 1024)
    try:
        with robosoa.connect(url, **options) as provider, \
                robosoa.connect(url, **options) as consumer:
            seen: list[int] = []
            provider.provide("sink", {"size": lambda d: {"n": len(d)},
                                      "note": lambda d: seen.append(len(d))})
            for n in range(200):
                if n % 4:
                    assert consumer.request("sink", "size", {"d": blob}) == {"n": len(blob)}
                else:
                    for _ in range(4):  # 3.6 MB ahead of the provider, and a request
                        consumer.send("sink", "note", {"d": blob})
            eventually(lambda: len(seen) == 200, timeout=30)
            drops = {(f.role, f.key): dict(f.drops) for f in provider.stats()}
            assert drops.get(("wire", "inbox"), {}).get("budget", 0) == 0
    finally:
        proc.stop()


def test_refused_messages_are_credited_to_their_connection(
        zmq_url: str, name: str, ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
    """A message refused for its size was still taken from its connection: six of 4.6 MB
    through one connection (27.6 MB, past its 16 MiB budget if they were not counted) are
    answered with errors, and the connection is never cut."""
    proc, endpoint, _ = provider(zmq_url, name, max_message=MIB, max_total=4 * MIB)
    sock = ctx.socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(endpoint)
    data = b"x" * (900 * 1024)
    try:
        sock.send(b"")  # answered with an error: connected, and watched from the next check
        assert sock.poll(10_000)
        sock.recv()
        time.sleep(0.5)
        for n in range(6):
            head = {"kind": "request", "service": name, "operation": "size", "id": str(n),
                    "payload": {"d": [None] * 5}, "blobs": [["d", i] for i in range(5)]}
            sock.send_multipart([json.dumps(head).encode(), *[data] * 5], copy=False)
            assert sock.poll(30_000), f"no answer to message {n}"
            reply = json.loads(sock.recv())
            assert reply["context"]["error_type"] == "InvalidMessage", reply
            time.sleep(0.2)  # the guard takes the monitor's news and checks meanwhile
        assert cuts(zmq_url, "wire", "inbox") == 0
    finally:
        sock.close(0)
        proc.stop()
