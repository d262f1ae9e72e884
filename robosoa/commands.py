"""The ``robosoa`` subcommands: each takes parsed arguments and returns an exit status."""
from __future__ import annotations

import argparse
import json
import os
import signal
import sys
import threading
import time
from collections.abc import Callable
from importlib import import_module
from typing import Any

from robosoa import connect
from robosoa.bus import Bus
from robosoa.cli_input import UsageError, endpoint, location_config, parse_pairs, positive
from robosoa.errors import RobosoaError
from robosoa.extras import missing
from robosoa.location import BUS_ENTRY, ServiceInfo

DEFAULT_LOCATION = "zmq://tcp://127.0.0.1:5555"
PUBLISH_SETTLE = 0.3  # seconds a fresh publisher waits so that subscribers have joined it


def location_url(text: str | None) -> str:
    """``--location`` (or $ROBOSOA_LOCATION) as a bus URL; bare tcp:// and ipc:// accepted."""
    url = text or os.environ.get("ROBOSOA_LOCATION") or DEFAULT_LOCATION
    return url if url.startswith(("zmq://", "inproc")) else f"zmq://{url}"


def _checked_url(flag: str, text: str | None) -> str:
    """``location_url(text)``, its endpoint checked (UsageError naming ``flag``)."""
    url = location_url(text)
    if url.startswith("zmq://"):
        endpoint(flag, url.removeprefix("zmq://"))
    return url


def _bus(args: argparse.Namespace) -> Bus:
    url = _checked_url("--location", args.location)
    positive("--connect-timeout", args.connect_timeout)
    return connect(url, location_timeout=args.connect_timeout, **_curve_options(args))


def _curve_options(args: argparse.Namespace) -> dict[str, str]:
    """CURVE options of a client command (empty ones fall back to the environment)."""
    from robosoa.transports import zmq_curve as curve

    options = {"curve_secret": args.curve_secret or "", "curve_allow": args.curve_allow or "",
               "curve_location": getattr(args, "curve_location", None) or ""}
    try:
        curve.load(options["curve_secret"], options["curve_allow"], options["curve_location"])
    except RobosoaError as exc:
        raise UsageError(str(exc)) from None
    return options


def cmd_location(args: argparse.Namespace) -> int:
    """Run a location service (and its message broker) until SIGINT/SIGTERM."""
    from robosoa.transports.zmq_location import LocationServer

    config = location_config(args)
    try:
        server = LocationServer(config)
    except RobosoaError as exc:  # cannot bind or federate, bad keys: the flags are wrong
        raise UsageError(str(exc)) from None
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: server.stop())
    print(f"robosoa location service on {server.endpoint} announce={server.announce}",
          flush=True)
    print(_exposure(server.endpoint, server.curve is not None), file=sys.stderr, flush=True)
    server.serve()
    return 0


def _exposure(endpoint: str, secured: bool) -> str:
    """What the location service's binding means for who can join the bus."""
    host = endpoint.removeprefix("tcp://").rpartition(":")[0].strip("[]")
    if secured:
        return "robosoa: CURVE on: only the keys of the allow folder can join; traffic encrypted"
    if endpoint.startswith("ipc://") or host in ("127.0.0.1", "::1", "localhost"):
        return ("robosoa: bound to this machine only (loopback/ipc): other machines cannot "
                "join; to open the bus, bind an address with --curve-secret and --curve-allow "
                "(docs/runtime.md, Security)")
    return (f"robosoa: WARNING: {endpoint} is reachable from the network WITHOUT "
            "authentication or encryption: anyone who reaches it can register, publish and "
            "call; use --curve-secret and --curve-allow (docs/runtime.md, Security)")


def cmd_keys(args: argparse.Namespace) -> int:
    """Write a CURVE certificate pair per name."""
    from robosoa.transports import zmq_curve as curve

    for name in args.names:
        try:
            public, secret = curve.create(args.folder, name)
        except RobosoaError as exc:
            raise UsageError(str(exc)) from None
        print(f"{public}\n{secret}")
    return 0


