"""The location service core (Hestand 2011, fig. 5.2): registry, expiry, lookup, federation.

Pure logic behind one ``handle(request) -> reply`` entry point, so the in-process broker and
the ZeroMQ location process answer exactly the same protocol.
"""

from __future__ import annotations

import collections
import functools
import logging
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from typing import Any

from robosoa.entries import (
    BUS_ENTRY,
    INTERNAL,
    MAX_ENTRY,
    MAX_OPERATIONS,
    MAX_TEXT,
    PATTERNS,
    PUBLISHERS,
    ServiceInfo,
    select,
)
from robosoa.errors import RobosoaError
from robosoa.federation import ask_all
from robosoa.stats import Counter

log = logging.getLogger("robosoa.location")

__all__ = ["BUS_ENTRY", "INTERNAL", "MAX_ENTRY", "MAX_OPERATIONS", "MAX_TEXT", "PATTERNS",
           "PUBLISHERS", "Limits", "LocationService", "Registry", "RegistryFull",
           "ServiceInfo", "select"]

Clock = Callable[[], float]
PEER_BACKOFF = 5.0  # seconds a federated location service that failed is not asked again



@dataclass(frozen=True, slots=True)
class Limits:
    """What one location service accepts from its (untrusted) peers; see docs/security.md."""

    max_ttl: float = 60.0  # seconds; a longer TTL asked for by a provider is cut to this
    max_entries: int = 10_000  # registrations in total; more are refused
    max_per_peer: int = 1_000  # registrations from one peer (host address); more are refused
    max_peers: int = 32  # federated location services
    federation_timeout: float = 0.5  # seconds one lookup waits for all federated peers


class RegistryFull(ValueError):
    """A registration refused by a limit (total, per peer) or by another peer's ownership."""


class Registry:
    """Entries with expiry: a provider that stops heart-beating disappears after its TTL.

    Each entry belongs to the peer (host address) that registered it: only that peer can
    refresh or remove it, and each peer may hold at most ``limits.max_per_peer`` entries.
    """

    def __init__(self, default_ttl: float = 3.0, clock: Clock = time.monotonic,
                 limits: Limits = Limits()) -> None:
        self._entries: dict[str, tuple[ServiceInfo, float, str]] = {}  # (info, expiry, peer)
        self._per_peer: collections.Counter[str] = collections.Counter()
        self._publishers = 0  # changes of the PUBLISHERS entries (a generation counter)
        self._default_ttl = default_ttl
        self._limits = limits
        self._clock = clock
        self._lock = threading.Lock()

    def register(self, info: ServiceInfo, peer: str = "") -> bool:
        """Add or refresh (heartbeat) an entry; True if it was new; RegistryFull if refused."""
        ttl = min(info.ttl, self._limits.max_ttl) if info.ttl > 0 else self._default_ttl
        if len(self._entries) >= self._limits.max_entries:
            self.expire()
        with self._lock:
            old = self._entries.get(info.instance)
            if old is None:
                self._admit(peer)
            elif old[2] != peer:
                raise RegistryFull(f"instance {info.instance[:80]!r} belongs to another peer")
            self._entries[info.instance] = (info, self._clock() + ttl, peer)
            if info.name == PUBLISHERS and (old is None or old[0].endpoint != info.endpoint):
                self._publishers += 1
        if old is None:
            log.info("registered", extra={"service": info.name, "instance": info.instance,
                                          "endpoint": info.endpoint, "peer": peer})
        return old is None

    def _admit(self, peer: str) -> None:
        """Count a new entry of ``peer`` (lock held); RegistryFull past a limit."""
        limits = self._limits
        if len(self._entries) >= limits.max_entries:
            raise RegistryFull(f"registry full: {limits.max_entries} entries (max_entries)")
        if self._per_peer[peer] >= limits.max_per_peer:
            raise RegistryFull(f"registry full for peer {peer[:80]!r}: "
                               f"{limits.max_per_peer} entries (max_per_peer)")
        self._per_peer[peer] += 1

    def publishers(self) -> int:
        """How many times ``PUBLISHERS`` entries came, went or moved (a change counter)."""
        return self._publishers

    def _drop(self, instance: str) -> ServiceInfo:
        info, _, peer = self._entries.pop(instance)
        self._publishers += info.name == PUBLISHERS
        self._per_peer[peer] -= 1
        if self._per_peer[peer] <= 0:
            del self._per_peer[peer]
        return info

    def unregister(self, instance: str, peer: str = "") -> bool:
        """Remove an entry at once (a provider closing cleanly); only its own peer may."""
        with self._lock:
            found = self._entries.get(instance)
            if found is None or found[2] != peer:
                return False
            self._drop(instance)
            return True

    def expire(self) -> list[ServiceInfo]:
        """Drop entries whose TTL ran out; returns them."""
        now = self._clock()
        with self._lock:
            dead = [i for i, (_, t, _) in self._entries.items() if t <= now]
            gone = [self._drop(i) for i in dead]
        for info in gone:
            log.info("expired", extra={"service": info.name, "instance": info.instance})
        return gone

    def entries(self) -> list[ServiceInfo]:
        """Live entries (expired ones removed first)."""
        self.expire()
        with self._lock:
            return [info for info, _, _ in self._entries.values()]


