"""Calling one provider instance: the request/response step shared by the bus and by
point-to-point channels."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from typing import Any

from robosoa.errors import (
    ProviderLost,
    RemoteError,
    RemoteInvalidMessage,
    RequestTimeout,
    ServiceNotFound,
)
from robosoa.location import ServiceInfo
from robosoa.message import Kind, Message, Payload, check_payload
from robosoa.stats import Counter
from robosoa.transports.base import Lost, ProtocolAdapter, Unreachable

CallInstance = Callable[[ServiceInfo, str, Payload, float, float | None], Payload]


def raise_remote(service: str, reply: Message) -> None:
    """Turn an error reply into the matching exception."""
    reason = reply.error or "unknown error"
    if reply.context.get("error_type") == "InvalidMessage":
        raise RemoteInvalidMessage(service, reason)
    raise RemoteError(service, reason)


def call_instance(adapter: ProtocolAdapter, counter: Counter, info: ServiceInfo, operation: str,
                  body: Payload, remaining: float, timeout: float | None = None) -> Payload:
    """One request to one instance; the reply payload, or RequestTimeout / RemoteError.

    The consumer's deadline travels in the context (``deadline``: seconds since the epoch)
    so the provider can drop work nobody waits for. Unreachable and Lost propagate so the
    caller can try another instance.
    """
    context = {"operation": operation, "deadline": time.time() + remaining}
    msg = Message(Kind.REQUEST, info.name, operation, "", body, context)
    start = time.perf_counter()
    try:
        reply = adapter.call(info.endpoint, msg, remaining)
    except RequestTimeout:
        counter.record(None, error=True)
        raise RequestTimeout(info.name, operation, timeout or remaining) from None
    counter.record(time.perf_counter() - start, error=reply.error is not None)
    if reply.error is not None:
        raise_remote(info.name, reply)
    return reply.payload  # freshly decoded: nobody else holds it


class Channel:
    """Point-to-point: a direct line to ONE provider instance, no load balancing, no re-lookup.

    If that instance goes away, calls fail with ServiceNotFound naming the instance.
    """

    def __init__(self, call: CallInstance, adapter: ProtocolAdapter, info: ServiceInfo) -> None:
        self._call = call
        self._adapter = adapter
        self.info = info

    def _gone(self, exc: Exception) -> ServiceNotFound:
        return ServiceNotFound(self.info.name, f"instance {self.info.instance}: {exc}")

    def request(self, operation: str, payload: Mapping[str, Any] | None = None,
                timeout: float = 5.0) -> Payload:
        """Blocking request to this instance; ProviderLost if its connection goes away
        before the reply (a channel never fails over)."""
        try:
            return self._call(self.info, operation, check_payload(payload), timeout, timeout)
        except Unreachable as exc:
            raise self._gone(exc) from None
        except Lost:
            raise ProviderLost(self.info.name, operation, self.info.instance,
                               "point-to-point channels do not fail over") from None

    def send(self, operation: str, payload: Mapping[str, Any] | None = None) -> None:
        """One-way message to this instance."""
        msg = Message(Kind.ONEWAY, self.info.name, operation, "", check_payload(payload),
                      {"operation": operation})
        try:
            self._adapter.post(self.info.endpoint, msg)
        except Unreachable as exc:
            raise self._gone(exc) from None

    def close(self) -> None:
        """Nothing to release; present for symmetry with the other handles."""
