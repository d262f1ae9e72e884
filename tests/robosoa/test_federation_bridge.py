"""Location-service federation and protocol bridging, on both transports."""

from __future__ import annotations

import uuid
from collections.abc import Iterator

import pytest

import robosoa
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import tcp_location
from tests.robosoa.util import eventually

pytestmark = pytest.mark.timeout(60)


@pytest.fixture(params=["inproc", "zmq"])
def two_urls(request: pytest.FixtureRequest) -> Iterator[tuple[str, str]]:
    """Two separate location services of one transport."""
    if request.param == "inproc":
        yield f"inproc://fed-a-{uuid.uuid4().hex[:6]}", f"inproc://fed-b-{uuid.uuid4().hex[:6]}"
        return
    (one, first), (two, second) = tcp_location("--accept-federate"), tcp_location()
    yield first, second
    one.stop()
    two.stop()


def test_federated_location_answers_for_services_learned_there(two_urls: tuple[str, str],
                                                               name: str) -> None:
    here, there = two_urls
    with robosoa.connect(there, **FAST) as remote, robosoa.connect(here, **FAST) as local:
        remote.provide(name, {"where": lambda: {"at": "there"}}, version="3.1.0")
        with pytest.raises(robosoa.ServiceNotFound):
            local.request(name, "where")
        local.federate(there)
        [info] = eventually(lambda: local.services(name))
        assert info.origin == there.removeprefix("zmq://") and info.version == "3.1.0"
        assert local.request(name, "where", version="~=3.1") == {"at": "there"}
        assert not remote.services(name + "-x")


def test_bridge_inproc_and_zmq_both_ways(zmq_url: str, name: str) -> None:
    embedded = robosoa.connect(f"inproc://bridge-{uuid.uuid4().hex[:6]}", **FAST)
    network = robosoa.connect(zmq_url, **FAST)
    client = robosoa.connect(zmq_url, **FAST)
    try:
        embedded.provide(name, {"add": lambda a, b: {"sum": a + b}}, version="1.1.0")
        network.provide(name + "-net", {"twice": lambda x: {"x2": 2 * x}})
        with robosoa.bridge(embedded, network, services=[name], topics=[name + "-pose"],
                            both_ways=True), \
                robosoa.bridge(network, embedded, services=[name + "-net"]):
            # a zmq client calls the in-process service through the bridge, and back
            assert client.request(name, "add", {"a": 2, "b": 3}) == {"sum": 5}
            assert embedded.request(name + "-net", "twice", {"x": 4}) == {"x2": 8}
            with pytest.raises(robosoa.InvalidMessage, match="bad arguments"):
                client.request(name, "add", {"a": 1})
            [info] = client.services(name)
            assert info.version == "1.1.0" and info.operations == ("add",)
            # topics cross in both directions, without echoing back
            from_net: list[robosoa.Message] = []
            from_embedded: list[robosoa.Message] = []
            embedded.subscribe(name + "-pose", from_net.append)
            client.subscribe(name + "-pose", from_embedded.append)
            eventually(lambda: client.publish(name + "-pose", {"src": "net"}) or any(
                m.payload == {"src": "net"} for m in from_net))
            eventually(lambda: embedded.publish(name + "-pose", {"src": "emb"}) or any(
                m.payload == {"src": "emb"} for m in from_embedded))
            assert all(m.payload["src"] in ("net", "emb") for m in from_net + from_embedded)
    finally:
        client.close()
        network.close()
        embedded.close()
