"""Fail fast and fail over: deadlines travel with requests, a provider lost mid-request is
noticed by its connection (not at the timeout), idempotent requests move to a live instance,
and later requests keep away from the dead one."""

from __future__ import annotations

import json
import threading
import uuid

import pytest

import robosoa
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import Proc, start_worker
from tests.robosoa.relay import Relay
from tests.robosoa.test_cli import run
from tests.robosoa.util import eventually

pytestmark = pytest.mark.timeout(120)

Pair = tuple[robosoa.Bus, robosoa.Bus]


def _figures(bus: robosoa.Bus, key: str, role: str) -> robosoa.ServiceFigures | None:
    return next((f for f in bus.stats() if (f.key, f.role) == (key, role)), None)


def test_providers_drop_requests_whose_deadline_passed(pair: Pair, name: str) -> None:
    a, b = pair
    release = threading.Event()
    ran: list[int] = []

    def slow(n: int) -> dict[str, int]:
        ran.append(n)
        release.wait(30)
        return {"n": n}

    a.provide(name, {"slow": slow})
    b.wait_for(name)
    futures = [b.request_async(name, "slow", {"n": n}, timeout=0.5) for n in range(6)]
    for future in futures:
        with pytest.raises(robosoa.RequestTimeout, match=name):
            future.result(timeout=30)
    release.set()  # the five queued behind the first are past their deadline now
    dropped = eventually(lambda: (f := _figures(a, name, "provider")) and f.dropped == 5 and f,
                         timeout=20)
    assert dropped.drops == (("deadline", 5),) and len(ran) == 1
    if b.adapter.scheme == "zmq":
        done = run("stats", "--json", "--name", name, "--location",
                   b.adapter.address.removeprefix("zmq://"))
        rows = [r for r in json.loads(done.stdout) if r.get("role") == "provider"]
        assert [(r["dropped"], r["drops"]) for r in rows] == [(5, {"deadline": 5})]


def _busy(proc: Proc) -> None:
    proc.wait_line("busy", timeout=30)


@pytest.fixture
def worker_name() -> str:
    return f"work-{uuid.uuid4().hex[:8]}"


def _pid(proc: Proc) -> int:
    return proc.popen.pid


@pytest.mark.slow
def test_an_idempotent_request_moves_to_a_spare_when_its_provider_dies(
        zmq_url: str, worker_name: str) -> None:
    victim = start_worker(zmq_url, worker_name, "victim", idempotent=True)
    spare: Proc | None = None
    try:
        with robosoa.connect(zmq_url, **FAST) as bus:
            bus.wait_for(worker_name)
            pending = bus.request_async(worker_name, "work", {"n": 1}, timeout=60)
            _busy(victim)
            spare = start_worker(zmq_url, worker_name, "spare", idempotent=True)
            bus.wait_for(worker_name, count=2)
            victim.kill()
            reply = pending.result(timeout=90)  # without fail-over: RequestTimeout at 60 s
            assert reply == {"pid": _pid(spare), "n": 1, "role": "spare"}
            consumer = _figures(bus, worker_name, "consumer")
            assert consumer is not None and consumer.errors == 1  # the lost attempt
    finally:
        victim.stop()
        if spare is not None:
            spare.stop()


@pytest.mark.slow
def test_a_request_that_is_not_idempotent_fails_fast_then_calls_go_to_the_spare(
        zmq_url: str, worker_name: str) -> None:
    victim = start_worker(zmq_url, worker_name, "victim", idempotent=False)
    spare: Proc | None = None
    try:
        with robosoa.connect(zmq_url, **FAST) as bus:
            [info] = bus.wait_for(worker_name)
            pending = bus.request_async(worker_name, "work", {"n": 1}, timeout=60)
            _busy(victim)
            spare = start_worker(zmq_url, worker_name, "spare", idempotent=False)
            bus.wait_for(worker_name, count=2)
            victim.kill()
            with pytest.raises(robosoa.ProviderLost, match=info.instance) as caught:
                pending.result(timeout=90)  # not RequestTimeout: the connection told us
            assert "not idempotent" in str(caught.value)
            replies = [bus.request(worker_name, "work", {"n": n}, timeout=30)
                       for n in range(10)]  # the victim is still registered (TTL 1 s)
            assert {r["pid"] for r in replies} == {_pid(spare)}
            consumer = _figures(bus, worker_name, "consumer")
            assert consumer is not None and consumer.dropped <= 1  # not one per request
    finally:
        victim.stop()
        if spare is not None:
            spare.stop()


def test_idempotent_operations_are_registered_and_checked(pair: Pair, name: str) -> None:
    a, b = pair
    a.provide(name, {"get": lambda: 1, "put": lambda: 2}, idempotent=("get",))
    [info] = b.wait_for(name)
    assert info.idempotent == ("get",)
    with pytest.raises(ValueError, match="unknown operations: nope"):
        a.provide(name, {"get": lambda: 1}, idempotent=("nope",))


def test_the_descriptor_marks_operations_idempotent() -> None:
    from robosoa.descriptor import DescriptorError, loads

    d = loads("""<service name="wdb" version="1.0.0"><pattern>request-response</pattern>
      <operation name="query" idempotent="true"/><operation name="update"/></service>""")
    assert [op.idempotent for op in d.operations] == [True, False]
    with pytest.raises(DescriptorError, match="'idempotent': applies to request-response"):
        loads("""<service name="m" version="1.0.0"><pattern>one-way</pattern>
          <operation name="stop" idempotent="true"/></service>""", source="m.xml")
    with pytest.raises(DescriptorError, match="'maybe' is not a valid value"):
        loads("""<service name="m" version="1.0.0"><pattern>request-response</pattern>
          <operation name="stop" idempotent="maybe"/></service>""", source="m.xml")


@pytest.mark.slow
def test_a_provider_cut_off_by_a_partition_is_noticed_by_heartbeats(
        zmq_url: str, worker_name: str) -> None:
    victim = start_worker(zmq_url, worker_name, "victim", idempotent=False,
                          advertise="127.0.0.2")
    relay: Relay | None = None
    try:
        with robosoa.connect(zmq_url, **FAST) as bus:
            [info] = bus.wait_for(worker_name)
            host, port = info.endpoint.removeprefix("tcp://").split(":")
            assert host == "127.0.0.2"
            relay = Relay((host, int(port)), ("127.0.0.1", int(port)))
            pending = bus.request_async(worker_name, "work", {"n": 1}, timeout=60)
            _busy(victim)
            relay.partition()  # nothing is closed: only ZMTP heartbeats can tell
            with pytest.raises(robosoa.ProviderLost, match=info.instance):
                pending.result(timeout=90)  # link_timeout (3 s), not the request's 60 s
    finally:
        if relay is not None:
            relay.close()
        victim.stop()
