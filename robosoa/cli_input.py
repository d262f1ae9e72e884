"""Command-line input, checked before anything connects or binds: ``key=value`` payloads,
endpoints, positive numbers and the location service's configuration. Bad input raises
:class:`UsageError` (exit status 2, one line on stderr)."""

from __future__ import annotations

import argparse
import math
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from robosoa.errors import InvalidMessage, RobosoaError
from robosoa.wire import LimitExceeded, load_json

if TYPE_CHECKING:
    from robosoa.transports.zmq_location import LocationConfig


class UsageError(Exception):
    """Bad command-line input (exit status 2)."""


def parse_pairs(pairs: Sequence[str], raw_json: str | None) -> dict[str, Any]:
    """``key=value`` words (values parsed as JSON when they are JSON) merged over ``--json``.

    JSON is read within the bus's limits (``robosoa.wire``), so what the command line accepts
    a provider accepts too; an empty value is refused (write ``key='""'`` for "").
    """
    payload: dict[str, Any] = {}
    if raw_json is not None:
        try:
            loaded = load_json(raw_json)
        except InvalidMessage as exc:
            raise UsageError(f"--json: {exc}") from None
        if not isinstance(loaded, dict):
            raise UsageError("--json must be a JSON object")
        payload.update(loaded)
    for pair in pairs:
        key, sep, value = pair.partition("=")
        if not sep or not key or not value:
            raise UsageError(f"expected key=value with a non-empty key and value, got {pair!r}")
        try:
            payload[key] = load_json(value)
        except LimitExceeded as exc:
            raise UsageError(f"{key}: {exc}") from None
        except InvalidMessage:
            payload[key] = value
    return payload


def endpoint(flag: str, address: str) -> str:
    """``address`` if it is a usable ZeroMQ endpoint, else UsageError naming ``flag``."""
    from robosoa.transports.zmq_sockets import check_endpoint

    try:
        return check_endpoint(address)
    except RobosoaError as exc:
        raise UsageError(f"{flag}: {exc}") from None


def positive(flag: str, value: float, integer: bool = False) -> None:
    """UsageError unless ``value`` is finite and > 0 (and whole when ``integer``)."""
    if not (math.isfinite(value) and value > 0) or (integer and value != int(value)):
        kind = "a whole number" if integer else "a finite number"
        raise UsageError(f"{flag} must be {kind} > 0, got {value!r}")


def location_config(args: argparse.Namespace) -> LocationConfig:
    """The location service's configuration from its flags; UsageError for a bad one."""
    from robosoa.location import Limits
    from robosoa.transports.zmq_location import LocationConfig

    binds = [("--bind", args.bind), ("--announce", args.announce)]
    binds += [("--federate", f) for f in args.federate or ()]
    for flag, address in binds:
        if address:
            endpoint(flag, address)
    for flag, value in [("--ttl", args.ttl), ("--max-ttl", args.max_ttl),
                        ("--federation-timeout", args.federation_timeout)]:
        positive(flag, value)
    for flag, value in [("--max-message", args.max_message),
                        ("--max-depth", args.max_depth), ("--max-entries", args.max_entries),
                        ("--max-per-peer", args.max_per_peer), ("--max-peers", args.max_peers)]:
        positive(flag, value, integer=True)
    limits = Limits(args.max_ttl, args.max_entries, args.max_per_peer, args.max_peers,
                    args.federation_timeout)
    return LocationConfig(args.bind, args.announce or "", args.ttl,
                          tuple(args.federate or ()), args.max_message,
                          args.max_depth, limits, args.curve_secret or "",
                          args.curve_allow or "", args.accept_federate)
