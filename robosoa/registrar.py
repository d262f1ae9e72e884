"""The provider side of the location service (fig. 5.2): register, heartbeat, unregister.

One heartbeat thread per bus re-registers every live provider each ``heartbeat`` seconds, so
entries stay alive while the process lives, expire after their TTL when it dies, and a
restarted location service is re-populated at the next beat.
"""

from __future__ import annotations

import logging
import threading

from robosoa.errors import RobosoaError
from robosoa.location import ServiceInfo
from robosoa.provider import ProviderHandle
from robosoa.transports.base import BusOptions, ProtocolAdapter

log = logging.getLogger("robosoa.bus")

UNREGISTER_TIMEOUT = 0.5  # seconds; past it the entry simply expires after its TTL


class Registrar:
    """Keeps this bus's providers registered; runs the heartbeat thread."""

    def __init__(self, adapter: ProtocolAdapter, options: BusOptions) -> None:
        self._adapter = adapter
        self._options = options
        self._handles: dict[str, ProviderHandle] = {}
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._beat, daemon=True, name="robosoa-heartbeat")
        self._thread.start()

    def add(self, handle: ProviderHandle) -> None:
        """Track ``handle`` and register it at once."""
        with self._lock:
            self._handles[handle.instance] = handle
        self.register(handle.info)

    def remove(self, handle: ProviderHandle) -> None:
        """Forget ``handle`` and unregister it (best effort: otherwise its entry expires)."""
        with self._lock:
            self._handles.pop(handle.instance, None)
        if not self._adapter.connected:
            return
        try:
            self._adapter.location({"op": "unregister", "instance": handle.instance},
                                   min(self._options.location_timeout, UNREGISTER_TIMEOUT))
        except RobosoaError as exc:
            log.info("unregister failed", extra={"service": handle.info.name, "error": str(exc)})

    def handles(self) -> list[ProviderHandle]:
        """The live provider handles."""
        with self._lock:
            return list(self._handles.values())

    def register(self, info: ServiceInfo) -> bool:
        """Register (or refresh) one entry; False if the location service could not be
        reached (logged; the next beat retries)."""
        try:
            reply = self._adapter.location({"op": "register", "service": info.to_dict()},
                                           self._options.location_timeout)
            if "error" in reply:
                log.warning("registration refused", extra={"service": info.name,
                                                           "reason": reply["error"]})
        except RobosoaError as exc:
            log.warning("registration failed", extra={"service": info.name, "error": str(exc)})
            return False
        return True

    def register_all(self) -> None:
        """Refresh every entry now (after a reconnect), the transport's own ones too; stops
        at the first that cannot reach the location service (the others would wait too)."""
        for info in [*(h.info for h in self.handles()), *self._adapter.registrations()]:
            if not self.register(info):
                return

    def _beat(self) -> None:
        away = False
        while not self._stop.wait(self._options.heartbeat):
            if not self._adapter.connected:
                continue  # disconnected: no heartbeats, so our entries expire
            try:
                self._adapter.maintain()
            except Exception as exc:  # the location service is away: try at the next beat
                if not away:
                    log.warning("location service unreachable", extra={"error": str(exc)})
                away = True
                continue
            if away:
                log.info("location service back: registering again")
            away = False
            self.register_all()

    def stop(self) -> None:
        """Ask the heartbeat thread to end (it ends at its next wake-up)."""
        self._stop.set()

    def join(self) -> None:
        """Wait for the heartbeat thread (bounded)."""
        self._thread.join(timeout=5.0)
