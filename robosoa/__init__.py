"""robosoa: the reference service-oriented runtime that archmetrics measures (Hestand 2011, ch. 5).

``robosoa.connect(url)`` gives a Bus offering every message exchange pattern over the
``inproc`` (embedded) or ``zmq`` (ZeroMQ, between processes and machines) transport.
"""

from __future__ import annotations

from dataclasses import fields
from typing import Any

from robosoa.bridge import Bridge
from robosoa.bus import Bus
from robosoa.channel import Channel
from robosoa.errors import (
    BusClosed,
    InvalidMessage,
    ProviderLost,
    PublishTimeout,
    RemoteError,
    RemoteInvalidMessage,
    RequestTimeout,
    RobosoaError,
    ServiceNotFound,
)
from robosoa.location import ServiceInfo
from robosoa.message import Kind, Message
from robosoa.provider import ERROR_EVENT, ProviderHandle
from robosoa.qos import QoS
from robosoa.router import Router, RuleError
from robosoa.stats import ServiceFigures
from robosoa.subscription import Subscription
from robosoa.transports import make_adapter
from robosoa.transports.base import BusOptions

__version__ = "0.1.0"

_OPTION_NAMES = {f.name for f in fields(BusOptions)}


def connect(url: str = "inproc", **options: Any) -> Bus:
    """Connect to a bus: ``inproc``, ``inproc://NAME``, ``zmq://tcp://HOST:PORT`` or
    ``zmq://ipc:///PATH`` (the location service's endpoint). Keyword options are
    ``BusOptions`` fields, e.g. ``heartbeat=0.2, ttl=0.6``."""
    unknown = set(options) - _OPTION_NAMES
    if unknown:
        raise TypeError(f"unknown bus options: {', '.join(sorted(unknown))}")
    return Bus(make_adapter(url, BusOptions(**options)))


def bridge(source: Bus, target: Bus, services: tuple[str, ...] | list[str] = (),
           topics: tuple[str, ...] | list[str] = (), events: tuple[str, ...] | list[str] = (),
           both_ways: bool = False) -> Bridge:
    """Join two buses: ``services`` of ``source`` become callable on ``target``; topics and
    events are forwarded (both ways if asked)."""
    return Bridge(source, target, services, topics, events, both_ways)


__all__ = [
    "ERROR_EVENT", "Bridge", "Bus", "BusClosed", "BusOptions", "Channel", "InvalidMessage",
    "Kind", "Message", "ProviderHandle", "ProviderLost", "PublishTimeout", "QoS", "RemoteError",
    "RemoteInvalidMessage",
    "RequestTimeout", "RobosoaError", "Router", "RuleError", "ServiceFigures", "ServiceInfo",
    "ServiceNotFound", "Subscription", "bridge", "connect",
]
