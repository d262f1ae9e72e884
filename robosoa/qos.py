"""Quality of service of a stream (a topic or an event) and of one subscription to it.

Declared per topic in a service descriptor (``<qos>`` of a publish-subscribe or event
operation) and given in code to ``bus.advertise`` (the publishing side: ``lifespan``,
``reliable``, ``block``) and ``bus.subscribe`` / ``bus.on`` (the subscription: all of them),
where it overrides the descriptor's. See docs/runtime.md, *Quality of service*.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from typing import Any

MAX_DEPTH = 1_000_000  # messages one subscription may be asked to hold
MAX_BLOCK = 3600.0  # seconds a reliable publish may be asked to wait
DEFAULT_BYTES = 64 * 1024 * 1024  # bytes one subscription holds by default


@dataclass(frozen=True, slots=True)
class QoS:
    """Stream quality of service; the defaults are best effort with bounded queues.

    ``depth``: history depth, the messages a subscription holds (oldest dropped past it).
    ``max_bytes``: byte budget of a subscription's queue (oldest dropped past it; one message
    larger than the budget is still held alone). ``lifespan``: seconds after publishing after
    which a message is stale and dropped (0: never). ``keep_latest``: hold only the newest
    message (a sensor stream: depth 1). ``reliable``: never drop for lack of room; the
    publisher waits up to ``block`` seconds for room and then raises PublishTimeout.
    """

    depth: int = 1000
    max_bytes: int = DEFAULT_BYTES
    lifespan: float = 0.0
    keep_latest: bool = False
    reliable: bool = False
    block: float = 1.0

    def __post_init__(self) -> None:
        problem = self.problem()
        if problem:
            raise ValueError(f"bad QoS: {problem}")

    def problem(self) -> str:
        """Why these settings cannot be used ("" when they can)."""
        if type(self.depth) is not int or not 1 <= self.depth <= MAX_DEPTH:
            return f"depth must be a whole number from 1 to {MAX_DEPTH}"
        if type(self.max_bytes) is not int or self.max_bytes < 1:
            return "max_bytes must be a whole number >= 1"
        if not _seconds(self.lifespan, math.inf):
            return "lifespan must be a finite number of seconds >= 0"
        if not _seconds(self.block, MAX_BLOCK):
            return f"block must be a number of seconds from 0 to {MAX_BLOCK:g}"
        if self.keep_latest and self.reliable:
            return "keep_latest drops every message but the newest; reliable drops none"
        return ""

    @property
    def held(self) -> int:
        """The messages a subscription holds: 1 for keep-latest, else ``depth``."""
        return 1 if self.keep_latest else self.depth

    def but(self, **changes: Any) -> QoS:
        """A copy with ``changes`` (checked again)."""
        return replace(self, **changes)


def _seconds(value: object, limit: float) -> bool:
    return (type(value) in (int, float) and math.isfinite(value)  # type: ignore[arg-type]
            and 0 <= value <= limit)  # type: ignore[operator]


BEST_EFFORT = QoS()
