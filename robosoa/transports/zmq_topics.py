"""Publish/subscribe of one ZeroMQ bus without a broker: the bus's outlet (its own PUB,
made at the first publish), its feed (one SUB, made at the first subscribe) and discovery
(which keeps the feed connected to every publisher the location service knows).

Failure modes (docs/runtime.md, *No single point of failure*): connections that exist keep
carrying messages when the location service dies; what needs the location service is
finding publishers that appear meanwhile.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from typing import Any

import zmq

from robosoa.errors import PublishTimeout, RobosoaError
from robosoa.location import PUBLISHERS, ServiceInfo
from robosoa.message import Frames
from robosoa.transports.base import BusOptions, Sink
from robosoa.transports.zmq_curve import Curve
from robosoa.transports.zmq_guard import Guarding
from robosoa.transports.zmq_outlet import RELIABLE, Outlet
from robosoa.transports.zmq_pubsub import Feed

log = logging.getLogger("robosoa.zmq")

Location = Callable[[dict[str, Any], float], dict[str, Any]]
Peers = dict[str, str]  # endpoint -> its CURVE key ("" without CURVE)
Found = tuple[Peers, Peers]  # publishers' PUBs and reliable XPUBs
LOOKUP_TIMEOUT = 1.0  # seconds one look-up of the publishers may take
QUIET = 0.05  # seconds between two look-ups prompted by announcements (however many)


class Discovery:
    """A thread that looks the publishers up at once when woken, and every ``every`` s."""

    def __init__(self, ask: Callable[[], Found | None], apply: Callable[[Found], None],
                 every: float) -> None:
        self._ask = ask
        self._apply = apply
        self._every = every
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True,
                                        name="robosoa-discovery")
        self._thread.start()

    def wake(self) -> None:
        """Look again now (an announcement came)."""
        self._wake.set()

    def _run(self) -> None:
        while not self._stop.is_set():
            self._wake.wait(self._every)
            if self._stop.wait(QUIET):
                return
            self._wake.clear()
            found = self._ask()
            if found is not None:  # the location service failed: keep what we have
                self._apply(found)

    def close(self) -> None:
        """Stop the thread (it ends within ``QUIET`` s of its current look-up)."""
        self._stop.set()
        self._wake.set()
        self._thread.join(timeout=5.0)


class Topics:
    """The publish/subscribe side of a ZeroMQ bus."""

    def __init__(self, ctx: zmq.Context[zmq.Socket[bytes]], location: str, options: BusOptions,
                 ask: Location, rejected: Callable[[str], None],
                 lost: Callable[[str, int], None], curve: Curve | None = None,
                 guarding: Guarding | None = None,
                 cut: Callable[[str], None] = lambda peer: None) -> None:
        self._curve = curve
        self._guarding = guarding  # bounds what each publisher's connection holds
        self._cut = cut
        self._ctx = ctx
        self._location = location
        self._options = options
        self._ask = ask
        self._rejected = rejected
        self._lost = lost
        self._lock = threading.Lock()
        self._outlet: Outlet | None = None
        self._feed: Feed | None = None
        self._discovery: Discovery | None = None
        self._found: Found = ({}, {})
        self.announce = ""

    def outlet(self) -> Outlet:
        """This bus's PUB, bound and registered at the first call."""
        outlet = self._outlet
        if outlet is not None:
            return outlet
        with self._lock:
            if self._outlet is None:
                self._outlet = Outlet(self._ctx, self._location, self._options, self._curve)
                for info in self._outlet.infos:
                    self._register(info)
            return self._outlet

    def publish(self, channel: str, frames: Frames, expires: float = 0.0,
                block: float | None = None) -> None:
        """Send to every subscriber connected to this bus's PUB now (its reliable XPUB when
        ``block`` is given; PublishTimeout if there was no room in time), and to this bus's
        own subscriptions directly."""
        outlet = self.outlet()
        if block is None:
            outlet.publish(channel, frames, expires)
        elif not outlet.publish_reliably(channel, frames, expires, block):
            raise PublishTimeout(channel[2:], block)
        feed = self._feed
        if feed is not None:
            feed.local(channel, frames, expires, block)

    def room(self, channel: str) -> None:
        """A reliable subscription has room: the feed offers what it held back again."""
        if self._feed is not None:
            self._feed.room()

    def tidy(self) -> None:
        """Housekeeping of the heartbeat thread."""
        if self._outlet is not None:
            self._outlet.tidy()

    def subscribe(self, channel: str, sink: Sink) -> Callable[[], None]:
        """Deliver ``channel`` to ``sink``; the first call connects to every publisher."""
        feed = self._feed
        if feed is None:
            with self._lock:
                if self._feed is None:
                    self._feed = Feed(self._ctx, self._options, self._rejected, self._lost,
                                      self.announce, self._announced, self._curve,
                                      self._guarding, self._cut)
                    self._discovery = Discovery(self._publishers, self._connected,
                                                max(0.1, self._options.heartbeat))
                feed = self._feed
            found = self._publishers()
            if found is not None:
                self._found = found
            self._connect(wait=True)
        return feed.subscribe(channel, sink)

    def follow(self, announce: str) -> None:
        """The location service's announcement endpoint (from its ``hello``)."""
        if announce != self.announce:
            self.announce = announce
            if self._feed is not None:
                self._feed.move(announce)

    def registrations(self) -> list[ServiceInfo]:
        """The entries this bus keeps registered for its topics (its PUB)."""
        outlet = self._outlet
        return list(outlet.infos) if outlet is not None else []

    def _register(self, info: ServiceInfo) -> None:
        try:
            self._ask({"op": "register", "service": info.to_dict()},
                      self._options.location_timeout)
        except RobosoaError as exc:  # the heartbeats try again
            log.warning("publisher registration failed", extra={"error": str(exc)})

    def _announced(self) -> None:
        if self._discovery is not None:
            self._discovery.wake()

    def _publishers(self) -> Found | None:
        """Endpoints of every publisher the location service knows (best-effort PUBs,
        reliable XPUBs), or None if it could not be asked."""
        request = {"op": "lookup", "name": PUBLISHERS, "local": True}
        try:
            reply = self._ask(request, min(LOOKUP_TIMEOUT, self._options.location_timeout))
        except RobosoaError:
            return None
        found = reply.get("services")
        if not isinstance(found, list):
            return None
        lossy: Peers = {}
        reliable: Peers = {}
        for data in found:
            try:
                info = ServiceInfo.from_dict(data)
            except ValueError:
                continue
            if self._curve is not None and not info.key:
                continue  # nobody to authenticate: not connected to
            (reliable if info.group == RELIABLE else lossy)[info.endpoint] = info.key
        return lossy, reliable

    def _connected(self, found: Found) -> None:
        self._found = found
        self._connect()

    def _connect(self, wait: bool = False) -> None:
        """Connect the feed to what was found, except this bus's own sockets."""
        feed, outlet = self._feed, self._outlet
        if feed is not None:
            own = {outlet.endpoint, outlet.reliable_endpoint} if outlet is not None else set()
            lossy, reliable = ({e: k for e, k in peers.items() if e not in own}
                               for peers in self._found)
            feed.connect((lossy, reliable), wait)

    def close(self) -> None:
        """Stop discovery and the feed, close the PUB."""
        if self._discovery is not None:
            self._discovery.close()
        if self._feed is not None:
            self._feed.close()
        if self._outlet is not None:
            self._outlet.close()
