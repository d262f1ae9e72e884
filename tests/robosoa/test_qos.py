"""Quality of service of streams: history depth, byte budget, lifespan, keep-latest and
reliable delivery, per subscription and per topic, on both transports; every drop counted
with its reason."""

from __future__ import annotations

import json
import threading
import time
import uuid
from collections.abc import Iterator

import pytest

import robosoa
from robosoa.message import Kind, Message
from robosoa.stats import Counter
from robosoa.subscription import Subscription
from tests.robosoa.conftest import FAST
from tests.robosoa.util import eventually

pytestmark = pytest.mark.timeout(120)


def _msg(n: int, age: float = 0.0) -> Message:
    return Message(Kind.PUBLISH, topic="t", payload={"n": n}, timestamp=time.time() - age)


def _drained(sub: Subscription) -> list[int]:
    out = []
    while (msg := sub.get(timeout=0)) is not None:
        out.append(msg.payload["n"])
    return out


def _drops(counter: Counter) -> dict[str, int]:
    return dict(counter.figures().drops)


def test_depth_and_byte_budget_drop_the_oldest_and_say_why() -> None:
    counter = Counter("t", "subscriber")
    deep = Subscription("t", robosoa.QoS(depth=3), counter)
    for n in range(10):
        deep.sink(_msg(n), 10)
    assert _drained(deep) == [7, 8, 9] and _drops(counter) == {"depth": 7}
    counter = Counter("t", "subscriber")
    budget = Subscription("t", robosoa.QoS(max_bytes=250), counter)
    for n in range(10):
        budget.sink(_msg(n), 100)
        assert budget.queued_bytes <= 250
    budget.sink(_msg(10), 1000)  # larger than the budget: held alone
    assert budget.queued_bytes == 1000
    assert _drained(budget) == [10] and _drops(counter) == {"bytes": 10}


def test_keep_latest_holds_only_the_newest() -> None:
    counter = Counter("t", "subscriber")
    latest = Subscription("t", robosoa.QoS(keep_latest=True, depth=50), counter)
    for n in range(5):
        latest.sink(_msg(n), 10)
    assert _drained(latest) == [4] and _drops(counter) == {"depth": 4}


def test_lifespan_drops_stale_messages_on_arrival_and_in_the_queue() -> None:
    counter = Counter("t", "subscriber")
    sub = Subscription("t", robosoa.QoS(lifespan=5.0), counter)
    sub.sink(_msg(1, age=10.0))  # stale already: its own lifespan
    sub.sink(_msg(2), expires=time.time() - 1)  # stale already: its publisher's lifespan
    assert _drops(counter) == {"lifespan": 2} and sub.queued_bytes == 0
    sub.sink(_msg(3, age=4.9))  # goes stale in the queue (0.1 s)
    sub.sink(_msg(4), expires=time.time() + 0.1)  # goes stale in the queue (its publisher's)
    sub.sink(_msg(5))
    start = time.time()
    eventually(lambda: time.time() > start + 0.2)
    assert _drained(sub) == [5] and _drops(counter) == {"lifespan": 4}


def test_a_reliable_subscription_refuses_instead_of_dropping() -> None:
    counter = Counter("t", "subscriber")
    told: list[bool] = []
    sub = Subscription("t", robosoa.QoS(depth=2, reliable=True), counter,
                       on_room=lambda: told.append(True))
    assert sub.sink(_msg(1), 10, 0.0, True) and sub.sink(_msg(2), 10, 0.0, True)
    assert not sub.sink(_msg(3), 10, 0.0, True)  # full: the transport holds it back
    assert sub.sink(_msg(3), 10, 0.0, False)  # a best-effort stream: the oldest goes
    assert sub.get(timeout=0) is not None and told == [True]
    assert _drops(counter) == {"depth": 1}


@pytest.mark.parametrize(("settings", "why"), [
    ({"depth": 0}, "depth"), ({"max_bytes": 0}, "max_bytes"), ({"lifespan": -1.0}, "lifespan"),
    ({"lifespan": float("inf")}, "lifespan"), ({"block": 1e9}, "block"),
    ({"keep_latest": True, "reliable": True}, "reliable drops none"),
])
def test_bad_settings_are_refused(settings: dict[str, object], why: str) -> None:
    with pytest.raises(ValueError, match=why):
        robosoa.QoS(**settings)  # type: ignore[arg-type]


@pytest.fixture
def buses(url: str) -> Iterator[tuple[robosoa.Bus, robosoa.Bus]]:
    """A publisher bus and a subscriber bus with small ZeroMQ queues (zmq) so that a stuck
    subscriber pushes back on its publisher within a few hundred messages."""
    a = robosoa.connect(url, **FAST, hwm=10)
    b = robosoa.connect(url, **FAST, hwm=10)
    yield a, b
    b.close()
    a.close()


def _live(publisher: robosoa.Bus, subscriber: robosoa.Bus, topic: str) -> None:
    """Publish on a probe topic until the subscriber hears it: both ends are joined."""
    heard: list[robosoa.Message] = []
    with subscriber.subscribe(topic + "-probe", heard.append):
        eventually(lambda: publisher.publish(topic + "-probe", {}) or heard, timeout=20)


