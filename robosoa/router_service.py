"""Puts a content-based Router on a bus: a service for calls, a subscriber for topics."""

from __future__ import annotations

import logging
from types import TracebackType
from typing import Any

from robosoa.bus import Bus
from robosoa.errors import InvalidMessage, RobosoaError
from robosoa.message import Message
from robosoa.provider import ERROR_EVENT, ProviderHandle
from robosoa.router import Outgoing, Router, RuleError
from robosoa.subscription import Subscription

log = logging.getLogger("robosoa.router")


class RouterHandle:
    """A running router; ``close`` stops its service and subscriptions."""

    def __init__(self, router: Router, bus: Bus, service: str, version: str) -> None:
        self.router = router
        self.bus = bus
        self.service = service
        self.handle: ProviderHandle | None = None
        self.subscriptions: list[Subscription] = []
        operations = {r.operation for r in router.rules if not r.topic}
        if operations:
            ops = () if "*" in operations else tuple(sorted(operations))
            self.handle = bus.provide(service, self._on_call, version=version, operations=ops)
        for topic in router.topics:
            self.subscriptions.append(bus.subscribe(topic, self._on_topic))

    def _deliver(self, out: Outgoing) -> dict[str, Any]:
        done: dict[str, Any] = {"rule": out.rule, "kind": out.kind}
        if out.kind == "request":
            done["to"] = f"{out.service}.{out.operation}"
            done["reply"] = self.bus.request(out.service, out.operation, out.payload)
        elif out.kind == "send":
            done["to"] = f"{out.service}.{out.operation}"
            done["delivered"] = self.bus.send(out.service, out.operation, out.payload)
        elif out.kind == "publish":
            done["to"] = out.topic
            self.bus.publish(out.topic, out.payload)
        else:
            done["to"] = out.topic
            self.bus.emit(out.topic, out.payload)
        return done

    def _on_call(self, msg: Message) -> dict[str, Any]:
        try:
            outs = self.router.route(msg.operation, "", msg.payload, msg.service)
        except RuleError as exc:
            raise InvalidMessage(str(exc)) from None
        if not outs:
            raise InvalidMessage(f"no rule of router {self.service!r} matches "
                                 f"operation {msg.operation!r} with this payload")
        return {"routed": [self._deliver(out) for out in outs]}

    def _on_topic(self, msg: Message) -> None:
        try:
            for out in self.router.route("", msg.topic, msg.payload):
                self._deliver(out)
        except (RobosoaError, RuleError) as exc:
            log.warning("routing failed", extra={"topic": msg.topic, "error": str(exc)})
            self.bus.emit(ERROR_EVENT, {"service": self.service, "operation": "",
                                        "instance": "", "reason": str(exc)})

    def close(self) -> None:
        """Stop serving and listening."""
        if self.handle is not None:
            self.handle.close()
        for sub in self.subscriptions:
            sub.close()

    def __enter__(self) -> RouterHandle:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()


def attach(router: Router, bus: Bus, service: str, version: str) -> RouterHandle:
    """Serve ``router`` on ``bus`` under the service name ``service``."""
    return RouterHandle(router, bus, service, version)