Peer = Callable[[str | None], list[ServiceInfo]]
PeerFactory = Callable[[str], Peer]


class LocationService:
    """Answers the location protocol: register, unregister, lookup, federate, hello, ping,
    stats. ``handle`` never raises: a bad request gets ``{"error": reason}``."""

    def __init__(self, registry: Registry, peer_factory: PeerFactory | None = None,
                 hello: Mapping[str, Any] | None = None, name: str = "location",
                 limits: Limits = Limits(), refuse_federate: str = "") -> None:
        self.registry = registry
        self.refuse_federate = refuse_federate  # why a client's federate is refused; "": not
        self.name = name
        self.limits = limits
        self.counter = Counter("requests", "location")  # count; errors: refused requests
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
            if len(self._peers) >= self.limits.max_peers:
                raise ValueError(f"already {self.limits.max_peers} federation peers (max_peers)")
            self._peers[address] = self._peer_factory(address)
            log.info("federated", extra={"peer": address})

    def needs_peers(self, request: Mapping[str, Any]) -> bool:
        """Whether answering ``request`` means asking federated peers (and so waiting up to
        ``federation_timeout``): a lookup, not local, of a name not known here or of all."""
        if request.get("op") != "lookup" or request.get("local") or not self._peers:
            return False
        name = request.get("name")
        return name is None or not select(self.registry.entries(), str(name), None)

    def lookup(self, name: str | None, local: bool = False) -> list[ServiceInfo]:
        """Local entries; peers are asked only for names not known locally (and for listings),
        all at once and for ``federation_timeout`` seconds in total; a peer that failed or
        did not answer in time is dropped from this answer, counted, and skipped for
        ``PEER_BACKOFF`` seconds. A peer's entries of other names are ignored."""
        found = select(self.registry.entries(), name, None)
        if local or (found and name is not None):
            return found
        seen = {info.instance for info in found}
        for address, remote in self._ask_peers(name):
            for info in remote[: self.limits.max_per_peer]:
                if info.instance not in seen and name in (None, info.name):
                    seen.add(info.instance)  # a peer's word on keys is never passed on
                    found.append(replace(info, origin=info.origin or address, key=""))
        return found

    def _ask_peers(self, name: str | None) -> list[tuple[str, list[ServiceInfo]]]:
        now = self._clock()
        calls = {address: functools.partial(peer, name)
                 for address, peer in list(self._peers.items())
                 if now >= self._backoff.get(address, 0.0)}
        good = []
        for address, outcome in ask_all(calls, self.limits.federation_timeout).items():
            if isinstance(outcome, Exception):  # a dead peer must not break local lookups
                self._backoff[address] = self._clock() + PEER_BACKOFF
                self.counter.drop("late" if isinstance(outcome, TimeoutError) else "bad-reply")
                log.warning("federated lookup failed", extra={"peer": address,
                                                              "error": str(outcome)})
            else:
                good.append((address, outcome))
        return good

    def handle(self, request: Mapping[str, Any], peer: str = "") -> dict[str, Any]:
        """One protocol request from ``peer`` in, one reply out; errors become
        ``{"error": reason}`` and are counted."""
        reply = self._handle(request, peer)
        self.counter.record(None, error="error" in reply)
        return reply

    def _handle(self, request: Mapping[str, Any], peer: str) -> dict[str, Any]:
        op = request.get("op")
        try:
            if op == "register":
                info = ServiceInfo.from_dict(request["service"])
                return {"ok": True, "new": self.registry.register(info, peer)}
            if op == "unregister":
                return {"ok": self.registry.unregister(str(request["instance"]), peer)}
            if op == "lookup":
                name = request.get("name")
                infos = self.lookup(None if name is None else str(name),
                                    bool(request.get("local", False)))
                return {"services": [i.to_dict() for i in infos]}
            if op == "federate":
                if self.refuse_federate:
                    return {"error": f"federate refused: {self.refuse_federate}"}
                self.federate(str(request["address"]))
                return {"ok": True}
            if op == "hello":
                return {"location": self.name, **self._hello}
            if op == "ping":
                return {"ok": True, "location": self.name}
            if op == "stats":
                return {"location": self.name, "entries": len(self.registry.entries()),
                        "figures": [self.counter.figures().to_dict()]}
        except (KeyError, TypeError, ValueError, RobosoaError) as exc:
            return {"error": f"bad {str(op)[:40]} request: {exc}"}
        return {"error": f"unknown location operation {str(op)[:40]!r}"}
