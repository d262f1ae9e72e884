"""The protocol adapter seam (the thesis's SOA_Base, p. 66) that every transport implements.

The bus (MessagingProxy) implements the exchange patterns once, on top of these few
primitives; a transport only moves messages, answers the location protocol and fans out
broker channels. Adding a transport means one new module implementing this class.
"""

from __future__ import annotations

import time
from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, NamedTuple

from robosoa.errors import PublishTimeout, RobosoaError
from robosoa.location import ServiceInfo
from robosoa.message import Frames, Message, decode_frames
from robosoa.stats import StatsBook
from robosoa.wire import MAX_DEPTH, MAX_MESSAGE

# (message, its size in bytes on the wire, the expiry its publisher gave it or 0, whether the
# transport can hold it back) -> whether it was taken (False only when holding back is
# possible and a reliable subscription is full: offer it again later). Never blocks.
Sink = Callable[[Message, int, float, bool], bool]
ReplyFn = Callable[[Message], None]


def offer_until(sink: Sink, offer: tuple[Message, int, float], deadline: float,
                channel: str) -> None:
    """Offer a message until ``sink`` takes it (a reliable sink may refuse while full),
    backing off up to 10 ms; PublishTimeout once ``deadline`` (monotonic) has passed."""
    pause = 0.0005
    start = time.monotonic()
    while not sink(*offer, True):
        if time.monotonic() >= deadline:
            raise PublishTimeout(channel[2:], max(0.0, deadline - start))
        time.sleep(pause)
        pause = min(pause * 2, 0.01)


def hand_out(sinks: Sequence[Sink], frames: list[bytes], expires: float, block: float | None,
             channel: str, options: BusOptions) -> None:  # fmt: skip
    """A message published on this bus, to its own subscriptions (``sinks``), on the
    publisher's thread: best-effort ones take it or drop it, reliable ones (``block`` given)
    are offered it until they take it or ``block`` seconds have passed (PublishTimeout)."""
    msg = decode_frames(frames, options.max_message, options.max_depth, options.total)
    size = sum(map(len, frames))
    if block is None:
        for sink in sinks:
            sink(msg, size, expires, False)
        return
    deadline = time.monotonic() + block
    for sink in sinks:
        offer_until(sink, (msg, size, expires), deadline, channel)


class Unreachable(RobosoaError):
    """A provider endpoint cannot take a message right now (gone, or its queue is full)."""


class Lost(RobosoaError):
    """The connection to an endpoint went away after a message was handed over to it (the
    peer died, or heartbeats stopped coming back): no reply can come any more."""


@dataclass(frozen=True, slots=True)
class BusOptions:
    """Tunables of one bus; every queue is bounded by one of these numbers."""

    heartbeat: float = 1.0  # seconds between provider heartbeats to the location service
    ttl: float = 3.0  # location entries expire this long after the last heartbeat
    inbox_size: int = 1000  # bounded provider inbox (inproc queue / zmq receive HWM)
    queue_size: int = 1000  # bounded per-subscription queue; oldest dropped when full
    hwm: int = 1000  # ZeroMQ send/receive high-water marks
    lookup_cache: float = 1.0  # seconds a consumer reuses a lookup result
    location_timeout: float = 2.0  # seconds to wait for the location service
    provider_bind: str = ""  # zmq: where providers bind, e.g. "tcp://0.0.0.0"; "" = derive
    advertise_host: str = ""  # zmq: host name/IP other machines use to reach our providers
    max_message: int = MAX_MESSAGE  # bytes per frame taken from a peer (ZeroMQ MAXMSGSIZE)
    max_total: int = 0  # bytes in all frames of one message taken from a peer; 0: max_message
    max_depth: int = MAX_DEPTH  # JSON nesting taken from a peer (robosoa.wire)
    link_heartbeat: float = 1.0  # zmq: seconds between ZMTP heartbeats on every connection
    link_timeout: float = 3.0  # zmq: a connection silent this long is closed (peer dead/cut off)
    deadline_slack: float = 0.0  # a provider still runs requests this late (clocks that differ)
    curve_secret: str = ""  # zmq: this participant's certificate (NAME.key_secret); "" = off
    curve_allow: str = ""  # zmq: folder of the public certificates allowed on the bus
    curve_location: str = ""  # zmq: the location service's certificate (default allow/location.key)

    @property
    def total(self) -> int:
        """Bytes one message from a peer may hold in all its frames (``max_total``, or
        ``max_message`` when that is 0)."""
        return self.max_total or self.max_message


