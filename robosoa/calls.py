"""Request/response and one-way messages of one bus (part of the MessagingProxy): instance
choice, fail-over, deadlines, the bounded pool of asynchronous requests."""

from __future__ import annotations

import logging
import threading
import time
from concurrent.futures import Future, ThreadPoolExecutor

from robosoa.channel import call_instance
from robosoa.directory import Directory
from robosoa.errors import BusClosed, ProviderLost, RequestTimeout, RobosoaError, ServiceNotFound
from robosoa.location import ServiceInfo
from robosoa.message import Kind, Message, Payload
from robosoa.stats import Counter
from robosoa.transports.base import BusOptions, Lost, ProtocolAdapter, Unreachable

log = logging.getLogger("robosoa.bus")

ASYNC_WORKERS = 8  # asynchronous requests run on this many threads per bus


class Calls:
    """Requests and one-way messages; payloads come checked (``check_payload``)."""

    def __init__(self, adapter: ProtocolAdapter, options: BusOptions,
                 directory: Directory) -> None:
        self._adapter = adapter
        self._options = options
        self._directory = directory
        self._stats = adapter.stats_book
        self._consumers: dict[str, Counter] = {}
        self._lock = threading.Lock()
        self._executor: ThreadPoolExecutor | None = None
        self._pending = 0

    def request(self, service: str, operation: str, body: Payload, timeout: float,
                version: str | None, idempotent: bool | None) -> Payload:
        """One request, tried on another instance after a failure that allows it."""
        deadline = time.monotonic() + timeout
        tried: set[str] = set()
        failed: set[str] = set()
        fresh = False
        while True:
            found = self.lookup(service, version, fresh, deadline)
            if not found and not tried:
                detail = f"no provider in version range {version!r}" if version else ""
                raise ServiceNotFound(service, detail)
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                self._stats.counter(service, "consumer").record(None, error=True)
                raise RequestTimeout(service, operation, timeout, _tried(failed))
            left = [i for i in found if i.instance not in tried] if tried else found
            if not left:  # every instance failed: wait a little and look again
                time.sleep(min(0.05, remaining))
                tried.clear()
                fresh = True
                continue
            info = self._directory.pick(left)
            try:
                return self.call_instance(info, operation, body, remaining, timeout)
            except (Unreachable, Lost) as exc:
                self._failed(info, operation, exc, idempotent)
                tried.add(info.instance)
                failed.add(info.instance)
                fresh = True

    def _failed(self, info: ServiceInfo, operation: str, exc: RobosoaError,
                idempotent: bool | None) -> None:
        """An instance failed a call: pass it over for a while; a request it may have run
        is tried again elsewhere only when idempotent (else ProviderLost)."""
        self._directory.suspect(info)
        counter = self._stats.counter(info.name, "consumer")
        if isinstance(exc, Unreachable):  # never handed over: safe to try another instance
            counter.drop("unreachable")
            return
        retry = operation in info.idempotent if idempotent is None else idempotent
        if not retry:
            counter.record(None, error=True)
            why = f"not retried: operation {operation!r} is not idempotent"
            raise ProviderLost(info.name, operation, info.instance, why) from None
        counter.fail()
        log.info("request retried on another instance", extra={
            "service": info.name, "instance": info.instance, "reason": str(exc)})

    def lookup(self, service: str, version: str | None, fresh: bool,
               deadline: float) -> list[ServiceInfo]:
        """Candidates within the caller's deadline; a location failure names the service."""
        try:
            return self._directory.candidates(service, version, fresh,
                                              max(0.01, deadline - time.monotonic()))
        except BusClosed:
            raise
        except RobosoaError as exc:
            raise ServiceNotFound(service, str(exc)) from None

    def call_instance(self, info: ServiceInfo, operation: str, body: Payload,
                      remaining: float, timeout: float | None = None) -> Payload:
        """One request to one instance (also what point-to-point channels use)."""
        counter = self._consumers.get(info.name)
        if counter is None:
            counter = self._consumers[info.name] = self._stats.counter(info.name, "consumer")
        try:
            return call_instance(self._adapter, counter, info, operation, body, remaining,
                                 timeout)
        except RequestTimeout:
            self._directory.forget(info.name)
            raise

    def request_async(self, service: str, operation: str, body: Payload, timeout: float,
                      version: str | None, idempotent: bool | None) -> Future[Payload]:
        """A request on the bounded pool; refused at once (a failed future) when full."""
        with self._lock:
            if self._executor is None:
                self._executor = ThreadPoolExecutor(ASYNC_WORKERS,
                                                    thread_name_prefix="robosoa-async")
            executor = self._executor
            full = self._pending >= self._options.queue_size
            if not full:
                self._pending += 1
        if full:  # bounded: refuse rather than queue without limit
            self._stats.counter(service, "consumer").drop("queue")
            refused: Future[Payload] = Future()
            refused.set_exception(RobosoaError(
                f"request {service}.{operation} refused: {self._options.queue_size} "
                "asynchronous requests already pending"))
            return refused
        future = executor.submit(self.request, service, operation, body, timeout, version,
                                 idempotent)
        future.add_done_callback(self._async_done)
        return future

    def _async_done(self, _future: Future[Payload]) -> None:
        with self._lock:
            self._pending -= 1

    def send(self, service: str, operation: str, body: Payload, to: str, group: str | None,
             version: str | None) -> int:
        """One-way to one instance (the first that takes it), a group, or all."""
        msg = Message(Kind.ONEWAY, service=service, operation=operation, payload=body,
                      context={"operation": operation})
        found = self.lookup(service, version, False, time.monotonic() + 5.0)
        if to == "group":
            found = [i for i in found if i.group == group]
        if not found:
            raise ServiceNotFound(service, f"no instance in group {group!r}" if group else "")
        if to == "one":
            first = self._directory.pick(found)
            targets = [first, *(i for i in found if i is not first)]
        else:
            targets = found
        counter = self._stats.counter(service, "sender")
        delivered = 0
        for info in targets:
            try:
                self._adapter.post(info.endpoint, msg)
                delivered += 1
                counter.record(None)
            except Unreachable:
                counter.drop("unreachable")
                self._directory.suspect(info)
                continue
            if to == "one":
                break
        return delivered

    def close(self) -> None:
        """Stop taking asynchronous requests (those running end with the transport)."""
        with self._lock:
            executor, self._executor = self._executor, None
        if executor is not None:
            executor.shutdown(wait=False, cancel_futures=True)


def _tried(instances: set[str]) -> str:
    """The detail of a timeout after failed instances."""
    return f"no instance answered (failed: {', '.join(sorted(instances))})" if instances else ""