def _health(bus: Bus, info: ServiceInfo, timeout: float) -> str:
    start = time.perf_counter()
    try:
        bus.channel(info.name, info.instance).request("_ping", {}, timeout=timeout)
    except RobosoaError as exc:
        return f"DOWN ({exc})"
    return f"ok {1000 * (time.perf_counter() - start):.1f}ms"


def cmd_services(args: argparse.Namespace) -> int:
    """List live services (``--health``: ping every instance)."""
    with _bus(args) as bus:
        infos = bus.services(args.name)
        health = {i.instance: _health(bus, i, 1.0) for i in infos} if args.health else {}
    if args.json:
        rows = [{**i.to_dict(), **({"health": health[i.instance]} if health else {})}
                for i in infos]
        print(json.dumps(rows, indent=2))
        return 0
    for info in infos:
        origin = f" via {info.origin}" if info.origin else ""
        group = f" group={info.group}" if info.group else ""
        status = f" {health[info.instance]}" if health else ""
        print(f"{info.name} {info.version} [{info.pattern}] {','.join(info.operations)} "
              f"{info.endpoint} {info.instance}{group}{origin}{status}")
    return 0


def cmd_call(args: argparse.Namespace) -> int:
    """Request/response from the command line; prints the reply as JSON."""
    payload = parse_pairs(args.pairs, args.json)
    with _bus(args) as bus:
        reply = bus.request(args.service, args.operation, payload, timeout=args.timeout,
                            version=args.version)
    print(json.dumps(reply, sort_keys=True))
    return 0


def cmd_publish(args: argparse.Namespace) -> int:
    """Publish a topic message (``--count`` times, ``--interval`` apart)."""
    payload = parse_pairs(args.pairs, args.json)
    with _bus(args) as bus:
        bus.advertise(args.topic)
        time.sleep(PUBLISH_SETTLE)
        for n in range(args.count):
            if n:
                time.sleep(args.interval)
            if args.event:
                bus.emit(args.topic, payload)
            else:
                bus.publish(args.topic, payload)
        time.sleep(0.1)  # let ZeroMQ flush before the socket closes
    return 0


def cmd_echo(args: argparse.Namespace) -> int:
    """Print each message of a topic as one JSON line."""
    with _bus(args) as bus:
        listen = bus.on if args.event else bus.subscribe
        with listen(args.topic) as sub:
            print(f"listening on {args.topic}", file=sys.stderr, flush=True)
            seen = 0
            deadline = None if args.timeout is None else time.monotonic() + args.timeout
            while args.count is None or seen < args.count:
                left = None if deadline is None else deadline - time.monotonic()
                if left is not None and left <= 0:
                    break
                msg = sub.get(timeout=min(left, 0.5) if left is not None else 0.5)
                if msg is not None:
                    seen += 1
                    print(json.dumps({"topic": msg.topic, "payload": msg.payload}), flush=True)
    return 0 if args.count is None or seen >= args.count else 1


def cmd_stats(args: argparse.Namespace) -> int:
    """Ask every provider instance for its counters and print them."""
    rows: list[dict[str, Any]] = []
    with _bus(args) as bus:
        infos = bus.services(args.name)
        if args.name is None:  # the location service's own counters come first, and the
            rows += _location_rows(bus, args.timeout)  # buses that only publish or listen
            infos += bus.services(BUS_ENTRY)
        for info in infos:
            try:
                reply = bus.channel(info.name, info.instance).request("_stats", {},
                                                                       timeout=args.timeout)
            except RobosoaError as exc:
                rows.append({"instance": info.instance, "error": str(exc)})
                continue
            rows += _figure_rows(info.instance, reply.get("figures"))
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    print(f"{'INSTANCE':40} {'ROLE':10} {'KEY':16} {'COUNT':>7} {'ERRORS':>6} {'DROPPED':>7} "
          f"{'P50_MS':>8} {'P99_MS':>8} WHY DROPPED")
    for row in rows:
        if "error" in row:
            print(f"{row['instance']:40} unreachable: {row['error']}")
            continue
        why = ",".join(f"{k}={v}" for k, v in sorted(row["drops"].items()))
        print(f"{row['instance']:40} {row['role']:10} {row['key']:16} {row['count']:7d} "
              f"{row['errors']:6d} {row['dropped']:7d} {row['p50_ms']:8.3f} {row['p99_ms']:8.3f}"
              f" {why}".rstrip())
    return 0


