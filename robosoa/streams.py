"""Publish/subscribe and events of one bus (part of the MessagingProxy): the publishing side
of each stream's QoS, subscriptions and their counters, on any transport."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Mapping
from typing import Any

from robosoa.errors import PublishTimeout
from robosoa.message import Kind, check_payload, encode_broadcast, event_channel, topic_channel
from robosoa.qos import QoS
from robosoa.stats import Counter
from robosoa.subscription import Callback, Subscription
from robosoa.transports.base import BusOptions, ProtocolAdapter


class Streams:
    """The topics and events of one bus; ``expose`` is called once it publishes or listens
    (the bus makes its counters reachable by ``robosoa stats``)."""

    def __init__(self, adapter: ProtocolAdapter, options: BusOptions,
                 expose: Callable[[], None]) -> None:
        self._adapter = adapter
        self._options = options
        self._expose = expose
        self._qos: dict[str, QoS] = {}  # channel -> QoS its publisher (this bus) declared
        self._counters: dict[tuple[Kind, str], Counter] = {}
        self._subscriptions: list[Subscription] = []
        self._lock = threading.Lock()

    def advertise(self, channel: str, qos: QoS | None) -> None:
        """Remember the publishing side of ``qos`` for ``channel``; get the transport ready."""
        with self._lock:
            if qos is None:
                self._qos.pop(channel, None)
            else:
                self._qos[channel] = qos
        self._expose()
        self._adapter.advertise(channel)

    def send(self, kind: Kind, name: str, payload: Mapping[str, Any] | None,
             context: Mapping[str, Any] | None) -> None:
        """Publish a topic message or emit an event, as its advertised QoS says."""
        frames = encode_broadcast(kind, name, check_payload(payload),
                                  dict(context) if context else None)
        counter = self._counters.get((kind, name))
        if counter is None:
            self._expose()
            role = "publisher" if kind is Kind.PUBLISH else "emitter"
            counter = self._counters[(kind, name)] = self._adapter.stats_book.counter(name, role)
        channel = topic_channel(name) if kind is Kind.PUBLISH else event_channel(name)
        qos = self._qos.get(channel)
        if qos is None:
            self._adapter.publish(channel, frames)
        else:
            expires = time.time() + qos.lifespan if qos.lifespan else 0.0
            try:
                self._adapter.publish(channel, frames, expires,
                                      qos.block if qos.reliable else None)
            except PublishTimeout:
                counter.drop("blocked")
                raise
        counter.record(None)

    def listen(self, channel: str, name: str, callback: Callback | None,
               queue_size: int | None, qos: QoS | None) -> Subscription:
        """A subscription of ``channel`` shaped by ``qos`` (default: best effort, depth
        ``queue_size`` or the bus's ``queue_size``)."""
        chosen = qos if qos is not None else QoS(depth=self._options.queue_size)
        if queue_size is not None:
            chosen = chosen.but(depth=max(1, queue_size))
        self._expose()
        counter = self._adapter.stats_book.counter(name, "subscriber")
        sub = Subscription(name, chosen, counter, callback,
                           lambda: self._adapter.room(channel))
        cancel = self._adapter.subscribe(channel, sub.sink)

        def detach() -> None:
            with self._lock:
                if sub in self._subscriptions:
                    self._subscriptions.remove(sub)
            cancel()

        sub.attach(detach)
        with self._lock:
            self._subscriptions.append(sub)
        return sub

    def close(self) -> None:
        """Close every subscription (their threads end)."""
        with self._lock:
            subs = list(self._subscriptions)
        for sub in subs:
            sub.close()
