"""Pure parts: versions, the location registry (fake clock), the wire format, statistics."""

from __future__ import annotations

import json

import pytest
from hypothesis import given
from hypothesis import strategies as st

import robosoa
from robosoa.location import LocationService, Registry, ServiceInfo, select
from robosoa.message import Kind, Message, decode, encode
from robosoa.stats import percentile
from robosoa.versions import parse_version, version_matcher


@pytest.mark.parametrize(("spec", "yes", "no"), [
    (">=1.0,<2", ["1.0.0", "1.9.9"], ["0.9", "2.0.0"]),
    ("1.2", ["1.2.0", "1.2.7"], ["1.3.0"]),
    ("1.2.3", ["1.2.3"], ["1.2.4"]),
    ("1.*", ["1.0", "1.8.2"], ["2.0"]),
    ("~=1.4", ["1.4.0", "1.9"], ["2.0", "1.3"]),
    ("~=1.4.2", ["1.4.2", "1.4.9"], ["1.5.0"]),
    ("^2", ["2.0.0", "2.5"], ["3.0", "1.9"]),
    ("!=1.0.0", ["1.0.1"], ["1.0"]),
    (None, ["0.0.1", "9"], ["not-a-version"]),
])
def test_version_ranges(spec: str | None, yes: list[str], no: list[str]) -> None:
    match = version_matcher(spec)
    assert [v for v in yes if not match(v)] == []
    if spec is not None:
        assert [v for v in no if match(v)] == []


def test_bad_versions_are_refused() -> None:
    with pytest.raises(ValueError, match="bad version"):
        parse_version("1.x")
    with pytest.raises(ValueError, match="clause"):
        version_matcher(">>1")


def _info(name: str, version: str, instance: str, ttl: float = 0.0) -> ServiceInfo:
    return ServiceInfo(name, version, ("op",), "request-response", f"inproc://x/{instance}",
                       instance, ttl=ttl)


def test_registry_expires_entries_without_heartbeats() -> None:
    now = [100.0]
    registry = Registry(default_ttl=3.0, clock=lambda: now[0])
    assert registry.register(_info("a", "1.0", "a1"))
    assert registry.register(_info("a", "1.0", "a2", ttl=10.0))
    now[0] += 2.0
    assert not registry.register(_info("a", "1.0", "a1"))  # heartbeat
    now[0] += 2.5
    assert [i.instance for i in registry.entries()] == ["a1", "a2"]
    now[0] += 1.0
    assert [i.instance for i in registry.entries()] == ["a2"]
    now[0] += 10.0
    assert registry.entries() == []


def test_location_protocol_and_federation() -> None:
    remote = LocationService(Registry())
    remote.registry.register(_info("far", "2.0", "f1"))
    local = LocationService(Registry(), peer_factory=lambda _addr: lambda n: remote.lookup(
        n, local=True))
    local.registry.register(_info("near", "1.0", "n1"))
    local.registry.register(_info("near", "1.5", "n2"))
    assert local.handle({"op": "federate", "address": "peer"}) == {"ok": True}
    found = local.handle({"op": "lookup", "name": None})["services"]
    assert [(d["instance"], d["origin"]) for d in found] == [("n2", ""), ("n1", ""),
                                                             ("f1", "peer")]
    assert local.handle({"op": "lookup", "name": "far", "local": True}) == {"services": []}
    assert "error" in local.handle({"op": "register", "service": {"name": "x"}})
    assert "unknown location operation" in local.handle({"op": "nope"})["error"]
    infos = [ServiceInfo.from_dict(d) for d in found]
    assert [i.version for i in select(infos, "near", "<1.5")] == ["1.0"]


