"""Counters and latency figures per service (count, errors, p50/p99) and per subscription.

Every message dropped is counted with the reason it was dropped (see ``REASONS`` and
docs/runtime.md, *Fault behaviour*), so ``robosoa stats`` can say why.
"""

from __future__ import annotations

import math
import threading
from collections import deque
from dataclasses import dataclass
from typing import Any

WINDOW = 2048  # latency samples kept per service: a bounded window, not a full history
REASONS = {
    "queue": "a bounded queue was full (asynchronous requests, inproc inboxes)",
    "unreachable": "no instance could take the message (gone, or its bounded inbox full)",
    "deadline": "a request reached its provider after the consumer's deadline",
    "depth": "a subscription held its history depth: the oldest message made room",
    "bytes": "a subscription held its byte budget: the oldest messages made room",
    "lifespan": "a message was older than its lifespan",
    "lost": "sequence numbers skipped: dropped in a ZeroMQ queue or a lost connection",
    "blocked": "a reliable publish found no room within its blocking time",
    "late": "a federated location service did not answer within its time budget (a reply "
            "over the size cap is dropped unread by ZeroMQ and counts here)",
    "bad-reply": "a federated location service's reply was malformed",
    "busy": "every federation worker was busy: a lookup was answered from local entries only",
    "truncated": "entries left out of a lookup reply to keep it within the frame limit",
    "budget": "a peer connection was more than its byte budget ahead of the provider (a "
              "message too large in all its frames): it was shut down, with what it queued",
}


def percentile(samples: list[float], fraction: float) -> float:
    """Nearest-rank percentile of ``samples`` (0.0 when empty)."""
    if not samples:
        return 0.0
    ordered = sorted(samples)
    rank = min(len(ordered) - 1, max(0, math.ceil(fraction * len(ordered)) - 1))
    return ordered[rank]


@dataclass(frozen=True, slots=True)
class ServiceFigures:
    """A snapshot of one service's counters; latencies in milliseconds."""

    key: str
    role: str  # "provider", "consumer", "sender", "publisher", "subscriber", "wire", ...
    count: int
    errors: int
    dropped: int  # the sum of ``drops``
    p50_ms: float
    p99_ms: float
    drops: tuple[tuple[str, int], ...] = ()  # (reason, count), reasons of ``REASONS``

    def to_dict(self) -> dict[str, Any]:
        """JSON-compatible form."""
        return {"key": self.key, "role": self.role, "count": self.count, "errors": self.errors,
                "dropped": self.dropped, "drops": dict(self.drops),
                "p50_ms": round(self.p50_ms, 3), "p99_ms": round(self.p99_ms, 3)}


class Counter:
    """Thread-safe counters and a bounded latency window for one key."""

    def __init__(self, key: str, role: str) -> None:
        self.key = key
        self.role = role
        self.count = 0
        self.errors = 0
        self.dropped = 0
        self._drops: dict[str, int] = {}
        self._latency: deque[float] = deque(maxlen=WINDOW)
        self._lock = threading.Lock()

    def record(self, seconds: float | None, error: bool = False) -> None:
        """Count one exchange and its latency (None when there is no latency to speak of)."""
        with self._lock:
            self.count += 1
            self.errors += int(error)
            if seconds is not None:
                self._latency.append(seconds)

    def fail(self) -> None:
        """Count an error that is not an exchange of its own (e.g. a failing callback)."""
        with self._lock:
            self.errors += 1

    def drop(self, reason: str = "queue", n: int = 1) -> None:
        """Count ``n`` messages dropped or refused, for ``reason`` (one of ``REASONS``)."""
        with self._lock:
            self.dropped += n
            self._drops[reason] = self._drops.get(reason, 0) + n

    def figures(self) -> ServiceFigures:
        """A consistent snapshot."""
        with self._lock:
            samples = list(self._latency)
            count, errors, dropped = self.count, self.errors, self.dropped
            drops = tuple(sorted(self._drops.items()))
        return ServiceFigures(self.key, self.role, count, errors, dropped,
                              percentile(samples, 0.50) * 1000, percentile(samples, 0.99) * 1000,
                              drops)


class StatsBook:
    """All counters of one bus, created on first use."""

    def __init__(self) -> None:
        self._counters: dict[tuple[str, str], Counter] = {}
        self._lock = threading.Lock()

    def counter(self, key: str, role: str) -> Counter:
        """The counter for ``key`` in ``role``."""
        with self._lock:
            found = self._counters.get((key, role))
            if found is None:
                found = self._counters[(key, role)] = Counter(key, role)
            return found

    def snapshot(self) -> list[ServiceFigures]:
        """Figures for every counter, sorted by role then key."""
        with self._lock:
            counters = list(self._counters.values())
        return sorted((c.figures() for c in counters), key=lambda f: (f.role, f.key))
