"""Hostile peers on a real bus: raw ZeroMQ sockets on 127.0.0.1 against a real location
process and real providers. Nothing they send kills a process; bad frames are answered where
a reply exists, dropped otherwise, and counted either way."""

from __future__ import annotations

import json
import time
import uuid
from collections.abc import Iterator

import pytest
import zmq

import robosoa
from robosoa.transports.zmq_location import PEER_TIMEOUT
from robosoa.transports.zmq_outlet import MARK, META
from robosoa.transports.zmq_pubsub import BATCH
from robosoa.wire import MAX_DEPTH
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import free_port, tcp_location
from tests.robosoa.util import eventually, raw_publisher

pytestmark = [pytest.mark.timeout(120), pytest.mark.slow]

DEEP = b"[" * 200_000 + b"]" * 200_000
BAD_FRAMES = [DEEP, b"\xff\xfe", b"NaN", b'{"op": "lookup", "x": Infinity}', b"[1, 2]",
              b'{"op": 5}', b'{"op": "ping", "rid": {"a": 1}}', b'{"op": "lookup", "t": 1e999}']


@pytest.fixture(scope="module")
def ctx() -> Iterator[zmq.Context[zmq.Socket[bytes]]]:
    context: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
    yield context
    context.destroy(linger=0)


def ask(ctx: zmq.Context[zmq.Socket[bytes]], endpoint: str, *frames: bytes,
        timeout: float = 3.0) -> bytes | None:
    """Send ``frames`` from a fresh DEALER; the first reply frame, or None after timeout."""
    sock = ctx.socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    try:
        sock.connect(endpoint)
        sock.send_multipart(list(frames))
        return sock.recv() if sock.poll(int(timeout * 1000)) else None
    finally:
        sock.close(0)


def location_call(ctx: zmq.Context[zmq.Socket[bytes]], url: str,
                  request: dict[str, object]) -> dict[str, object]:
    raw = ask(ctx, url.removeprefix("zmq://"), json.dumps(request).encode())
    assert raw is not None, request
    reply = json.loads(raw)
    assert isinstance(reply, dict)
    return reply


def location_errors(ctx: zmq.Context[zmq.Socket[bytes]], url: str) -> int:
    figures = location_call(ctx, url, {"op": "stats"})["figures"]
    assert isinstance(figures, list)
    return int(figures[0]["errors"])


def test_bad_frames_get_error_replies_and_the_location_service_lives(
        ctx: zmq.Context[zmq.Socket[bytes]]) -> None:
    proc, url = tcp_location()
    try:
        before = location_errors(ctx, url)
        for frame in BAD_FRAMES:
            raw = ask(ctx, url.removeprefix("zmq://"), frame)
            assert raw is not None and "bad" in json.loads(raw)["error"], frame[:40]
        assert ask(ctx, url.removeprefix("zmq://"), b"{}", b"{}") is not None  # two frames
        assert location_call(ctx, url, {"op": "ping", "rid": 7}) == {
            "ok": True, "location": url.removeprefix("zmq://"), "rid": 7}
        assert location_errors(ctx, url) - before == len(BAD_FRAMES) + 1
        assert proc.popen.poll() is None
        rows = robosoa_stats(url)
        assert any(r["role"] == "location" and int(str(r["errors"])) >= len(BAD_FRAMES)
                   for r in rows)
    finally:
        proc.stop()


def robosoa_stats(url: str) -> list[dict[str, object]]:
    from tests.robosoa.test_cli import run

    done = run("stats", "--json", "--location", url)
    assert done.returncode == 0, done.stderr
    rows = json.loads(done.stdout)
    assert isinstance(rows, list)
    return rows


def test_a_provider_answers_every_malformed_frame_and_counts_it(zmq_url: str, name: str,
                                                              ctx: zmq.Context[zmq.Socket[bytes]]
                                                              ) -> None:
    frames = [DEEP, b"\xff", b'{"kind": "request", "timestamp": 1' + b"0" * 400 + b"}",
              b'{"kind": "request", "payload": {"x": NaN}}', b"[]"]
    with robosoa.connect(zmq_url, **FAST) as bus:
        handle = bus.provide(name, {"echo": lambda **kw: kw})
        for frame in frames:
            raw = ask(ctx, handle.endpoint, frame)
            assert raw is not None, frame[:40]
            reply = json.loads(raw)
            assert reply["context"]["error_type"] == "InvalidMessage", reply
        assert ask(ctx, handle.endpoint, b"{}", b"{}") is not None  # extra frames
        assert bus.request(name, "echo", {"a": 1}) == {"a": 1}
        stats = {(f.role, f.key): f for f in bus.stats()}
        assert stats[("wire", "inbox")].errors == len(frames) + 1
        assert stats[("provider", name)].errors == len(frames) + 1


