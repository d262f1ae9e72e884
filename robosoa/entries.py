"""What a provider registers with the location service (``ServiceInfo``), read from a peer
with every field checked, and the selection of entries by name and version range."""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from robosoa.versions import version_key, version_matcher

PATTERNS = ("request-response", "oneway", "publish-subscribe", "event", "point-to-point")
MAX_TEXT = 1024  # characters of one text field of a registration (name, endpoint, ...)
MAX_OPERATIONS = 1024  # operations one registration may list
MAX_ENTRY = 16 * 1024  # characters of all text of one registration together
INTERNAL = "robosoa."  # names the runtime registers for itself; providers may not use them
PUBLISHERS = "robosoa.pub"  # a bus's PUB sockets: subscribers connect to them directly
BUS_ENTRY = "robosoa.bus"  # a publishing or subscribing bus's _ping/_stats instance


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
        """JSON-compatible form (built field by field: ``dataclasses.asdict`` deep-copies
        and took 0.18 ms per entry, most of a federated listing's time)."""
        return {"name": self.name, "version": self.version,
                "operations": list(self.operations), "pattern": self.pattern,
                "endpoint": self.endpoint, "instance": self.instance, "group": self.group,
                "host": self.host, "pid": self.pid, "ttl": self.ttl, "origin": self.origin,
                "idempotent": list(self.idempotent), "key": self.key}

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