def test_wire_format_round_trip_and_rejections() -> None:
    msg = Message(Kind.REQUEST, service="s", operation="o", payload={"a": [1, 2.5, None]},
                  context={"operation": "o"})
    assert decode(encode(msg)) == msg
    reply = msg.reply({"ok": True})
    assert reply.correlation_id == msg.id and reply.kind is Kind.REPLY
    for raw, reason in [(b"\xff", "not valid JSON"), (b"[]", "not a JSON object"),
                        (b'{"kind": "x"}', "unknown message kind"),
                        (b'{"kind": "request", "payload": []}', "payload is not an object"),
                        (b'{"kind": "request", "extra": 1}', "unknown message fields")]:
        with pytest.raises(robosoa.InvalidMessage, match=reason):
            decode(raw)
    with pytest.raises(robosoa.InvalidMessage, match="JSON-compatible"):
        encode(Message(Kind.EVENT, payload={"x": float("nan")}))
    assert json.loads(encode(msg))["kind"] == "request"


def test_percentiles() -> None:
    samples = [float(n) for n in range(1, 101)]
    assert (percentile(samples, 0.5), percentile(samples, 0.99)) == (50.0, 99.0)
    assert percentile([], 0.5) == 0.0


def test_connect_rejects_unknown_transports_and_options() -> None:
    with pytest.raises(robosoa.RobosoaError, match="unknown transport 'carrier'"):
        robosoa.connect("carrier://pigeon")
    with pytest.raises(TypeError, match="unknown bus options"):
        robosoa.connect("inproc", speed=3)
    with pytest.raises(robosoa.RobosoaError, match="bad ZeroMQ endpoint"):
        robosoa.connect("zmq://udp://x")


def test_a_dead_federation_peer_is_skipped_for_a_while() -> None:
    calls: list[str | None] = []

    def dead(name: str | None) -> list[ServiceInfo]:
        calls.append(name)
        raise OSError("peer down")

    local = LocationService(Registry(), peer_factory=lambda _addr: dead)
    local.federate("peer")
    local.registry.register(_info("near", "1.0", "n1"))
    assert local.lookup("far") == [] and calls == ["far"]
    assert [i.instance for i in local.lookup(None)] == ["n1"]
    assert local.lookup("near")[0].instance == "n1"
    assert calls == ["far"]  # backed off; local names never ask peers


@given(st.binary(max_size=200))
def test_decode_never_fails_except_with_invalid_message(raw: bytes) -> None:
    try:
        msg = decode(raw)
    except robosoa.InvalidMessage:
        return
    assert isinstance(msg, Message)


_json = st.recursive(st.none() | st.booleans() | st.integers() | st.floats(allow_nan=False)
                     | st.text(max_size=5),
                     lambda inner: st.lists(inner, max_size=3)
                     | st.dictionaries(st.text(max_size=5), inner, max_size=3), max_leaves=10)


@given(st.dictionaries(st.sampled_from(["kind", "service", "operation", "payload", "context",
                                        "id", "timestamp", "error", "correlation_id", "x"]),
                       _json | st.sampled_from(["request", "reply", "event"]), max_size=6))
def test_any_json_object_decodes_or_is_refused_with_a_reason(data: dict[str, object]) -> None:
    try:
        msg = decode(json.dumps(data).encode())
    except robosoa.InvalidMessage as exc:
        assert str(exc)
        return
    assert decode(encode(msg)) == msg


def test_logs_are_json_lines_with_extra_fields() -> None:
    import io
    import logging

    from robosoa import logs

    stream = io.StringIO()
    handler = logs.configure("INFO", stream=stream)
    try:
        logging.getLogger("robosoa.test").info("registered", extra={"service": "wdb"})
        logging.getLogger("robosoa.test").debug("hidden")
    finally:
        root = logging.getLogger("robosoa")
        root.removeHandler(handler)
        root.propagate = True
        root.setLevel(logging.NOTSET)
    [line] = stream.getvalue().splitlines()
    record = json.loads(line)
    assert (record["level"], record["logger"], record["message"], record["service"]) == (
        "INFO", "robosoa.test", "registered", "wdb")


def test_messages_are_immutable() -> None:
    msg = Message(Kind.EVENT, topic="t", payload={"a": 1})
    with pytest.raises(AttributeError):
        msg.payload = {}  # type: ignore[misc]
    assert msg.with_context(hop=1).context == {"hop": 1} and msg.context == {}
    assert msg.id and msg.timestamp > 0
