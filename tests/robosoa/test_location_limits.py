"""The location service's limits on what peers register (pure: fake clock, fake peers)."""

from __future__ import annotations

import dataclasses
import json
import math
import time

import pytest

from robosoa.location import (
    MAX_ENTRY,
    MAX_TEXT,
    Limits,
    LocationService,
    Registry,
    RegistryFull,
    ServiceInfo,
)
from robosoa.transports.zmq_federation import encode_reply


def entry(instance: str, ttl: object = 0.0, **extra: object) -> dict[str, object]:
    return {"name": "svc", "version": "1.0.0", "operations": ["op"], "endpoint": "tcp://h:1",
            "instance": instance, "ttl": ttl, **extra}


@pytest.mark.parametrize("ttl", [math.inf, -math.inf, math.nan, -1.0, "Infinity", "nan"])
def test_ttls_that_never_expire_are_refused(ttl: object) -> None:
    service = LocationService(Registry())
    reply = service.handle({"op": "register", "service": entry("a", ttl)})
    assert "ttl" in reply["error"]
    assert service.registry.entries() == []


def test_long_ttls_are_cut_to_max_ttl() -> None:
    now = [0.0]
    limits = Limits(max_ttl=5.0)
    registry = Registry(default_ttl=3.0, clock=lambda: now[0], limits=limits)
    registry.register(ServiceInfo.from_dict(entry("a", 1e308)))
    now[0] = limits.max_ttl - 0.01
    assert [i.instance for i in registry.entries()] == ["a"]
    now[0] = limits.max_ttl + 0.01
    assert registry.entries() == []


def test_100000_registrations_from_one_peer_stop_at_the_per_peer_limit() -> None:
    limits = Limits()
    frozen = Registry(clock=lambda: 0.0, limits=limits)  # no entry expires however slow this is
    service = LocationService(frozen, limits=limits)
    refused = [service.handle({"op": "register", "service": entry(f"i{n}")}, peer="10.0.0.9")
               for n in range(100_000)]
    assert len(service.registry.entries()) == limits.max_per_peer
    errors = [r["error"] for r in refused if "error" in r]
    assert len(errors) == 100_000 - limits.max_per_peer
    assert "registry full for peer '10.0.0.9'" in errors[0] and "max_per_peer" in errors[0]
    other = service.handle({"op": "register", "service": entry("mine")}, peer="10.0.0.7")
    assert other == {"ok": True, "new": True}  # another host is not starved


def test_the_total_is_bounded_across_peers() -> None:
    limits = Limits(max_entries=10, max_per_peer=4)
    registry = Registry(limits=limits)
    for n in range(30):
        try:
            registry.register(ServiceInfo.from_dict(entry(f"i{n}")), peer=f"host{n % 5}")
        except RegistryFull as exc:
            assert "max_entries" in str(exc) or "max_per_peer" in str(exc)
    assert len(registry.entries()) == limits.max_entries


def test_an_entry_belongs_to_the_peer_that_registered_it() -> None:
    registry = Registry()
    info = ServiceInfo.from_dict(entry("a"))
    registry.register(info, peer="10.0.0.1")
    hijack = ServiceInfo.from_dict(entry("a", endpoint="tcp://evil:1"))
    with pytest.raises(RegistryFull, match="belongs to another peer"):
        registry.register(hijack, peer="10.0.0.66")
    assert not registry.unregister("a", peer="10.0.0.66")
    assert [i.endpoint for i in registry.entries()] == ["tcp://h:1"]
    assert not registry.register(info, peer="10.0.0.1")  # its own heartbeat
    assert registry.unregister("a", peer="10.0.0.1")


@pytest.mark.parametrize(("bad", "reason"), [
    ({"name": "x" * (MAX_TEXT + 1)}, "longer than"),
    ({"operations": ["op"] * 100_000}, "operations"),
    ({"operations": ["o" * MAX_TEXT] * 20}, f"more than {MAX_ENTRY} characters"),
    ({"operations": "op"}, "operations"),
    ({"pid": 1e308 * 10}, "bad service entry"),
    ({"pattern": "telepathy"}, "unknown pattern"),
])
def test_registrations_are_bounded_and_typed(bad: dict[str, object], reason: str) -> None:
    with pytest.raises(ValueError, match=reason):
        ServiceInfo.from_dict(entry("a", **bad))
    with pytest.raises(ValueError, match="not an object"):
        ServiceInfo.from_dict("a")  # type: ignore[arg-type]


def test_federated_lookups_run_at_once_within_one_deadline() -> None:
    peers = 30
    delay = 0.3  # each fake peer takes this long, as a dead ZeroMQ peer does

    def slow(_address: str):  # type: ignore[no-untyped-def]
        def lookup(name: str | None) -> list[ServiceInfo]:
            time.sleep(delay)
            return []
        return lookup

    limits = Limits(max_peers=peers)
    service = LocationService(Registry(), peer_factory=slow, limits=limits)
    for n in range(peers):
        service.federate(f"peer{n}")
    with pytest.raises(ValueError, match="max_peers"):
        service.federate("one-too-many")
    start = time.monotonic()
    assert service.lookup("missing") == []
    elapsed = time.monotonic() - start
    assert elapsed < peers * delay / 3  # one after the other would take peers * delay
    assert elapsed >= min(delay, limits.federation_timeout) * 0.9  # it did wait for them


def test_peers_that_miss_the_deadline_are_backed_off() -> None:
    calls: list[str | None] = []

    def stuck(_address: str):  # type: ignore[no-untyped-def]
        def lookup(name: str | None) -> list[ServiceInfo]:
            calls.append(name)
            time.sleep(2.0)
            return []
        return lookup

    limits = Limits(federation_timeout=0.1)
    service = LocationService(Registry(), peer_factory=stuck, limits=limits)
    service.federate("peer")
    start = time.monotonic()
    assert service.lookup("a") == [] and service.lookup("b") == []
    assert time.monotonic() - start < 1.0 and calls == ["a"]


def test_an_entry_as_a_dict_has_every_field() -> None:
    info = ServiceInfo.from_dict(entry("a", 2.5, group="g", idempotent=["op"], pid=7))
    expected = dataclasses.asdict(info) | {"operations": ["op"], "idempotent": ["op"]}
    assert info.to_dict() == expected
    assert list(info.to_dict()) == [f.name for f in dataclasses.fields(ServiceInfo)]
    assert ServiceInfo.from_dict(info.to_dict()) == info


def test_a_lookup_reply_is_cut_to_its_limit() -> None:
    services = [ServiceInfo.from_dict(entry(f"i{n}", pid=n)).to_dict() for n in range(100)]
    whole, left = encode_reply({"services": services}, 7, 10**6)
    assert left == 0 and json.loads(whole) == {"services": services, "rid": 7}
    for limit in (len(whole) - 1, len(whole) // 2, 300):
        frame, left = encode_reply({"services": services}, 7, limit)
        data = json.loads(frame)
        assert len(frame) <= limit and 0 < left == data["truncated"]
        assert data["services"] == services[: 100 - left] and data["rid"] == 7
    past_64_bits, _ = encode_reply({"services": [{"pid": 10**30}]}, 10**40, 1000)
    assert json.loads(past_64_bits) == {"services": [{"pid": 10**30}], "rid": 10**40}
    assert json.loads(encode_reply({"error": "no"}, "r", 1000)[0]) == {"error": "no", "rid": "r"}
