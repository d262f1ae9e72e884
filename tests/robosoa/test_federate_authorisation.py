"""Threat: a client adds federation peers to a location service. `federate` from a client
needs the operator's word (`robosoa location --accept-federate`), is refused under CURVE, an
added peer is never asked in plaintext on a CURVE bus, and what peers return never carries a
key to consumers."""

from __future__ import annotations

import json
import shutil
import socket
from collections.abc import Iterator
from pathlib import Path

import pytest
import zmq

import robosoa
from robosoa.location import LocationService, Registry, ServiceInfo
from tests.robosoa.conftest import FAST
from tests.robosoa.fakepeers import FakePeers, entries
from tests.robosoa.procs import free_port, start_location, tcp_location
from tests.robosoa.test_cli import run
from tests.robosoa.test_cli_untrusted import refused
from tests.robosoa.test_hostile_peers import location_call

pytestmark = [pytest.mark.timeout(120), pytest.mark.slow]

PEER_KEY = "rq:rM>}U?@Lns47E1%kR.o@n%FcmmsL/@{H8]yf7"  # a well-formed Z85 public key


@pytest.fixture(scope="module")
def ctx() -> Iterator[zmq.Context[zmq.Socket[bytes]]]:
    context: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
    yield context
    context.destroy(linger=0)


@pytest.fixture
def peer() -> Iterator[FakePeers]:
    """One fake location service whose entries carry a CURVE key."""
    with FakePeers(1, 0.0, lambda n: entries(3, f"far-{n}", key=PEER_KEY)) as fake:
        yield fake


def test_federate_from_a_client_is_refused_by_default(ctx: zmq.Context[zmq.Socket[bytes]],
                                                      peer: FakePeers) -> None:
    proc, url = tcp_location()
    try:
        reply = location_call(ctx, url, {"op": "federate", "address": peer.endpoints[0]})
        assert "--accept-federate" in str(reply["error"]), reply
        with robosoa.connect(url, **FAST) as bus:
            with pytest.raises(robosoa.RobosoaError, match="--accept-federate"):
                bus.federate(peer.endpoints[0])
            assert bus.services("far-0") == []
        assert peer.asked == [0]
    finally:
        proc.stop()


def test_an_operator_may_accept_federate_and_keys_never_reach_consumers(
        ctx: zmq.Context[zmq.Socket[bytes]], peer: FakePeers) -> None:
    proc, url = tcp_location("--accept-federate")
    try:
        with robosoa.connect(url, **FAST) as bus:
            bus.federate(peer.endpoints[0])
            found = bus.services("far-0")
        assert sorted(i.instance for i in found) == ["far-0-0", "far-0-1", "far-0-2"]
        assert {(i.origin, i.key) for i in found} == {(peer.endpoints[0], "")}
        raw = location_call(ctx, url, {"op": "lookup", "name": "far-0"})
        assert PEER_KEY not in json.dumps(raw)
    finally:
        proc.stop()


def test_entries_from_peers_lose_their_keys() -> None:
    remote = [ServiceInfo.from_dict(e) for e in entries(2, "far", key=PEER_KEY)]
    service = LocationService(Registry(), peer_factory=lambda address: lambda name: remote)
    service.federate("elsewhere")
    assert [(i.key, i.origin) for i in service.lookup("far")] == [("", "elsewhere")] * 2


@pytest.fixture(scope="module")
def keys(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("keys")
    done = run("keys", str(folder), "location", "alice")
    assert done.returncode == 0, done.stderr
    (folder / "allow").mkdir()
    for name in ("location", "alice"):
        shutil.copy(folder / f"{name}.key", folder / "allow")
    return folder


def _curve_flags(keys: Path) -> list[str]:
    return ["--curve-secret", str(keys / "location.key_secret"),
            "--curve-allow", str(keys / "allow")]


def test_federate_is_refused_under_curve_and_the_peer_never_asked(keys: Path,
                                                                  peer: FakePeers) -> None:
    proc, url = start_location(f"tcp://127.0.0.1:{free_port()}",
                               "--announce", f"tcp://127.0.0.1:{free_port()}",
                               *_curve_flags(keys))
    alice = {**FAST, "curve_secret": str(keys / "alice.key_secret"),
             "curve_allow": str(keys / "allow")}
    try:
        with robosoa.connect(url, **alice) as bus:  # an allowed key: still not authorised
            with pytest.raises(robosoa.RobosoaError, match="CURVE"):
                bus.federate(peer.endpoints[0])
            assert bus.services("far-0") == [] and bus.services() == []
        assert peer.asked == [0]  # nothing went to it, in plaintext or otherwise
    finally:
        proc.stop()


@pytest.mark.parametrize("flag", [["--accept-federate"], ["--federate", "tcp://127.0.0.1:9"]])
def test_federation_flags_with_curve_are_refused_before_binding(keys: Path,
                                                               flag: list[str]) -> None:
    port = free_port()
    refused(run("location", "--bind", f"tcp://127.0.0.1:{port}", *flag, *_curve_flags(keys)),
            "CURVE")
    with socket.socket() as sock:  # nothing was bound: the port is still free
        sock.bind(("127.0.0.1", port))
