"""Protocol bridge (Hestand 2011, p. 56): joins two buses, e.g. inproc and zmq, so services
and topics of one are usable from the other (ESB federation by protocol bridging)."""

from __future__ import annotations

import uuid
from collections.abc import Iterable
from types import TracebackType
from typing import Any

from robosoa.bus import Bus
from robosoa.errors import InvalidMessage, RemoteInvalidMessage
from robosoa.message import Kind, Message
from robosoa.provider import ProviderHandle
from robosoa.subscription import Subscription

HOP = "robosoa.bridge"  # context key marking messages a bridge forwarded (prevents echo loops)


class Bridge:
    """Re-provides ``services`` of ``source`` on ``target``; forwards topics and events.

    Services are forwarded one way (calls on ``target`` reach the providers on ``source``);
    topics and events go source -> target, and also back when ``both_ways`` is true.
    """

    def __init__(self, source: Bus, target: Bus, services: Iterable[str] = (),
                 topics: Iterable[str] = (), events: Iterable[str] = (),
                 both_ways: bool = False, timeout: float = 5.0) -> None:
        self.source, self.target, self.timeout = source, target, timeout
        self.id = uuid.uuid4().hex[:8]
        self.handles: list[ProviderHandle] = []
        self.subscriptions: list[Subscription] = []
        try:
            for name in services:
                self._service(name)
            for topic in topics:
                self._topic(source, target, topic, event=False)
                if both_ways:
                    self._topic(target, source, topic, event=False)
            for event in events:
                self._topic(source, target, event, event=True)
                if both_ways:
                    self._topic(target, source, event, event=True)
        except BaseException:
            self.close()
            raise

    def _service(self, name: str) -> None:
        best = self.source.wait_for(name, timeout=self.timeout)[0]

        def forward(msg: Message) -> dict[str, Any] | None:
            if msg.kind is Kind.ONEWAY:
                self.source.send(name, msg.operation, msg.payload)
                return None
            try:
                return self.source.request(name, msg.operation, msg.payload,
                                           timeout=self.timeout)
            except RemoteInvalidMessage as exc:
                raise InvalidMessage(exc.reason) from None

        self.handles.append(self.target.provide(name, forward, version=best.version,
                                                operations=best.operations,
                                                pattern=best.pattern, group=best.group,
                                                idempotent=best.idempotent))

    def _topic(self, src: Bus, dst: Bus, name: str, event: bool) -> None:
        mark = f"{self.id}:{id(dst)}"

        def forward(msg: Message) -> None:
            if msg.context.get(HOP) is not None:
                return  # already bridged once: never bounce back
            if event:
                dst.emit(name, msg.payload, context={HOP: mark})
            else:
                dst.publish(name, msg.payload, context={HOP: mark})

        listen = src.on if event else src.subscribe
        self.subscriptions.append(listen(name, forward))

    def close(self) -> None:
        """Stop forwarding."""
        for handle in self.handles:
            handle.close()
        for sub in self.subscriptions:
            sub.close()

    def __enter__(self) -> Bridge:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
