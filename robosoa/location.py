"""The location service core (Hestand 2011, fig. 5.2): registry, expiry, lookup, federation.

Pure logic behind one ``handle(request) -> reply`` entry point, so the in-process broker and
the ZeroMQ location process answer exactly the same protocol.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, replace
from typing import Any

from robosoa.versions import version_key, version_matcher

log = logging.getLogger("robosoa.location")

Clock = Callable[[], float]
PEER_BACKOFF = 5.0  # seconds a federated location service that failed is not asked again


@dataclass(frozen=True, slots=True)
class ServiceInfo:
    """What a provider instance registers: name, version, operations, pattern, endpoint."""

    name: str
    version: str
    operations: tuple[str, ...]
    pattern: str
    endpoint: str
    instance: str
    group: str | None = None
    host: str = ""
    pid: int = 0
    ttl: float = 0.0
    origin: str = ""  # "" when local, else the federated location service it came from

    def to_dict(self) -> dict[str, Any]:
        """JSON-compatible form."""
        data = asdict(self)
        data["operations"] = list(self.operations)
        return data

    @staticmethod
    def from_dict(data: Mapping[str, Any]) -> ServiceInfo:
        """Parse and check the dict form; raises ValueError naming the bad key."""
        try:
            info = ServiceInfo(
                name=str(data["name"]), version=str(data["version"]),
                operations=tuple(str(op) for op in data.get("operations", ())),
                pattern=str(data.get("pattern", "request-response")),
                endpoint=str(data["endpoint"]), instance=str(data["instance"]),
                group=None if data.get("group") is None else str(data["group"]),
                host=str(data.get("host", "")), pid=int(data.get("pid", 0)),
                ttl=float(data.get("ttl", 0.0)), origin=str(data.get("origin", "")),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"bad service entry: {exc!r}") from None
        if not info.name or not info.instance:
            raise ValueError("bad service entry: empty name or instance")
        return info


def select(infos: list[ServiceInfo], name: str | None, version: str | None) -> list[ServiceInfo]:
    """Entries for ``name`` within the version range, highest version first."""
    accept = version_matcher(version)
    chosen = [i for i in infos if (name is None or i.name == name) and accept(i.version)]
    return sorted(chosen, key=lambda i: (i.name, tuple(-p for p in version_key(i.version))))


class Registry:
    """Entries with expiry: a provider that stops heart-beating disappears after its TTL."""

    def __init__(self, default_ttl: float = 3.0, clock: Clock = time.monotonic) -> None:
        self._entries: dict[str, tuple[ServiceInfo, float]] = {}
        self._default_ttl = default_ttl
        self._clock = clock
        self._lock = threading.Lock()

    def register(self, info: ServiceInfo) -> bool:
        """Add or refresh (heartbeat) an entry; True if it was new."""
        ttl = info.ttl if info.ttl > 0 else self._default_ttl
        with self._lock:
            new = info.instance not in self._entries
            self._entries[info.instance] = (info, self._clock() + ttl)
        if new:
            log.info("registered", extra={"service": info.name, "instance": info.instance,
                                          "endpoint": info.endpoint})
        return new

    def unregister(self, instance: str) -> bool:
        """Remove an entry at once (a provider closing cleanly)."""
        with self._lock:
            return self._entries.pop(instance, None) is not None

    def expire(self) -> list[ServiceInfo]:
        """Drop entries whose TTL ran out; returns them."""
        now = self._clock()
        with self._lock:
            dead = [i for i, (_, t) in self._entries.items() if t <= now]
            gone = [self._entries.pop(i)[0] for i in dead]
        for info in gone:
            log.info("expired", extra={"service": info.name, "instance": info.instance})
        return gone

    def entries(self) -> list[ServiceInfo]:
        """Live entries (expired ones removed first)."""
        self.expire()
        with self._lock:
            return [info for info, _ in self._entries.values()]


Peer = Callable[[str | None], list[ServiceInfo]]
PeerFactory = Callable[[str], Peer]


class LocationService:
    """Answers the location protocol: register, unregister, lookup, federate, hello, ping."""

    def __init__(self, registry: Registry, peer_factory: PeerFactory | None = None,
                 hello: Mapping[str, Any] | None = None, name: str = "location") -> None:
        self.registry = registry
        self.name = name
        self._peer_factory = peer_factory
        self._peers: dict[str, Peer] = {}
        self._backoff: dict[str, float] = {}
        self._clock = time.monotonic
        self._hello = dict(hello or {})

    def federate(self, address: str) -> None:
        """Also answer lookups with entries learned from the location service at ``address``."""
        if self._peer_factory is None:
            raise ValueError("this location service cannot federate")
        if address not in self._peers:
            self._peers[address] = self._peer_factory(address)
            log.info("federated", extra={"peer": address})

    def lookup(self, name: str | None, local: bool = False) -> list[ServiceInfo]:
        """Local entries; peers are asked only for names not known locally (and for listings),
        and a peer that failed is skipped for ``PEER_BACKOFF`` seconds."""
        found = select(self.registry.entries(), name, None)
        if local or (found and name is not None):
            return found
        seen = {info.instance for info in found}
        for address, peer in list(self._peers.items()):
            if self._clock() < self._backoff.get(address, 0.0):
                continue
            try:
                remote = peer(name)
            except Exception as exc:  # a dead peer must not break local lookups
                self._backoff[address] = self._clock() + PEER_BACKOFF
                log.warning("federated lookup failed", extra={"peer": address, "error": str(exc)})
                continue
            for info in remote:
                if info.instance not in seen:
                    seen.add(info.instance)
                    found.append(replace(info, origin=info.origin or address))
        return found

    def handle(self, request: Mapping[str, Any]) -> dict[str, Any]:
        """One protocol request in, one reply out; errors become ``{"error": reason}``."""
        op = request.get("op")
        try:
            if op == "register":
                new = self.registry.register(ServiceInfo.from_dict(request["service"]))
                return {"ok": True, "new": new}
            if op == "unregister":
                return {"ok": self.registry.unregister(str(request["instance"]))}
            if op == "lookup":
                name = request.get("name")
                infos = self.lookup(None if name is None else str(name),
                                    bool(request.get("local", False)))
                return {"services": [i.to_dict() for i in infos]}
            if op == "federate":
                self.federate(str(request["address"]))
                return {"ok": True}
            if op == "hello":
                return {"location": self.name, **self._hello}
            if op == "ping":
                return {"ok": True, "location": self.name}
        except (KeyError, TypeError, ValueError) as exc:
            return {"error": f"bad {op} request: {exc}"}
        return {"error": f"unknown location operation {op!r}"}