class Incoming(NamedTuple):
    """One message taken from a provider inbox, or the reason it could not be decoded.

    A NamedTuple rather than a dataclass: one is built per message on the hot path.
    """

    message: Message | None
    problem: str
    reply: ReplyFn | None  # None when the sender expects no reply (one-way)


class Inbox(ABC):
    """A provider instance's bounded receive queue; its endpoint is what gets registered."""

    endpoint: str
    key: str = ""  # the endpoint's public key when the transport authenticates (zmq CURVE)

    @abstractmethod
    def receive(self, timeout: float) -> Incoming | None:
        """The next message, or None after ``timeout`` seconds or once woken for closing."""

    @abstractmethod
    def wake(self) -> None:
        """Make a blocked ``receive`` return (thread-safe)."""

    @abstractmethod
    def close(self) -> None:
        """Release the endpoint; called from the thread that calls ``receive``."""


class ProtocolAdapter(ABC):
    """SOA_Base plus the message primitives the bus needs."""

    scheme: str = ""

    def __init__(self, address: str, options: BusOptions) -> None:
        self.address = address
        self.options = options
        self.connected = False
        self.stats_book = StatsBook()  # the bus's counters; the transport adds role "wire"

    def rejected(self, where: str) -> None:
        """Count one frame from a peer that was refused (malformed, too large, too deep).

        Shown by ``bus.stats()`` and ``robosoa stats`` as role ``wire``, key ``where``, in
        ``errors``.
        """
        self.stats_book.counter(where, "wire").fail()

    # --- SOA_Base (Hestand 2011, p. 66) ---------------------------------------------
    @abstractmethod
    def configure(self) -> None:
        """Prepare the protocol objects for connection (no communication yet)."""

    @abstractmethod
    def connect(self) -> None:
        """Connect and be ready to communicate."""

    def reconnect(self) -> None:
        """Reuse a connection that was disconnected."""
        self.connect()

    @abstractmethod
    def disconnect(self) -> None:
        """Stop communicating but keep resources so ``reconnect`` can reuse them."""

    @abstractmethod
    def shutdown(self) -> None:
        """Release every resource; the adapter cannot be used afterwards."""

    @abstractmethod
    def ping(self, timeout: float) -> float:
        """Round-trip seconds to the location service; raises RobosoaError if unreachable."""

    def maintain(self) -> None:
        """Periodic housekeeping, called from the bus's heartbeat thread (default: nothing)."""
        return None

    def advertise(self, channel: str) -> None:
        """Get ready to publish on ``channel`` so subscribers can find this bus before its
        first message (default: nothing to prepare)."""
        return None

    def registrations(self) -> list[ServiceInfo]:
        """Entries the transport keeps registered for itself besides the providers (e.g. a
        PUB socket subscribers connect to); the bus's heartbeats refresh them."""
        return []

    # --- location service -----------------------------------------------------------
    @abstractmethod
    def location(self, request: dict[str, Any], timeout: float) -> dict[str, Any]:
        """Send one location-protocol request (see ``robosoa.location``) and return the reply."""

    # --- consumer side --------------------------------------------------------------
    @abstractmethod
    def call(self, endpoint: str, msg: Message, timeout: float) -> Message:
        """Send a request to one provider endpoint and wait for the correlated reply.

        Raises Unreachable if it cannot be handed over, RequestTimeout if no reply comes.
        """

    @abstractmethod
    def post(self, endpoint: str, msg: Message) -> None:
        """Hand a one-way message to one provider endpoint; raises Unreachable."""

    # --- provider side --------------------------------------------------------------
    @abstractmethod
    def open_inbox(self, instance: str) -> Inbox:
        """Open a provider inbox for one service instance."""

    # --- broker (publish/subscribe and events) --------------------------------------
    @abstractmethod
    def publish(self, channel: str, frames: Frames, expires: float = 0.0,
                block: float | None = None) -> None:
        """Send an encoded message (``encode_broadcast``: the JSON frame and its binary
        frames) to every subscriber of ``channel``, with the expiry (epoch seconds, 0: none)
        its sinks get. ``block`` None: best effort, never blocks, may drop. A number: the
        topic is reliable, wait up to that long for room, then raise PublishTimeout."""

    def room(self, channel: str) -> None:
        """A subscription of ``channel`` that refused a message (reliable, full) has room
        again (default: nothing to do; the publisher retries by itself)."""
        return None

    @abstractmethod
    def subscribe(self, channel: str, sink: Sink) -> Callable[[], None]:
        """Deliver messages on ``channel`` to ``sink`` until the returned function is called."""