def test_frames_over_max_message_are_dropped_by_zeromq(zmq_url: str, name: str,
                                                       ctx: zmq.Context[zmq.Socket[bytes]]
                                                       ) -> None:
    limit = 64 * 1024
    frame = b'{"kind": "request", "operation": "echo", "payload": {"s": "' + b"x" * (
        4 * limit) + b'"}}'
    with robosoa.connect(zmq_url, **FAST) as small, robosoa.connect(zmq_url, **FAST,
                                                                     max_message=limit) as tight:
        roomy = small.provide(name, {"echo": lambda **kw: {"n": len(kw["s"])}})
        strict = tight.provide(name + "-tight", {"echo": lambda **kw: {"n": len(kw["s"])}})
        assert ask(ctx, roomy.endpoint, frame) is not None  # the default limit takes it
        assert ask(ctx, strict.endpoint, frame, timeout=1.0) is None  # over the limit: dropped
        assert tight.request(name + "-tight", "echo", {"s": "ok"}) == {"n": 2}  # still serving


def test_a_consumer_drops_and_counts_hostile_replies(zmq_url: str, name: str) -> None:
    context: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
    router = context.socket(zmq.ROUTER)
    router.setsockopt(zmq.LINGER, 0)
    port = router.bind_to_random_port("tcp://127.0.0.1")
    info = {"name": name, "version": "1.0.0", "operations": ["op"], "endpoint":
            f"tcp://127.0.0.1:{port}", "instance": f"{name}-fake", "ttl": 10}
    try:
        with robosoa.connect(zmq_url, **FAST) as bus:
            bus.adapter.location({"op": "register", "service": info}, 2.0)
            request = bus.request_async(name, "op", {}, timeout=1.5)
            def arrived() -> list[bytes] | None:
                return router.recv_multipart() if router.poll(100) else None

            frames = eventually(arrived)
            assert frames is not None
            identity = frames[0]
            for junk in (DEEP, b"\xff", b"{}" * 3, b'{"kind": "reply", "x": 1}'):
                router.send_multipart([identity, junk])
            with pytest.raises(robosoa.RequestTimeout):
                request.result(timeout=10)
            stats = {(f.role, f.key): f for f in bus.stats()}
            assert stats[("wire", "reply")].errors == 4
    finally:
        router.close(0)
        context.destroy(linger=0)


def test_malformed_broadcasts_are_dropped_counted_and_harmless(zmq_url: str, name: str,
                                                               ctx: zmq.Context[zmq.Socket[bytes]]
                                                               ) -> None:
    with robosoa.connect(zmq_url, **FAST) as bus:
        got: list[robosoa.Message] = []
        bus.subscribe(name, got.append)
        pub = raw_publisher(ctx, bus, f"junk-{name}")
        channel = f"t:{name}\0".encode()
        try:
            def flood() -> int:
                for junk in (DEEP, b"\xff", b"[" * (MAX_DEPTH + 1)):
                    pub.send_multipart([channel, junk])
                figures = {(f.role, f.key): f for f in bus.stats()}
                found = figures.get(("wire", "broadcast"))
                return found.errors if found else 0

            eventually(flood)  # until the subscriber has found and joined the raw PUB
            bus.publish(name, {"ok": 1})
            eventually(lambda: got)
            assert got[-1].payload == {"ok": 1}
        finally:
            pub.close(0)


def _broadcast(channel: bytes, seq: int, body: bytes, expires: float = 0.0) -> bytes:
    """A broadcast frame as a publisher writes it: channel, stream data, JSON."""
    return channel + META.pack(7, seq, expires) + body


