"""What the runtime needs beyond the analyzer: pyzmq (the ``zmq`` transport, the location
service, CurveZMQ) and lxml (service descriptors and code generation). They install with
the ``runtime`` extra, ``pip install 'archmetrics[runtime]'``; a plain ``pip install
archmetrics`` has the analyzer only, and robosoa's in-process bus works without either."""

from __future__ import annotations

from robosoa.errors import RobosoaError

EXTRA = "pip install 'archmetrics[runtime]'"
_PROVIDES = {"zmq": "pyzmq", "lxml": "lxml"}


def missing(error: ModuleNotFoundError, feature: str) -> RobosoaError | None:
    """A one-line error naming the extra when ``error`` is one of the runtime's libraries
    missing, else None (another module is missing: a real error)."""
    top = (error.name or "").partition(".")[0]
    if top not in _PROVIDES:
        return None
    return RobosoaError(f"{feature} needs {_PROVIDES[top]}, which is not installed: {EXTRA}")
