"""The consumer's view of the location service: lookups, a short cache, instance choice.

The cache is also the consumer's memory of routes: while the location service cannot be
reached, requests keep going to the instances it last named (minus those that failed), for
as long as it stays away, instead of failing once the short cache runs out.
"""

from __future__ import annotations

import itertools
import logging
import threading
import time

from robosoa.errors import BusClosed, RobosoaError, ServiceNotFound
from robosoa.location import INTERNAL, ServiceInfo, select
from robosoa.transports.base import BusOptions, ProtocolAdapter

Selection = tuple[float, list[ServiceInfo]]  # when looked up, what came back
Chosen = tuple[list[ServiceInfo], list[ServiceInfo]]  # what came back, those in the range
log = logging.getLogger("robosoa.bus")
SUSPECT = 5.0  # seconds an instance that failed a call is passed over while others exist
STALE_LOOKUP = 0.25  # seconds a refresh may take when known routes can be used instead


def _entries(services: object) -> list[ServiceInfo]:
    """The well-formed entries of a lookup reply (a location service is a peer like any)."""
    if not isinstance(services, list):
        raise RobosoaError("location service sent a malformed lookup reply")
    infos = []
    for data in services:
        try:
            infos.append(ServiceInfo.from_dict(data))
        except ValueError as exc:
            log.warning("malformed service entry skipped", extra={"reason": str(exc)})
    return infos


class Directory:
    """Looks services up through the adapter; caches results for ``options.lookup_cache`` s."""

    def __init__(self, adapter: ProtocolAdapter, options: BusOptions) -> None:
        self._adapter = adapter
        self._options = options
        self._cache: dict[str, Selection] = {}
        self._chosen: dict[tuple[str, str | None], Chosen] = {}
        self._suspects: dict[str, float] = {}  # instance -> until (monotonic)
        self._away_until = 0.0  # the location service failed: use known routes until then
        self._turn = itertools.count()
        self._lock = threading.Lock()

    def services(self, name: str | None = None, version: str | None = None,
                 timeout: float | None = None) -> list[ServiceInfo]:
        """Ask the location service (never the cache); refreshes the cache for ``name``."""
        limit = self._options.location_timeout
        reply = self._adapter.location({"op": "lookup", "name": name},
                                       limit if timeout is None else min(limit, timeout))
        if "error" in reply:
            raise RobosoaError(f"location service: {str(reply['error'])[:500]}")
        infos = _entries(reply.get("services"))
        if self._away_until:
            log.info("location service answers again", extra={"service": name})
            self._away_until = 0.0
        if name is not None:
            with self._lock:
                self._cache[name] = (time.monotonic(), infos)
        else:  # a listing: the runtime's own entries (publishers' PUBs) are not services
            infos = [i for i in infos if not i.name.startswith(INTERNAL)]
        return select(infos, name, version)

    def suspect(self, info: ServiceInfo) -> None:
        """``info`` failed a call (gone, or its connection lost): pass it over for a while."""
        now = time.monotonic()
        with self._lock:
            self._suspects = {k: t for k, t in self._suspects.items() if t > now}
            self._suspects[info.instance] = now + SUSPECT
            self._stale(info.name)

    def suspected(self, instance: str) -> bool:
        """Whether ``instance`` failed a call within the last ``SUSPECT`` seconds."""
        return self._suspects.get(instance, 0.0) > time.monotonic()

    def candidates(self, name: str, version: str | None, fresh: bool,
                   timeout: float | None = None) -> list[ServiceInfo]:
        """Instances of ``name`` in the range, best first; from the cache unless ``fresh``
        or older than ``lookup_cache``; from the last known routes while the location
        service cannot be reached."""
        with self._lock:
            cached = self._cache.get(name)
        now = time.monotonic()
        if cached is None:
            return self.services(name, version, timeout)
        usable = not fresh and now - cached[0] < self._options.lookup_cache
        if usable:
            chosen = self._chosen_from(name, version, cached)
            if chosen:  # none in the range yet: ask again, as the cache may be behind
                return chosen
        if now >= self._away_until:
            try:
                return self.services(name, version, min(timeout or STALE_LOOKUP, STALE_LOOKUP))
            except BusClosed:
                raise
            except RobosoaError as exc:  # keep using what it told us last
                if not self._away_until:
                    log.warning("location service unreachable: using known routes",
                                extra={"service": name, "reason": str(exc)})
                self._away_until = time.monotonic() + max(0.1, self._options.heartbeat)
        return self._chosen_from(name, version, cached)

    def _chosen_from(self, name: str, version: str | None, cached: Selection) -> list[ServiceInfo]:
        """The entries of a cached lookup within the version range (memoised per lookup:
        per list of entries the location service sent)."""
        key = (name, version)
        chosen = self._chosen.get(key)
        if chosen is None or chosen[0] is not cached[1]:
            chosen = (cached[1], select(cached[1], name, version))
            with self._lock:
                self._chosen[key] = chosen
        return chosen[1]

    def forget(self, name: str) -> None:
        """Look ``name`` up again at its next use (after a failure); its entries stay known
        as a fallback while the location service is away."""
        with self._lock:
            self._stale(name)

    def _stale(self, name: str) -> None:
        """Mark the cached lookup of ``name`` as too old (lock held)."""
        cached = self._cache.get(name)
        if cached is not None:
            self._cache[name] = (float("-inf"), cached[1])

    def pick(self, found: list[ServiceInfo]) -> ServiceInfo:
        """Round robin among the instances of the best version (not suspected, if any is)."""
        if len(found) == 1:
            return found[0]
        if self._suspects:
            trusted = [i for i in found if not self.suspected(i.instance)]
            found = trusted or found
        top = [i for i in found if i.version == found[0].version]
        return top[next(self._turn) % len(top)]

    def wait_for(self, name: str, timeout: float = 5.0, version: str | None = None,
                 count: int = 1) -> list[ServiceInfo]:
        """Block until ``count`` instances are registered; ServiceNotFound after ``timeout``."""
        deadline = time.monotonic() + timeout
        while True:
            try:
                found = self.services(name, version)
            except RobosoaError:
                found = []
            if len(found) >= count:
                return found
            if time.monotonic() >= deadline:
                raise ServiceNotFound(name, f"not registered within {timeout:g}s")
            time.sleep(0.02)
