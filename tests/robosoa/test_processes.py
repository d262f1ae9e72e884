"""Providers, consumers and location services in separate processes over ZeroMQ."""

from __future__ import annotations

import json
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest
import zmq

import robosoa
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import Proc, free_port, start_location, start_provider, tcp_location
from tests.robosoa.util import eventually, raw_publisher

pytestmark = [pytest.mark.timeout(90), pytest.mark.slow]


@pytest.fixture
def own_location() -> Iterator[tuple[Proc, str]]:
    """A location service this test may kill and restart."""
    proc, url = tcp_location()
    yield proc, url
    proc.stop()


def _name() -> str:
    return f"proc-{uuid.uuid4().hex[:8]}"


def test_provider_process_kill_and_restart(zmq_url: str) -> None:
    name = _name()
    provider = start_provider(zmq_url, name)
    try:
        with robosoa.connect(zmq_url, **FAST) as bus:
            first = bus.request(name, "echo", {"n": 1})
            assert first["echo"] == {"n": 1}
            provider.kill()
            # sent before ZeroMQ noticed the death: ProviderLost ("echo" is not idempotent)
            with pytest.raises((robosoa.RequestTimeout, robosoa.ServiceNotFound,
                                robosoa.ProviderLost), match=name):
                bus.request(name, "echo", {"n": 2}, timeout=1.5)
            eventually(lambda: not bus.services(name), timeout=10)  # TTL ran out: expired
            provider = start_provider(zmq_url, name)
            reply = eventually(lambda: _try(bus, name), timeout=10)
            assert reply["pid"] != first["pid"]
    finally:
        provider.stop()


def _try(bus: robosoa.Bus, name: str) -> dict[str, object] | None:
    try:
        return bus.request(name, "echo", {"n": 3}, timeout=0.5)
    except robosoa.RobosoaError:
        return None


def test_location_restart_is_repopulated_by_heartbeats(own_location: tuple[Proc, str]) -> None:
    proc, url = own_location
    name = _name()
    provider = start_provider(url, name)
    try:
        with robosoa.connect(url, **FAST) as bus:
            assert bus.request(name, "echo", {"n": 1})["echo"] == {"n": 1}
            proc.kill()
            restarted = Proc(proc.args)
            restarted.wait_line("robosoa location service on")
            try:
                eventually(lambda: bus.services(name), timeout=10)
                assert bus.request(name, "echo", {"n": 2})["echo"] == {"n": 2}
                got: list[robosoa.Message] = []
                with bus.subscribe(name, got.append):
                    eventually(lambda: bus.publish(name, {"x": 1}) or got, timeout=10)
            finally:
                restarted.stop()
    finally:
        provider.stop()


def test_ipc_transport_between_processes(tmp_path: Path) -> None:
    proc, url = start_location(f"ipc://{tmp_path}/loc")
    name = _name()
    provider = start_provider(url, name, "2.0.0", "left")
    try:
        with robosoa.connect(url, **FAST) as bus:
            [info] = bus.services(name)
            assert info.endpoint.startswith("ipc://") and info.group == "left"
            assert bus.request(name, "echo", {"n": 7}, version=">=2")["echo"] == {"n": 7}
            assert bus.send(name, "note", {"n": 8}, to="group", group="left") == 1
            eventually(lambda: 8 in bus.request(name, "seen")["seen"])
            got: list[robosoa.Message] = []
            with bus.subscribe("ipc-topic", got.append):
                eventually(lambda: bus.publish("ipc-topic", {"x": 1}) or got)
    finally:
        provider.stop()
        proc.stop()


