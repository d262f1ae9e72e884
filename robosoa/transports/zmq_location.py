"""The ZeroMQ location service process: location protocol on a ROUTER, announcements on a PUB.

There is no broker: publishers bind their own PUB sockets and register them here as
``robosoa.pub`` entries; subscribers connect to them directly. Whenever the set of publishers
changes, this process says so on its announcement PUB (``a:`` channel, no contents: a
subscriber that hears it looks the publishers up again), so new publishers are found in
milliseconds; a subscriber also looks them up every heartbeat, so nothing depends on an
announcement arriving. The location protocol is answered by
``robosoa.location.LocationService``.
"""

from __future__ import annotations

import contextlib
import logging
import threading
import time
from dataclasses import dataclass, field
from typing import Any

import zmq

from robosoa.errors import InvalidMessage, RobosoaError
from robosoa.location import Limits, LocationService, Peer, Registry, ServiceInfo
from robosoa.transports import zmq_curve as curve
from robosoa.transports.zmq_federation import PEER_REPLY, FederationPool, encode_reply
from robosoa.transports.zmq_guard import CURVE_FRAMING, FRAMING, Guard, budget
from robosoa.transports.zmq_sockets import (
    Waker,
    check_endpoint,
    keepalive,
    limit_input,
    location_frame,
    split_endpoint,
)
from robosoa.wire import MAX_DEPTH, MAX_MESSAGE, load_object

log = logging.getLogger("robosoa.location")

PEER_TIMEOUT = 0.3  # seconds a federated lookup may take before the peer is skipped
LINK_HEARTBEAT, LINK_TIMEOUT = 1.0, 3.0  # ZMTP heartbeats, as BusOptions' defaults
ANNOUNCE = b"a:\0"  # channel of "the publishers changed" announcements
# Peers' replies are read one at a time, in the order they arrive: read together, 32
# replies of a megabyte share the interpreter and all finish late; one by one, the first
# ones are done within the federation timeout and only the slowest are dropped.
_READING = threading.Lock()
MIN_REPLY = 64 * 1024  # a smaller max_bytes from an asker is not taken (room for an error)
NO_CURVE = "a federated location service's key cannot be given"


@dataclass(frozen=True, slots=True)
class LocationConfig:
    """Where the location service listens, its default TTL, its federation peers and what it
    accepts from peers (every limit is documented in docs/security.md)."""

    bind: str
    announce: str = ""  # PUB of publisher-set changes; default: port + 1 or PATH.announce
    ttl: float = 3.0
    federate: tuple[str, ...] = ()
    max_message: int = MAX_MESSAGE  # bytes per frame from a peer
    max_depth: int = MAX_DEPTH  # JSON nesting of one location request
    limits: Limits = field(default_factory=Limits)  # registrations, TTLs, federation
    curve_secret: str = ""  # this service's certificate (NAME.key_secret); "" = no CURVE
    curve_allow: str = ""  # folder of the public certificates allowed on the bus
    accept_federate: bool = False  # clients may add federation peers (no CURVE only)


def _wild(endpoint: str) -> str:
    scheme, host, port = split_endpoint(endpoint)
    return f"tcp://{host}:*" if scheme == "tcp" and port == 0 else endpoint


def announce_bind(config: LocationConfig) -> str:
    """The announcement PUB's bind endpoint (explicit, or derived from the location's)."""
    scheme, where, port = split_endpoint(config.bind)
    if scheme == "ipc":
        derived = f"ipc://{where}.announce"
    elif port == 0:
        derived = f"tcp://{where}:*"
    else:
        derived = f"tcp://{where}:{port + 1}"
    return _wild(config.announce or derived)


def _refusal(config: LocationConfig, curve: bool) -> str:
    """Why a client's ``federate`` is refused ("" when it is accepted)."""
    if curve:
        return f"federation over CURVE is not available ({NO_CURVE})"
    if not config.accept_federate:
        return ("only the operator adds federation peers (robosoa location --federate "
                "ENDPOINT, or --accept-federate to take them from clients)")
    return ""


