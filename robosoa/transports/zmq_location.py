"""The ZeroMQ location service process: location protocol on a ROUTER, plus the broker.

The broker is ZeroMQ's own XSUB/XPUB forwarder (``zmq.proxy_steerable``, C code, its own
thread); the location protocol is answered by ``robosoa.location.LocationService``.
"""

from __future__ import annotations

import json
import logging
import threading
from dataclasses import dataclass
from typing import Any

import zmq

from robosoa.location import LocationService, Peer, Registry, ServiceInfo
from robosoa.transports.zmq_sockets import location_request, split_endpoint

log = logging.getLogger("robosoa.location")

PEER_TIMEOUT = 0.3  # seconds a federated lookup may take before the peer is skipped


@dataclass(frozen=True, slots=True)
class LocationConfig:
    """Where the location service listens, its default TTL and its federation peers."""

    bind: str
    xsub: str = ""  # broker input (publishers connect); default: port + 1 or PATH.xsub
    xpub: str = ""  # broker output (subscribers connect); default: port + 2 or PATH.xpub
    ttl: float = 3.0
    federate: tuple[str, ...] = ()
    hwm: int = 1000  # broker queue per publisher (XSUB) and per subscriber (XPUB); then drops


def _wild(endpoint: str) -> str:
    scheme, host, port = split_endpoint(endpoint)
    return f"tcp://{host}:*" if scheme == "tcp" and port == 0 else endpoint


def broker_binds(config: LocationConfig) -> tuple[str, str]:
    """The XSUB and XPUB bind endpoints (explicit, or derived from the location endpoint)."""
    scheme, where, port = split_endpoint(config.bind)
    if scheme == "ipc":
        derived = (f"ipc://{where}.xsub", f"ipc://{where}.xpub")
    elif port == 0:
        derived = (f"tcp://{where}:*", f"tcp://{where}:*")
    else:
        derived = (f"tcp://{where}:{port + 1}", f"tcp://{where}:{port + 2}")
    return _wild(config.xsub or derived[0]), _wild(config.xpub or derived[1])


class LocationServer:
    """Binds the sockets at construction; ``serve`` answers until ``stop`` is called."""

    def __init__(self, config: LocationConfig) -> None:
        self.config = config
        self._ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
        self._router = self._socket(zmq.ROUTER, _wild(config.bind))
        xsub_bind, xpub_bind = broker_binds(config)
        self._xsub = self._socket(zmq.XSUB, xsub_bind, config.hwm)
        self._xpub = self._socket(zmq.XPUB, xpub_bind, config.hwm)
        self.endpoint = self._last(self._router)
        self.broker = (self._last(self._xsub), self._last(self._xpub))
        hello = {"transport": "zmq", "xsub": self.broker[0], "xpub": self.broker[1]}
        self.service = LocationService(Registry(default_ttl=config.ttl), self._peer, hello,
                                       name=self.endpoint)
        for address in config.federate:
            self.service.federate(address)
        self._control = f"inproc://robosoa-proxy-{id(self)}"
        self._stop = threading.Event()
        self._proxy = threading.Thread(target=self._run_proxy, daemon=True, name="robosoa-broker")

    def _socket(self, kind: int, bind: str, hwm: int = 1000) -> zmq.Socket[bytes]:
        sock = self._ctx.socket(kind)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.SNDHWM, hwm)
        sock.setsockopt(zmq.RCVHWM, hwm)
        sock.bind(bind)
        return sock

    @staticmethod
    def _last(sock: zmq.Socket[bytes]) -> str:
        return str(sock.getsockopt_string(zmq.LAST_ENDPOINT))

    def _peer(self, address: str) -> Peer:
        ctx = self._ctx

        def lookup(name: str | None) -> list[ServiceInfo]:
            reply = location_request(ctx, address, {"op": "lookup", "name": name, "local": True},
                                     PEER_TIMEOUT)
            return [ServiceInfo.from_dict(d) for d in reply.get("services", [])]

        return lookup

    def _run_proxy(self) -> None:
        control = self._ctx.socket(zmq.PAIR)
        control.connect(self._control)
        try:
            zmq.proxy_steerable(self._xsub, self._xpub, None, control)
        except zmq.ContextTerminated:
            pass
        finally:
            control.close(0)

    def _answer(self, frames: list[bytes]) -> None:
        if len(frames) != 2:
            return
        try:
            request: Any = json.loads(frames[1])
        except ValueError:
            request = None
        if isinstance(request, dict):
            reply = self.service.handle(request)
            reply["rid"] = request.get("rid")
        else:
            reply = {"error": "location request is not a JSON object"}
        self._router.send_multipart([frames[0], json.dumps(reply).encode()], zmq.NOBLOCK)

    def serve(self) -> None:
        """Answer location requests and forward broker traffic until ``stop``."""
        steer = self._ctx.socket(zmq.PAIR)
        steer.bind(self._control)
        self._proxy.start()
        log.info("location service started", extra={"endpoint": self.endpoint,
                                                    "xsub": self.broker[0],
                                                    "xpub": self.broker[1]})
        try:
            while not self._stop.is_set():
                if self._router.poll(200, zmq.POLLIN):
                    self._answer(self._router.recv_multipart())
                self.service.registry.expire()
        finally:
            steer.send(b"TERMINATE")
            self._proxy.join(timeout=5.0)
            steer.close(0)
            for sock in (self._router, self._xsub, self._xpub):
                sock.close(0)
            self._ctx.term()

    def stop(self) -> None:
        """Make ``serve`` return (thread-safe, signal-safe)."""
        self._stop.set()