def test_a_burst_keeps_order_counts_gaps_and_bad_frames(zmq_url: str, name: str,
                                                         ctx: zmq.Context[zmq.Socket[bytes]]
                                                         ) -> None:
    """A burst larger than one wake-up's batch (the feed reads and decodes a batch, then
    hands it out): malformed frames, a mark and skipped sequence numbers in the middle;
    both subscriptions get every good message once, in order, and every bad frame and gap
    is counted."""
    burst, skipped, bad = 3 * BATCH, {100, 101, 500}, {50, 300, 700}
    with robosoa.connect(zmq_url, **FAST) as bus:
        called: list[robosoa.Message] = []
        bus.subscribe(name, called.append)
        iterated = bus.subscribe(name)
        pub = raw_publisher(ctx, bus, f"burst-{name}")
        channel = f"t:{name}\0".encode()
        try:
            def probe() -> robosoa.Message | None:
                pub.send(_broadcast(channel, 1, b'{"kind":"publish","payload":{"n":0}}'))
                return iterated.get(timeout=0.05)

            eventually(probe)  # the subscriber has found and joined the raw PUB
            eventually(lambda: called)
            sent = []
            for seq in range(2, burst + 2):
                if seq in skipped:
                    continue
                if seq == 400:  # a mark: "my last number here is 399", and a frame too short
                    pub.send(_broadcast(channel, seq - 1, b"", MARK))
                    pub.send(channel + b"short")
                if seq in bad:
                    pub.send(_broadcast(channel, seq, b'{"kind":"publish","payload":'))
                else:
                    body = {"kind": "publish", "payload": {"n": seq}}
                    pub.send(_broadcast(channel, seq, json.dumps(body).encode()))
                    sent.append(seq)
            got = [msg.payload["n"] for msg in iter(lambda: iterated.get(timeout=2.0), None)]
            assert got == sent
            eventually(lambda: len(called) == len(sent) + 1)
            assert [msg.payload["n"] for msg in called[1:]] == sent
            figures = {(f.role, f.key): f for f in bus.stats()}
            assert figures[("wire", "broadcast")].errors == len(bad) + 1
            assert dict(figures[("subscriber", name)].drops) == {"lost": len(skipped)}
        finally:
            pub.close(0)


def test_ttls_registrations_and_federation_are_bounded(ctx: zmq.Context[zmq.Socket[bytes]]
                                                       ) -> None:
    per_peer, max_ttl = 5, 0.6
    proc, url = tcp_location("--max-per-peer", str(per_peer), "--max-ttl", str(max_ttl))
    try:
        def register(instance: str, ttl: float) -> dict[str, object]:
            return location_call(ctx, url, {"op": "register", "service": {
                "name": "svc", "version": "1.0.0", "endpoint": "tcp://127.0.0.1:9",
                "instance": instance, "ttl": ttl}})

        assert register("forever", 1e308) == {"ok": True, "new": True, "rid": None}
        refused = [register(f"i{n}", 5.0) for n in range(2 * per_peer)]
        assert sum("error" in r for r in refused) == per_peer + 1  # "forever" counts too
        assert "max_per_peer" in str(next(r for r in refused if "error" in r)["error"])
        raw = ask(ctx, url.removeprefix("zmq://"),
                  b'{"op": "register", "service": {"name": "s", "version": "1", '
                  b'"endpoint": "e", "instance": "inf", "ttl": Infinity}}')
        assert raw is not None and "error" in json.loads(raw)

        def gone() -> bool:
            found = location_call(ctx, url, {"op": "lookup", "name": "svc"})["services"]
            return isinstance(found, list) and "forever" not in {s["instance"] for s in found}

        start = time.monotonic()
        eventually(gone, timeout=10)
        assert time.monotonic() - start < max_ttl + 3.0  # not 1e308 seconds
    finally:
        proc.stop()


def test_thirty_silent_federation_peers_cost_one_deadline(ctx: zmq.Context[zmq.Socket[bytes]]
                                                          ) -> None:
    peers = 30
    silent = [ctx.socket(zmq.ROUTER) for _ in range(peers)]  # bound, never answering
    addresses = []
    for sock in silent:
        sock.setsockopt(zmq.LINGER, 0)
        addresses.append(f"tcp://127.0.0.1:{sock.bind_to_random_port('tcp://127.0.0.1')}")
    proc, url = tcp_location("--accept-federate",
                             *(a for address in addresses for a in ("--federate", address)))
    try:
        start = time.monotonic()
        reply = location_call(ctx, url, {"op": "lookup", "name": f"x-{uuid.uuid4().hex}"})
        elapsed = time.monotonic() - start
        assert reply["services"] == []
        assert elapsed < peers * PEER_TIMEOUT / 3  # one after the other: peers * PEER_TIMEOUT
        more = f"tcp://127.0.0.1:{free_port()}"
        over = location_call(ctx, url, {"op": "federate", "address": more})
        assert over == {"ok": True, "rid": None}  # 31 of at most 32 by default
        assert "not 0-65535" in str(location_call(
            ctx, url, {"op": "federate", "address": "tcp://127.0.0.1:99999"})["error"])
    finally:
        proc.stop()
        for sock in silent:
            sock.close(0)