def _entries(address: str, frame: bytes, limit: int) -> list[ServiceInfo]:
    """The entries of a federated peer's reply; RobosoaError if it is malformed."""
    try:
        services = load_object(frame, limit).get("services", [])
    except InvalidMessage as exc:
        raise RobosoaError(f"location service at {address} sent a bad reply: {exc}") from None
    if not isinstance(services, list):
        raise RobosoaError(f"location service at {address} sent a bad reply")
    return [ServiceInfo.from_dict(d) for d in services]


def _peer_of(frame: zmq.Frame) -> str:
    """Who sent ``frame`` (registry ownership): its CURVE public key when the bus uses CURVE,
    else the remote host for tcp, the process for ipc."""
    for prop in ("User-Id", "Peer-Address"):
        try:
            found = str(frame.get(prop))
        except zmq.ZMQError:
            continue
        if found and found != "anonymous":
            return found
    return ""


class LocationServer:
    """Binds the sockets at construction; ``serve`` answers until ``stop`` is called."""

    def __init__(self, config: LocationConfig) -> None:
        self.config = config
        self.curve = curve.load(config.curve_secret, config.curve_allow, "", server=True)
        if self.curve is not None and (config.federate or config.accept_federate):
            flag = "--federate" if config.federate else "--accept-federate"
            raise RobosoaError(f"{flag} is not available with CURVE yet ({NO_CURVE})")
        self._ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
        self._auth = self.curve.authenticator(self._ctx) if self.curve is not None else None
        self._sockets: list[zmq.Socket[bytes]] = []
        self._waker = Waker(self._ctx)  # federation workers' replies are ready
        self._federation = FederationPool(self._waker.wake)
        self._guard = Guard()
        try:  # a bind that fails (bad address, port taken) releases what was bound before
            self._router = self._socket(zmq.ROUTER, _wild(config.bind))
            self._announce = self._socket(zmq.PUB, announce_bind(config))
        except BaseException:
            self._release()
            raise
        self.endpoint = self._last(self._router)
        self.announce = self._last(self._announce)
        hello = {"transport": "zmq", "announce": self.announce}
        registry = Registry(default_ttl=config.ttl, limits=config.limits)
        peers = None if self.curve is not None else self._peer  # never asked in plaintext
        self._watch = self._guard.watch(self._router, budget(config.max_message),
                                        FRAMING if self.curve is None else CURVE_FRAMING,
                                        lambda peer: self.service.counter.drop("budget"))
        self.service = LocationService(registry, peers, hello, name=self.endpoint,
                                       limits=config.limits, refuse_federate=_refusal(config,
                                       self.curve is not None))
        for address in config.federate:
            self.service.federate(address)
        self._stop = threading.Event()
        self._publishers = registry.publishers()

    def _socket(self, kind: int, bind: str, hwm: int = 1000) -> zmq.Socket[bytes]:
        check_endpoint(bind)
        sock = self._ctx.socket(kind)
        self._sockets.append(sock)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.SNDHWM, hwm)
        sock.setsockopt(zmq.RCVHWM, hwm)
        limit_input(sock, self.config.max_message)
        keepalive(sock, LINK_HEARTBEAT, LINK_TIMEOUT)
        if self.curve is not None:
            self.curve.serve(sock)
        try:
            sock.bind(bind)
        except zmq.ZMQError as exc:
            raise RobosoaError(f"cannot bind {bind}: {exc.strerror}") from None
        return sock

    @staticmethod
    def _last(sock: zmq.Socket[bytes]) -> str:
        return str(sock.getsockopt_string(zmq.LAST_ENDPOINT))

    def _peer(self, address: str) -> Peer:
        if self.curve is not None:  # a plaintext socket must never leave a CURVE bus
            raise RobosoaError(f"federation over CURVE is not available ({NO_CURVE})")
        ctx = self._ctx
        check_endpoint(address)
        budget = self.config.limits.federation_timeout
        timeout = min(PEER_TIMEOUT, budget)
        limit = min(PEER_REPLY, self.config.max_message)
        request = {"op": "lookup", "local": True, "max_bytes": limit}

        def lookup(name: str | None) -> list[ServiceInfo]:
            deadline = time.monotonic() + budget  # ask_all gives up on us then
            frame = location_frame(ctx, address, {**request, "name": name}, timeout, limit)
            if not _READING.acquire(timeout=max(0.0, deadline - time.monotonic())):
                raise TimeoutError(f"location service at {address}: reply not read in time")
            try:
                return _entries(address, frame, limit)
            finally:
                _READING.release()

        return lookup

    def _announce_changes(self) -> None:
        """Say on the announcement PUB that the publishers changed, if they did."""
        now = self.service.registry.publishers()
        if now != self._publishers:
            self._publishers = now
            with contextlib.suppress(zmq.ZMQError):
                self._announce.send_multipart([ANNOUNCE, str(now).encode()], zmq.NOBLOCK)

    def _answer(self, frames: list[zmq.Frame]) -> None:
        """Answer one request, or hand it to a federation worker if it must ask peers; a
        malformed one gets an error reply and is counted."""
        identity = frames[0].bytes
        try:
            request = self._request(frames)
        except InvalidMessage as exc:
            self.service.counter.record(None, error=True)
            self._send(identity, encode_reply({"error": f"bad location request: {exc}"},
                                              None, self.config.max_message)[0])
            return
        peer = _peer_of(frames[-1])
        if self.service.needs_peers(request):
            if self._federation.submit(identity, lambda: self._reply(request, peer)):
                return
            self.service.counter.drop("busy")
            request = {**request, "local": True}
        self._send(identity, self._reply(request, peer))

    def _reply(self, request: dict[str, Any], peer: str) -> bytes:
        """The reply frame to ``request``, within the asker's frame limit (its
        ``max_bytes``, at most ours); entries left out are counted as ``truncated``."""
        limit = self.config.max_message
        asked = request.get("max_bytes")
        if type(asked) is int and asked >= MIN_REPLY:
            limit = min(limit, asked)
        frame, left_out = encode_reply(self.service.handle(request, peer), request.get("rid"),
                                       limit)
        if left_out:
            self.service.counter.drop("truncated", left_out)
        return frame

    def _send(self, identity: bytes, frame: bytes) -> None:
        with contextlib.suppress(zmq.ZMQError):  # the peer is gone or its queue is full
            self._router.send_multipart([identity, frame], zmq.NOBLOCK)

    def _request(self, frames: list[zmq.Frame]) -> dict[str, Any]:
        if len(frames) != 2:
            raise InvalidMessage(f"expected one message frame, got {len(frames) - 1}")
        config = self.config
        request = load_object(frames[1].bytes, config.max_message, config.max_depth)
        if type(request.get("op")) is not str:
            raise InvalidMessage("op is not a string")
        if type(request.get("rid")) not in (int, str, type(None)):
            raise InvalidMessage("rid is not a number or a string")
        return request

    def serve(self) -> None:
        """Answer location requests and announce publisher changes until ``stop``."""
        log.info("location service started", extra={"endpoint": self.endpoint,
                                                    "announce": self.announce})
        poller = zmq.Poller()
        poller.register(self._router, zmq.POLLIN)
        poller.register(self._waker.rx, zmq.POLLIN)
        try:
            while not self._stop.is_set():
                ready = dict(poller.poll(200))
                if self._router in ready:
                    frames = self._router.recv_multipart(copy=False)
                    if self._watch is not None:
                        self._watch.took(b"", sum(len(f) for f in frames[1:]),
                                         len(frames) - 1, frames[0])
                    try:
                        self._answer(frames)
                    except Exception:  # last line of defence: no request ends the service
                        self.service.counter.fail()
                        log.exception("location request failed")
                if self._waker.rx in ready:
                    self._waker.drain()
                for identity, frame in self._federation.finished():
                    self._send(identity, frame)
                self.service.registry.expire()
                self._announce_changes()
        finally:
            self._release()

    def _release(self) -> None:
        self._guard.close()
        self._federation.close()
        self._waker.close()
        for sock in self._sockets:
            sock.close(0)
        if self._auth is not None:
            self._auth.stop()
        self._ctx.term()

    def stop(self) -> None:
        """Make ``serve`` return (thread-safe, signal-safe)."""
        self._stop.set()
