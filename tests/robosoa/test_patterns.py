"""Every message exchange pattern, with the same test code on the inproc and zmq transports."""

from __future__ import annotations

import threading
from collections.abc import Mapping
from typing import Any

import pytest

import robosoa
from tests.robosoa.util import eventually

pytestmark = pytest.mark.timeout(60)

Pair = tuple[robosoa.Bus, robosoa.Bus]


def test_request_response_with_operation_table(pair: Pair, name: str) -> None:
    a, b = pair
    a.provide(name, {"query": lambda x: {"y": x + 1}, "count": lambda: 3}, version="1.0.0")
    assert b.request(name, "query", {"x": 41}) == {"y": 42}
    assert b.request(name, "count") == {"result": 3}


def test_message_handler_sees_the_envelope(pair: Pair, name: str) -> None:
    a, b = pair
    seen: list[robosoa.Message] = []

    def handler(msg: robosoa.Message) -> Mapping[str, Any]:
        seen.append(msg)
        return {"op": msg.context["operation"], "sum": sum(msg.payload["values"])}

    a.provide(name, handler, operations=("add",))
    assert b.request(name, "add", {"values": [1, 2, 3]}) == {"op": "add", "sum": 6}
    assert seen[0].kind is robosoa.Kind.REQUEST
    assert seen[0].service == name and seen[0].operation == "add"


def test_async_requests_resolve_futures(pair: Pair, name: str) -> None:
    a, b = pair
    a.provide(name, {"square": lambda n: {"n2": n * n}})
    futures = [b.request_async(name, "square", {"n": n}) for n in range(10)]
    assert [f.result(timeout=10)["n2"] for f in futures] == [n * n for n in range(10)]


def test_timeout_names_the_service(pair: Pair, name: str) -> None:
    a, b = pair
    release = threading.Event()
    a.provide(name, {"slow": lambda: release.wait(10)})
    try:
        with pytest.raises(robosoa.RequestTimeout, match=name) as caught:
            b.request(name, "slow", timeout=0.3)
        assert caught.value.service == name
        future = b.request_async(name, "slow", timeout=0.3)
        with pytest.raises(robosoa.RequestTimeout, match=name):
            future.result(timeout=10)
    finally:
        release.set()


def test_missing_service_fails_naming_it(pair: Pair, name: str) -> None:
    _, b = pair
    with pytest.raises(robosoa.ServiceNotFound, match=name):
        b.request(name, "anything", timeout=1.0)
    with pytest.raises(robosoa.ServiceNotFound, match=name):
        b.send(name, "anything")