def _location_rows(bus: Bus, timeout: float) -> list[dict[str, Any]]:
    """Counters of the location service: requests answered, refused (``errors``)."""
    try:
        reply = bus.adapter.location({"op": "stats"}, timeout)
    except RobosoaError as exc:
        return [{"instance": "location", "error": str(exc)}]
    if "error" in reply:
        return [{"instance": "location", "error": str(reply["error"])[:200]}]
    return _figure_rows(f"location {str(reply.get('location', ''))[:80]}", reply.get("figures"))


_FIGURE_TYPES = {"key": (str,), "role": (str,), "count": (int,), "errors": (int,),
                 "dropped": (int,), "p50_ms": (int, float), "p99_ms": (int, float)}


def _drops(value: object) -> dict[str, int] | None:
    """A peer's drop counts by reason, if well-formed (a few short names, whole numbers)."""
    if value is None:
        return {}
    if not (isinstance(value, dict) and len(value) <= 32 and all(
            isinstance(k, str) and len(k) <= 40 and type(n) is int for k, n in value.items())):
        return None
    return dict(value)


def _figure_rows(instance: str, figures: object) -> list[dict[str, Any]]:
    """Rows of the figures a peer sent; a malformed answer becomes one error row."""
    rows: list[dict[str, Any]] = []
    for fig in figures if isinstance(figures, list) else [None]:
        drops = _drops(fig.get("drops")) if isinstance(fig, dict) else None
        if drops is None or not (isinstance(fig, dict) and all(
                type(fig.get(k)) in types for k, types in _FIGURE_TYPES.items())):
            return [{"instance": instance, "error": "malformed statistics"}]
        rows.append({"instance": instance, **{k: fig[k] for k in _FIGURE_TYPES},
                     "drops": drops})
    return rows


def cmd_route(args: argparse.Namespace) -> int:
    """Run a content-based router service from a rules file until SIGINT/SIGTERM."""
    from robosoa.router import Router

    router = Router.from_file(args.rules)
    with _bus(args) as bus, router.attach(bus, args.service):
        print(f"router {args.service} running with {len(router.rules)} rules", flush=True)
        stop = False

        def halt(*_: Any) -> None:
            nonlocal stop
            stop = True

        for sig in (signal.SIGINT, signal.SIGTERM):
            signal.signal(sig, halt)
        while not stop:
            time.sleep(0.1)
    return 0


def cmd_bridge(args: argparse.Namespace) -> int:
    """Join two buses until SIGINT/SIGTERM: services and topics of --source on --target."""
    from robosoa.bridge import Bridge

    stop = threading.Event()
    for sig in (signal.SIGINT, signal.SIGTERM):
        signal.signal(sig, lambda *_: stop.set())
    source_url = _checked_url("--source", args.source)
    target_url = _checked_url("--target", args.target)
    with connect(source_url) as source, connect(target_url) as target, \
            Bridge(source, target, args.service or (), args.topic or (), args.event or (),
                   both_ways=args.both_ways):
        print(f"bridge {args.source} -> {args.target} running", flush=True)
        stop.wait()
    return 0


def run_gen(words: list[str]) -> int:
    """Delegate ``gen ...`` / ``validate ...`` to ``robosoa.codegen.cli`` when it is installed
    (imported lazily: the bus tools work without it)."""
    try:
        codegen = import_module("robosoa.codegen.cli")
    except ModuleNotFoundError as exc:  # lxml: the runtime extra
        raise missing(exc, "code generation") or RobosoaError(
            f"code generation is not available: {exc}"
        ) from None
    except ImportError as exc:
        raise RobosoaError(f"code generation is not available: {exc}") from None
    run: Callable[[list[str]], int | None] = codegen.main
    return int(run(words) or 0)