def test_reliable_topics_wait_for_a_stuck_subscriber_and_lose_nothing(
        buses: tuple[robosoa.Bus, robosoa.Bus]) -> None:
    publisher, subscriber = buses
    topic = f"orders-{uuid.uuid4().hex[:8]}"
    release = threading.Event()
    got: list[int] = []

    def stuck(msg: robosoa.Message) -> None:
        release.wait(60)
        got.append(msg.payload["n"])

    publisher.advertise(topic, robosoa.QoS(reliable=True, block=0.5))
    subscriber.subscribe(topic, stuck, qos=robosoa.QoS(reliable=True, depth=5))
    _live(publisher, subscriber, topic)
    sent = 0
    with pytest.raises(robosoa.PublishTimeout, match=topic):
        for sent in range(20_000):
            publisher.publish(topic, {"n": sent, "pad": b"x" * 10_000})
    release.set()
    eventually(lambda: len(got) == sent, timeout=60)  # every one that went, in order
    assert got == list(range(sent))
    figures = {(f.key, f.role): f for f in [*publisher.stats(), *subscriber.stats()]}
    assert figures[(topic, "publisher")].drops == (("blocked", 1),)
    assert figures[(topic, "subscriber")].dropped == 0


def test_keep_latest_on_a_burst(pair: tuple[robosoa.Bus, robosoa.Bus]) -> None:
    publisher, subscriber = pair  # ZeroMQ's queues (hwm 1000) take a burst of 20 whole
    topic = f"pose-{uuid.uuid4().hex[:8]}"
    latest = subscriber.subscribe(topic, qos=robosoa.QoS(keep_latest=True))
    _live(publisher, subscriber, topic)
    for n in range(20):
        publisher.publish(topic, {"n": n})
    eventually(lambda: _figures(subscriber, topic).dropped == 19, timeout=20)
    newest = latest.get(timeout=5)
    assert newest is not None and newest.payload == {"n": 19}
    assert _figures(subscriber, topic).drops == (("depth", 19),)


def test_a_publishers_lifespan_drops_what_waited_too_long(
        buses: tuple[robosoa.Bus, robosoa.Bus]) -> None:
    publisher, subscriber = buses
    topic = f"scan-{uuid.uuid4().hex[:8]}"
    release = threading.Event()
    delivered: list[robosoa.Message] = []

    def slow(msg: robosoa.Message) -> None:
        release.wait(60)
        delivered.append(msg)

    publisher.advertise(topic, robosoa.QoS(lifespan=0.3))
    subscriber.subscribe(topic, slow)  # the subscription itself would keep them for ever
    _live(publisher, subscriber, topic)
    for n in range(20):
        publisher.publish(topic, {"n": n})
    published = time.time()
    eventually(lambda: time.time() > published + 0.5)  # all of them are stale by now
    release.set()
    figures = eventually(lambda: (f := _figures(subscriber, topic)).count + f.dropped == 20
                         and f, timeout=20)
    assert figures.count == 1 and [m.payload["n"] for m in delivered] == [0]
    assert dict(figures.drops).get("lifespan", 0) >= 1
    assert set(dict(figures.drops)) <= {"lifespan", "lost"}


def _figures(bus: robosoa.Bus, key: str) -> robosoa.ServiceFigures:
    return next(f for f in bus.stats() if (f.key, f.role) == (key, "subscriber"))


def test_a_bus_that_only_listens_shows_its_drops_in_robosoa_stats(zmq_url: str) -> None:
    from tests.robosoa.test_cli import run

    topic = f"depth-{uuid.uuid4().hex[:8]}"
    with robosoa.connect(zmq_url, **FAST) as publisher, \
            robosoa.connect(zmq_url, **FAST) as listener:
        listener.subscribe(topic, qos=robosoa.QoS(depth=2))
        _live(publisher, listener, topic)
        for n in range(10):
            publisher.publish(topic, {"n": n})
        eventually(lambda: _figures(listener, topic).dropped == 8, timeout=20)
        done = run("stats", "--json", "--location", zmq_url.removeprefix("zmq://"))
        assert done.returncode == 0, done.stderr
        rows = [r for r in json.loads(done.stdout)
                if r.get("key") == topic and r.get("role") == "subscriber"]
        assert [(r["dropped"], r["drops"]) for r in rows] == [(8, {"depth": 8})]
        assert rows[0]["instance"].startswith("robosoa.bus-")


def test_descriptors_declare_the_qos_of_their_streams() -> None:
    from robosoa.descriptor import DescriptorError, loads

    d = loads("""<service name="lidar" version="1.0.0"><pattern>publish-subscribe</pattern>
      <operation name="scan"><qos keep-latest="true" lifespan="0.25" max-bytes="1048576"/>
        <param name="ranges" type="bytes"/></operation>
      <operation name="alarm"><qos reliable="true" block="2" depth="50"/></operation>
      <operation name="plain"/></service>""")
    assert d.qos("scan") == robosoa.QoS(keep_latest=True, lifespan=0.25, max_bytes=1048576)
    assert d.qos("alarm") == robosoa.QoS(reliable=True, block=2.0, depth=50)
    assert d.qos("plain") == robosoa.QoS()
    with pytest.raises(DescriptorError) as caught:
        loads("""<service name="x" version="1.0.0"><pattern>event</pattern>
          <operation name="a"><qos keep-latest="true" reliable="true"/></operation>
          <operation name="b"><qos depth="9999999999999999999999"/></operation>
          <operation name="c"><qos block="7200"/></operation></service>""", source="x.xml")
    assert [str(p) for p in caught.value.problems] == [
        "x.xml:2: operation 'a' qos: keep-latest drops every message but the newest; "
        "reliable drops none",
        "x.xml:3: operation 'b' qos: depth must be a whole number from 1 to 1000000",
        "x.xml:4: operation 'c' qos: block must be a number of seconds from 0 to 3600",
    ]
    with pytest.raises(DescriptorError, match="applies to publish-subscribe and event only"):
        loads("""<service name="x" version="1.0.0"><pattern>request-response</pattern>
          <operation name="a"><qos depth="1"/></operation></service>""")