def test_bad_requests_get_error_replies_and_the_provider_survives(pair: Pair,
                                                                  name: str) -> None:
    a, b = pair

    def validator(operation: str, payload: Mapping[str, Any]) -> None:
        if not isinstance(payload.get("x"), int):
            raise robosoa.InvalidMessage("x must be an integer")

    a.provide(name, {"inc": lambda x: {"x": x + 1}, "boom": lambda x: 1 // 0},
              validator=validator)
    with pytest.raises(robosoa.RemoteInvalidMessage, match="unknown operation 'nope'"):
        b.request(name, "nope", {"x": 1})
    with pytest.raises(robosoa.InvalidMessage, match="x must be an integer"):
        b.request(name, "inc", {"x": "one"})
    with pytest.raises(robosoa.RemoteError, match="ZeroDivisionError") as caught:
        b.request(name, "boom", {"x": 1})
    assert "ZeroDivisionError" in caught.value.reason
    with pytest.raises(robosoa.InvalidMessage, match="JSON"):
        b.request(name, "inc", {"x": object()})
    with pytest.raises(robosoa.InvalidMessage, match="mapping"):
        b.request(name, "inc", [1, 2])  # type: ignore[arg-type]
    assert b.request(name, "inc", {"x": 1}) == {"x": 2}


def test_version_ranges_pick_matching_providers(pair: Pair, name: str) -> None:
    a, b = pair
    a.provide(name, {"v": lambda: {"v": "1.4.0"}}, version="1.4.0")
    a.provide(name, {"v": lambda: {"v": "2.1.0"}}, version="2.1.0")
    assert b.request(name, "v", version=">=1.0,<2") == {"v": "1.4.0"}
    assert b.request(name, "v", version="^2") == {"v": "2.1.0"}
    assert b.request(name, "v") == {"v": "2.1.0"}  # highest version preferred
    with pytest.raises(robosoa.ServiceNotFound, match="version range"):
        b.request(name, "v", version=">=3")


def _publish_until(bus: robosoa.Bus, topic: str, got: list[Any], count: int = 1) -> None:
    n = 0

    def step() -> bool:
        nonlocal n
        bus.publish(topic, {"n": n})
        n += 1
        return len(got) >= count

    eventually(step, every=0.01)


def test_publish_subscribe_callback_and_iterator(pair: Pair, name: str) -> None:
    a, b = pair
    got: list[robosoa.Message] = []
    with b.subscribe(name, got.append) as sub:
        other = b.subscribe(name + "-other", got.append)
        _publish_until(a, name, got, 3)
        assert {m.topic for m in got} == {name}
        assert all(m.kind is robosoa.Kind.PUBLISH for m in got)
        numbers = [m.payload["n"] for m in got]
        assert numbers == sorted(numbers)
        other.close()
    assert sub.get(timeout=0.01) is None  # closed subscriptions yield nothing

    feed = b.subscribe(name + "-iter")
    _publish_until(a, name + "-iter", feed._queue)  # type: ignore[arg-type]
    first = next(iter(feed))
    assert first.topic == name + "-iter"
    feed.close()


def test_one_way_to_one_group_and_all(pair: Pair, name: str) -> None:
    a, b = pair
    inbox: dict[str, list[int]] = {"left": [], "right": []}
    for side in inbox:
        a.provide(name, {"note": lambda n, side=side: inbox[side].append(n)},
                  pattern="oneway", group=side)
    b.wait_for(name, count=2)
    assert b.send(name, "note", {"n": 1}, to="all") == 2
    eventually(lambda: inbox["left"] == [1] and inbox["right"] == [1])
    assert b.send(name, "note", {"n": 2}, to="group", group="right") == 1
    eventually(lambda: inbox["right"] == [1, 2])
    assert b.send(name, "note", {"n": 3}, to="one") == 1
    eventually(lambda: len(inbox["left"]) + len(inbox["right"]) == 4)
    assert inbox["left"][:1] == [1] and 2 not in inbox["left"]
    with pytest.raises(ValueError, match="group"):
        b.send(name, "note", {"n": 4}, to="group")


def test_failed_one_way_emits_an_error_event(pair: Pair, name: str) -> None:
    a, b = pair
    errors: list[robosoa.Message] = []
    with b.on(robosoa.ERROR_EVENT, errors.append):
        a.provide(name, {"note": lambda n: None}, pattern="oneway")
        b.wait_for(name)

        def provoke() -> bool:
            b.send(name, "nope", {"n": 1})
            return any(e.payload["service"] == name for e in errors)

        eventually(provoke, every=0.05)
    event = next(e for e in errors if e.payload["service"] == name)
    assert "unknown operation 'nope'" in event.payload["reason"]
    assert b.request(name, "_ping")["ok"] is True


def test_lightweight_events(pair: Pair, name: str) -> None:
    a, b = pair
    got: list[robosoa.Message] = []
    b.on(name, got.append)
    b.subscribe(name, lambda m: got.append(m))  # a topic of the same name is a different channel

    def step() -> bool:
        a.emit(name, {"bump": True})
        return bool(got)

    eventually(step, every=0.01)
    assert all(m.kind is robosoa.Kind.EVENT and m.payload == {"bump": True} for m in got)


def test_point_to_point_channel_sticks_to_one_instance(pair: Pair, name: str) -> None:
    a, b = pair
    first = a.provide(name, {"who": lambda: {"id": "first"}})
    a.provide(name, {"who": lambda: {"id": "second"}})
    b.wait_for(name, count=2)
    channel = b.channel(name, instance=first.instance)
    assert {channel.request("who")["id"] for _ in range(6)} == {"first"}
    first.close()
    with pytest.raises(robosoa.RobosoaError, match=name):
        channel.request("who", timeout=1.0)
    assert b.request(name, "who") == {"id": "second"}


def test_registration_lookup_and_unregistration(pair: Pair, name: str) -> None:
    a, b = pair
    handle = a.provide(name, {"q": lambda: None, "u": lambda: None}, version="1.2.3",
                       pattern="request-response", group="g1")
    [info] = b.wait_for(name)
    assert (info.name, info.version, info.operations, info.pattern, info.group) == (
        name, "1.2.3", ("q", "u"), "request-response", "g1")
    assert info.endpoint == handle.endpoint and info.instance == handle.instance
    assert b.services(name, ">=1.2,<1.3") and not b.services(name, ">=2")
    handle.close()
    eventually(lambda: not b.services(name))


def test_entries_expire_without_heartbeats_and_come_back(pair: Pair, name: str) -> None:
    a, b = pair
    a.provide(name, {"q": lambda: {"ok": 1}})
    b.wait_for(name)
    a.disconnect()  # heartbeats stop; the entry's TTL (1 s here) runs out
    eventually(lambda: not b.services(name))
    a.reconnect()
    b.wait_for(name)
    assert b.request(name, "q") == {"ok": 1}


def test_slow_subscriber_drops_oldest_and_counts(pair: Pair, name: str) -> None:
    a, b = pair
    release = threading.Event()
    got: list[int] = []

    def slow(msg: robosoa.Message) -> None:
        release.wait(10)
        got.append(msg.payload["n"])

    sub = b.subscribe(name, slow, queue_size=5)
    ready: list[robosoa.Message] = []
    probe = b.subscribe(name, ready.append)
    _publish_until(a, name, ready)
    probe.close()
    for n in range(100, 160):
        a.publish(name, {"n": n})
    eventually(lambda: sub.dropped >= 50)
    release.set()
    eventually(lambda: got and got[-1] == 159)
    assert len(got) <= 5 + 2  # the queue bound, the message in hand, the probe backlog
    figures = {(f.key, f.role): f for f in b.stats()}
    assert figures[(name, "subscriber")].dropped == sub.dropped
    sub.close()


def test_stats_count_requests_and_errors(pair: Pair, name: str) -> None:
    a, b = pair
    a.provide(name, {"ok": lambda: None, "bad": lambda: 1 // 0})
    b.request(name, "ok")
    with pytest.raises(robosoa.RemoteError):
        b.request(name, "bad")
    consumer = {(f.key, f.role): f for f in b.stats()}[(name, "consumer")]
    assert (consumer.count, consumer.errors) == (2, 1)
    remote = b.request(name, "_stats")["figures"]
    provider = next(f for f in remote if f["key"] == name and f["role"] == "provider")
    assert (provider["count"], provider["errors"]) == (2, 1)
    assert provider["p99_ms"] >= provider["p50_ms"] > 0
