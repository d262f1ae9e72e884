"""Threat: federation peers that answer slowly and at length stall the location service.

32 fake peers configured with ``--federate``, each answering every request with 1,000
entries just inside its time budget, while a client keeps federated listings in flight: a
lookup of a name registered here, a new bus and a registration must still be answered within
one federation budget (they never wait on peers), and no reply may exceed the consumer's
frame limit. What was left out is counted in the location service's statistics (`robosoa
stats`: late peers, lookups no worker could take, entries cut from a reply)."""

from __future__ import annotations

import json
import time
from collections.abc import Callable, Iterator

import pytest
import zmq

import robosoa
from robosoa.location import PEER_BACKOFF
from robosoa.transports.zmq_federation import PENDING, WORKERS
from tests.robosoa.conftest import FAST
from tests.robosoa.fakepeers import FakePeers, Listings, entries
from tests.robosoa.procs import Proc, tcp_location
from tests.robosoa.test_hostile_peers import robosoa_stats

pytestmark = [pytest.mark.timeout(180), pytest.mark.slow]

PEERS = 32
BUDGET = 1.0  # --federation-timeout of the location service under test, seconds
DELAY = 0.2  # each peer answers this late: inside its own budget (0.3 s)


@pytest.fixture
def peers() -> Iterator[FakePeers]:
    """32 peers answering 1,000 entries of about 900 characters each (0.9 MB a reply)."""
    with FakePeers(PEERS, DELAY, lambda n: entries(1000, f"far-{n}", size=900)) as fake:
        yield fake


def _location(peers: FakePeers, *extra: str, budget: float = BUDGET) -> tuple[Proc, str]:
    flags = [a for address in peers.endpoints for a in ("--federate", address)]
    return tcp_location(*flags, "--federation-timeout", str(budget), *extra)


def _timed(call: Callable[[], object]) -> float:
    start = time.monotonic()
    call()
    return time.monotonic() - start


def test_slow_peers_do_not_stall_local_lookups_or_new_buses(peers: FakePeers) -> None:
    proc, url = _location(peers)
    endpoint = url.removeprefix("zmq://")
    flood: Listings | None = None
    lookups: list[float] = []
    starts: list[float] = []
    try:
        with robosoa.connect(url, **FAST) as near:
            near.provide("near", {"hi": lambda: {"hi": 1}})
            flood = Listings(endpoint, depth=WORKERS + PENDING + 6)  # some find no worker
            until = time.monotonic() + PEER_BACKOFF + 2 * BUDGET  # peers asked again meanwhile
            while time.monotonic() < until:
                lookups.append(_timed(lambda: near.adapter.location(
                    {"op": "lookup", "name": "near"}, 20 * BUDGET)))
                if len(lookups) % 5 == 0:
                    starts.append(_timed(lambda: robosoa.connect(url, **FAST).close()))
                time.sleep(0.2)
            provided = _timed(lambda: near.provide("near-2", {"hi": lambda: {"hi": 2}}))
            assert flood.answered > 0  # the flood was being served meanwhile
        # a local answer never waits on peers: well inside one federation budget
        assert max(lookups) < BUDGET, lookups
        assert max(starts) < 2 * BUDGET, starts  # hello, its publishers' lookup, close
        assert provided < BUDGET, provided
        [location] = [r for r in robosoa_stats(url) if r["role"] == "location"]
        drops = location["drops"]
        assert isinstance(drops, dict) and drops["late"] > 0 and drops["busy"] > 0, drops
    finally:
        if flood is not None:
            flood.stop()
        proc.stop()


@pytest.fixture
def prompt_peers() -> Iterator[FakePeers]:
    """The same 32 peers answering at once (their time is not what is tested here)."""
    with FakePeers(PEERS, 0.0, lambda n: entries(1000, f"far-{n}", size=900)) as fake:
        yield fake


def test_a_federated_reply_never_exceeds_the_consumers_frame_limit(
        prompt_peers: FakePeers) -> None:
    limit = 512 * 1024  # one peer's reply alone is 0.94 MB, the 32 together about 29 MB
    budget = 4 * BUDGET  # time to read some of them even on a busy machine
    proc, url = _location(prompt_peers, budget=budget)
    ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
    try:
        with robosoa.connect(url, **FAST, max_message=limit) as bus:
            listed = bus.adapter.location({"op": "lookup", "name": None}, 5 * budget)
            assert listed["truncated"] > 0 and listed["services"], listed.keys()
            sock = ctx.socket(zmq.DEALER)  # the same, raw: the frame itself
            sock.setsockopt(zmq.LINGER, 0)
            sock.setsockopt(zmq.MAXMSGSIZE, limit)
            sock.connect(url.removeprefix("zmq://"))
            sock.send(json.dumps({"op": "lookup", "name": None, "max_bytes": limit}).encode())
            assert sock.poll(int(5 * budget * 1000))
            frame = sock.recv()
            sock.close(0)
            assert len(frame) <= limit and json.loads(frame)["truncated"] > 0
            location = bus.adapter.location({"op": "stats"}, 5.0)["figures"][0]
            assert location["drops"]["truncated"] >= listed["truncated"]
    finally:
        ctx.destroy(linger=0)
        proc.stop()
