"""The location service core (Hestand 2011, fig. 5.2): registry, expiry, lookup, federation.

Pure logic behind one ``handle(request) -> reply`` entry point, so the in-process broker and
the ZeroMQ location process answer exactly the same protocol.
"""

from __future__ import annotations

import collections
import functools
import logging
import math
import re
import threading
import time
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass, replace
from typing import Any

from robosoa.errors import RobosoaError
from robosoa.federation import ask_all
from robosoa.stats import Counter
from robosoa.versions import version_key, version_matcher

log = logging.getLogger("robosoa.location")

Clock = Callable[[], float]
PEER_BACKOFF = 5.0  # seconds a federated location service that failed is not asked again
PATTERNS = ("request-response", "oneway", "publish-subscribe", "event", "point-to-point")
MAX_TEXT = 1024  # characters of one text field of a registration (name, endpoint, ...)
MAX_OPERATIONS = 1024  # operations one registration may list
MAX_ENTRY = 16 * 1024  # characters of all text of one registration together
INTERNAL = "robosoa."  # names the runtime registers for itself; providers may not use them
PUBLISHERS = "robosoa.pub"  # a bus's PUB sockets: subscribers connect to them directly
BUS_ENTRY = "robosoa.bus"  # a publishing or subscribing bus's _ping/_stats instance


@dataclass(frozen=True, slots=True)
class Limits:
    """What one location service accepts from its (untrusted) peers; see docs/security.md."""

    max_ttl: float = 60.0  # seconds; a longer TTL asked for by a provider is cut to this
    max_entries: int = 10_000  # registrations in total; more are refused
    max_per_peer: int = 1_000  # registrations from one peer (host address); more are refused
    max_peers: int = 32  # federated location services
    federation_timeout: float = 0.5  # seconds one lookup waits for all federated peers


def _text(value: Any, key: str) -> str:
    text = str(value)
    if len(text) > MAX_TEXT:
        raise ValueError(f"{key} is longer than {MAX_TEXT} characters")
    return text


def _names(value: Any, key: str) -> tuple[str, ...]:
    if not isinstance(value, list | tuple) or len(value) > MAX_OPERATIONS:
        raise ValueError(f"{key} is not a list of at most {MAX_OPERATIONS}")
    return tuple(_text(name, key) for name in value)


_Z85 = re.compile(r"[0-9a-zA-Z.\-:+=^!/*?&<>()\[\]{}@%$#]{40}")


def _key(value: Any) -> str:
    if value == "":
        return ""
    if not isinstance(value, str) or not _Z85.fullmatch(value):
        raise ValueError("key is not a 40-character Z85 public key")
    return value


def _ttl(value: Any) -> float:
    ttl = float(value)
    if not math.isfinite(ttl) or ttl < 0:
        raise ValueError(f"ttl {value!r} is not a finite number >= 0")
    return ttl


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
    idempotent: tuple[str, ...] = ()  # operations a consumer may retry on another instance
    key: str = ""  # zmq with CURVE: the public key (z85) of the endpoint's server socket

    def to_dict(self) -> dict[str, Any]:
        """JSON-compatible form."""
        data = asdict(self)
        data["operations"] = list(self.operations)
        data["idempotent"] = list(self.idempotent)
        return data

    @staticmethod
    def from_dict(data: Mapping[str, Any]) -> ServiceInfo:
        """Parse and check the dict form; raises ValueError naming the bad key."""
        if not isinstance(data, Mapping):
            raise ValueError("bad service entry: not an object")
        try:
            operations = _names(data.get("operations", ()), "operations")
            idempotent = _names(data.get("idempotent", ()), "idempotent")
            info = ServiceInfo(
                name=_text(data["name"], "name"), version=_text(data["version"], "version"),
                operations=operations,
                pattern=str(data.get("pattern", "request-response")),
                endpoint=_text(data["endpoint"], "endpoint"),
                instance=_text(data["instance"], "instance"),
                group=None if data.get("group") is None else _text(data["group"], "group"),
                host=_text(data.get("host", ""), "host"), pid=int(data.get("pid", 0)),
                ttl=_ttl(data.get("ttl", 0.0)), origin=_text(data.get("origin", ""), "origin"),
                idempotent=idempotent, key=_key(data.get("key", "")),
            )
        except (KeyError, TypeError, ValueError, OverflowError) as exc:
            raise ValueError(f"bad service entry: {exc!r}") from None
        if not info.name or not info.instance:
            raise ValueError("bad service entry: empty name or instance")
        if info.pattern not in PATTERNS:
            raise ValueError(f"bad service entry: unknown pattern {info.pattern[:40]!r}")
        texts = (info.name, info.version, info.endpoint, info.instance, info.group or "",
                 info.host, info.origin, *info.operations, *info.idempotent)
        if sum(map(len, texts)) > MAX_ENTRY:
            raise ValueError(f"bad service entry: more than {MAX_ENTRY} characters of text")
        return info


def select(infos: list[ServiceInfo], name: str | None, version: str | None) -> list[ServiceInfo]:
    """Entries for ``name`` within the version range, highest version first."""
    accept = version_matcher(version)
    chosen = [i for i in infos if (name is None or i.name == name) and accept(i.version)]
    return sorted(chosen, key=lambda i: (i.name, tuple(-p for p in version_key(i.version))))


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
                 limits: Limits = Limits()) -> None:
        self.registry = registry
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

    def lookup(self, name: str | None, local: bool = False) -> list[ServiceInfo]:
        """Local entries; peers are asked only for names not known locally (and for listings),
        all at once and for ``federation_timeout`` seconds in total; a peer that failed or
        did not answer in time is skipped for ``PEER_BACKOFF`` seconds."""
        found = select(self.registry.entries(), name, None)
        if local or (found and name is not None):
            return found
        seen = {info.instance for info in found}
        for address, remote in self._ask_peers(name):
            for info in remote[: self.limits.max_per_peer]:
                if info.instance not in seen:
                    seen.add(info.instance)
                    found.append(replace(info, origin=info.origin or address))
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
