"""Transport registry: URL scheme -> protocol adapter class (one module per transport).

Built-in transports are listed here explicitly; third-party ones register through the
``robosoa.transports`` entry-point group and are type-checked when loaded.
"""

from __future__ import annotations

from importlib import import_module
from importlib.metadata import entry_points

from robosoa.errors import RobosoaError
from robosoa.extras import missing
from robosoa.transports.base import BusOptions, ProtocolAdapter

BUILTIN: dict[str, str] = {
    "inproc": "robosoa.transports.inproc:InprocAdapter",
    "zmq": "robosoa.transports.zmq_adapter:ZmqAdapter",
}
ENTRY_POINT_GROUP = "robosoa.transports"


def _load(target: str) -> type[ProtocolAdapter]:
    module, _, name = target.partition(":")
    try:
        loaded = import_module(module)
    except ModuleNotFoundError as error:  # pyzmq: the runtime extra
        said = missing(error, f"the transport {target.partition(':')[0]}")
        if said is None:
            raise
        raise said from error
    found = getattr(loaded, name)
    if not (isinstance(found, type) and issubclass(found, ProtocolAdapter)):
        raise RobosoaError(f"transport {target} is not a ProtocolAdapter subclass")
    return found


def adapter_class(scheme: str) -> type[ProtocolAdapter]:
    """The adapter class for a URL scheme (``inproc``, ``zmq`` or a plug-in)."""
    if scheme in BUILTIN:
        return _load(BUILTIN[scheme])
    for point in entry_points(group=ENTRY_POINT_GROUP):
        if point.name == scheme:
            return _load(point.value)
    known = ", ".join(sorted(BUILTIN))
    raise RobosoaError(f"unknown transport {scheme!r} (known: {known})")


def make_adapter(url: str, options: BusOptions) -> ProtocolAdapter:
    """Build (not yet connect) the adapter for ``url``."""
    scheme = url.split(":", 1)[0] if ":" in url else url
    return adapter_class(scheme)(url, options)


__all__ = ["BusOptions", "ProtocolAdapter", "adapter_class", "make_adapter"]