def test_malformed_bytes_get_an_error_reply_and_the_provider_survives(zmq_url: str) -> None:
    name = _name()
    provider = start_provider(zmq_url, name)
    ctx = zmq.Context()
    raw = ctx.socket(zmq.DEALER)
    raw.setsockopt(zmq.LINGER, 0)
    try:
        with robosoa.connect(zmq_url, **FAST) as bus:
            [info] = bus.services(name)
            raw.connect(info.endpoint)
            for junk in (b"\xff not json", b"[1, 2]", json.dumps({"kind": "bogus"}).encode(),
                         json.dumps({"kind": []}).encode(), b"",
                         json.dumps({"kind": "request", "payload": 3}).encode()):
                raw.send(junk)
                assert raw.poll(5000), f"no reply to {junk!r}"
                reply = json.loads(raw.recv())
                assert reply["kind"] == "reply" and reply["error"]
                assert reply["context"]["error_type"] == "InvalidMessage"
            request = json.dumps({"kind": "request", "operation": "echo"}).encode()
            for frames, why in (([request, b"undeclared"], "binary frames"),
                                ([json.dumps({"kind": "request", "operation": "echo",
                                              "payload": {"a": 1}, "blobs": [["a"]]}).encode(),
                                  b"x"], "null"),
                                ([json.dumps({"kind": "request", "operation": "echo",
                                              "blobs": [["a"]]}).encode()], "blobs")):
                raw.send_multipart(frames)
                assert raw.poll(5000)
                assert why in json.loads(raw.recv())["error"]
            assert bus.request(name, "echo", {"n": 1})["echo"] == {"n": 1}
            # junk broadcast on a topic: subscribers drop it and keep receiving
            got: list[robosoa.Message] = []
            bus.subscribe(name, got.append)
            pub = raw_publisher(ctx, bus, f"junk-{name}")
            try:
                def junk_then_good() -> bool:
                    for frames in ([f"t:{name}\0".encode(), b"{junk"],
                                   [f"t:{name}\0".encode(), b'{"kind": []}'],
                                   [f"t:{name}\0".encode()]):
                        pub.send_multipart(frames)
                    bus.publish(name, {"ok": True})
                    return bool(got)

                eventually(junk_then_good)
                assert all(m.payload == {"ok": True} for m in got)
            finally:
                pub.close()
    finally:
        raw.close()
        ctx.term()
        provider.stop()


def test_one_way_to_groups_across_processes(zmq_url: str) -> None:
    name = _name()
    left = start_provider(zmq_url, name, "1.0.0", "left")
    right = start_provider(zmq_url, name, "1.0.0", "right")
    try:
        with robosoa.connect(zmq_url, **FAST) as bus:
            bus.wait_for(name, count=2)
            assert bus.send(name, "note", {"n": 1}, to="all") == 2
            assert bus.send(name, "note", {"n": 2}, to="group", group="left") == 1
            seen = {}
            for info in bus.services(name):
                channel = bus.channel(name, info.instance)
                seen[info.group] = eventually(
                    lambda c=channel, g=info.group: _seen(c, g), timeout=5)
            assert seen == {"left": [1, 2], "right": [1]}
    finally:
        left.stop()
        right.stop()


def _seen(channel: robosoa.Channel, group: str | None) -> list[int] | None:
    seen = channel.request("seen")["seen"]
    want = 2 if group == "left" else 1
    return seen if len(seen) == want else None


def test_buses_follow_announcements_that_moved_to_a_new_port() -> None:
    port = free_port()
    args = ["--announce", "tcp://127.0.0.1:0"]
    proc, url = start_location(f"tcp://127.0.0.1:{port}", *args)
    name = _name()
    slow = {**FAST, "heartbeat": 0.5}
    try:
        with robosoa.connect(url, **slow) as sub_bus, robosoa.connect(url, **slow) as pub_bus:
            got: list[robosoa.Message] = []
            sub_bus.subscribe(name, got.append)
            eventually(lambda: pub_bus.publish(name, {"n": 1}) or got)
            before = pub_bus.adapter.location({"op": "hello"}, 2.0)["announce"]
            proc.stop()
            proc, _ = start_location(f"tcp://127.0.0.1:{port}", *args)
            after = eventually(lambda: _hello(pub_bus), timeout=10)["announce"]
            assert after != before
            got.clear()
            eventually(lambda: pub_bus.publish(name, {"n": 2}) or got, timeout=10)
            assert got[-1].payload == {"n": 2}
            with robosoa.connect(url, **slow) as late:  # found after the move too
                eventually(lambda: late.publish(name, {"n": 3}) or any(
                    m.payload == {"n": 3} for m in got), timeout=10)
    finally:
        proc.stop()


def _hello(bus: robosoa.Bus) -> dict[str, object] | None:
    try:
        return bus.adapter.location({"op": "hello"}, 0.5)
    except robosoa.RobosoaError:
        return None


def test_requests_fail_naming_the_service_while_the_location_service_is_down(
        own_location: tuple[Proc, str]) -> None:
    proc, url = own_location
    name = _name()
    with robosoa.connect(url, **FAST) as bus:
        proc.kill()
        with pytest.raises(robosoa.ServiceNotFound, match=name) as caught:
            bus.request(name, "echo", timeout=0.5)
        assert "location service" in str(caught.value)
