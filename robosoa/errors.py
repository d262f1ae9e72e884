"""The robosoa exception family: one base class so callers can catch every runtime failure."""

from __future__ import annotations


class RobosoaError(Exception):
    """Base class of every error the runtime raises on purpose."""


class ServiceNotFound(RobosoaError):
    """No live provider matches the service name (and version range) asked for."""

    def __init__(self, service: str, detail: str = "") -> None:
        self.service = service
        text = f"service {service!r} not found"
        super().__init__(f"{text}: {detail}" if detail else text)


class RequestTimeout(RobosoaError):
    """A request got no reply within its timeout; the message names the service."""

    def __init__(self, service: str, operation: str, timeout: float, detail: str = "") -> None:
        self.service = service
        self.operation = operation
        self.timeout = timeout
        text = f"request {service}.{operation} timed out after {timeout:g}s"
        super().__init__(f"{text}: {detail}" if detail else text)


class ProviderLost(RobosoaError):
    """The connection to the provider instance was lost after the request was handed over.

    The provider may or may not have run it; the bus retries on another instance only when
    the operation is idempotent, so this is raised for the others (and for point-to-point).
    """

    def __init__(self, service: str, operation: str, instance: str, why: str) -> None:
        self.service = service
        self.operation = operation
        self.instance = instance
        super().__init__(f"request {service}.{operation}: the connection to provider instance "
                         f"{instance} was lost after the request was sent (it may or may not "
                         f"have run); {why}")


class PublishTimeout(RobosoaError):
    """A reliable topic's subscriber had no room for the message within the blocking time;
    it was not sent (counted as dropped, reason ``blocked``)."""

    def __init__(self, topic: str, block: float) -> None:
        self.topic = topic
        super().__init__(f"publish on reliable {topic!r}: a subscriber had no room for "
                         f"{block:g}s; the message was not sent")


class RemoteError(RobosoaError):
    """The provider answered with an error; ``reason`` is its one-line explanation."""

    def __init__(self, service: str, reason: str) -> None:
        self.service = service
        self.reason = reason
        super().__init__(f"{service}: {reason}")


class InvalidMessage(RobosoaError):
    """A message or payload is malformed, not JSON-compatible, or fails its validator."""


class RemoteInvalidMessage(RemoteError, InvalidMessage):
    """The provider rejected the payload as invalid (validator or unknown operation)."""


class BusClosed(RobosoaError):
    """The bus (or handle) was closed while the call was in progress or before it."""
