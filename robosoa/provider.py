"""A provided service instance: its inbox, its serving thread and its registration."""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from types import TracebackType

from robosoa.dispatch import Dispatcher
from robosoa.errors import InvalidMessage
from robosoa.location import ServiceInfo
from robosoa.message import Kind, Message
from robosoa.stats import Counter
from robosoa.transports.base import Inbox, Incoming

log = logging.getLogger("robosoa.provider")

ERROR_EVENT = "robosoa.error"  # event emitted when a one-way message cannot be handled
_NUMBER = (float, int)


class ProviderHandle:
    """Serves one service instance on its own thread: messages are handled one at a time."""

    def __init__(self, info: ServiceInfo, dispatcher: Dispatcher, inbox: Inbox,
                 counter: Counter, on_error: Callable[[dict[str, str]], None],
                 on_close: Callable[[ProviderHandle], None], slack: float = 0.0) -> None:
        self.info = info
        self._slack = slack
        self._dispatcher = dispatcher
        self._inbox = inbox
        self._counter = counter
        self._on_error = on_error
        self._on_close = on_close
        self._closed = threading.Event()
        self._thread = threading.Thread(target=self._serve, daemon=True,
                                        name=f"robosoa-provider-{info.name}")
        self._thread.start()

    @property
    def instance(self) -> str:
        """The unique id of this provider instance (the point-to-point address)."""
        return self.info.instance

    @property
    def endpoint(self) -> str:
        """Where this instance receives messages."""
        return self.info.endpoint

    @property
    def closed(self) -> bool:
        """True once ``close`` was called."""
        return self._closed.is_set()

    def _serve(self) -> None:
        try:
            while not self._closed.is_set():
                try:
                    incoming = self._inbox.receive(0.5)
                    if incoming is not None:
                        self._handle(incoming)
                except Exception:  # last line of defence: a provider never dies of a message
                    self._counter.fail()
                    log.exception("provider loop error", extra={"service": self.info.name})
        finally:
            self._inbox.close()

    def _handle(self, incoming: Incoming) -> None:
        msg = incoming.message
        if msg is None:
            self._counter.record(None, error=True)
            self._refuse(incoming, incoming.problem)
            return
        deadline: float = msg.context.get("deadline", 0.0)
        if type(deadline) in _NUMBER and deadline and deadline + self._slack < time.time():
            self._counter.drop("deadline")  # the consumer has given up: no reply, no work
            return
        start = time.perf_counter()
        outcome = self._dispatcher.dispatch(msg)
        self._counter.record(time.perf_counter() - start, error=outcome.error is not None)
        if incoming.reply is None:
            if outcome.error is not None:
                self._report(msg.operation, outcome.error)
            return
        try:
            incoming.reply(msg.reply(outcome.payload, outcome.error, outcome.error_type))
        except InvalidMessage as exc:
            incoming.reply(msg.reply(error=f"reply of {self.info.name}.{msg.operation}: {exc}",
                                     error_type="RemoteError"))
        except Exception as exc:  # the consumer went away; keep serving
            log.warning("reply failed", extra={"service": self.info.name, "error": str(exc)})

    def _refuse(self, incoming: Incoming, problem: str) -> None:
        log.warning("malformed message", extra={"service": self.info.name, "reason": problem})
        if incoming.reply is None:
            self._report("", problem)
            return
        error = Message(Kind.REPLY, service=self.info.name, error=problem,
                        context={"error_type": "InvalidMessage"})
        try:
            incoming.reply(error)
        except Exception as exc:
            log.warning("error reply failed", extra={"service": self.info.name,
                                                     "error": str(exc)})

    def _report(self, operation: str, reason: str) -> None:
        try:
            self._on_error({"service": self.info.name, "operation": operation,
                            "instance": self.info.instance, "reason": reason})
        except Exception as exc:
            log.warning("error event failed", extra={"error": str(exc)})

    def close(self) -> None:
        """Stop serving, unregister from the location service and release the endpoint."""
        if self._closed.is_set():
            return
        self._closed.set()
        self._inbox.wake()
        if threading.current_thread() is not self._thread:
            self._thread.join(timeout=5.0)
        self._on_close(self)

    def __enter__(self) -> ProviderHandle:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()

    def __repr__(self) -> str:
        return f"<ProviderHandle {self.info.name} {self.info.version} at {self.info.endpoint}>"
