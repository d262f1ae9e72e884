"""The ``robosoa`` command line: argument parsing and error handling around ``commands``.

Exit status: 0 success, 1 runtime failure (service missing, timeout, remote error),
2 usage error. Errors are one line on stderr, never a traceback.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from typing import Any

from robosoa import commands, logs
from robosoa.cli_input import UsageError
from robosoa.errors import RobosoaError
from robosoa.extras import missing
from robosoa.location import Limits
from robosoa.wire import MAX_DEPTH, MAX_MESSAGE


def _location(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--location", help="location service, e.g. tcp://127.0.0.1:5555 "
                        "(default: $ROBOSOA_LOCATION or tcp://127.0.0.1:5555)")
    parser.add_argument("--connect-timeout", type=float, default=2.0, metavar="S",
                        help="seconds to wait for the location service (default 2)")
    _curve(parser)
    parser.add_argument("--curve-location", metavar="FILE", help="the location service's "
                        "public certificate (default $ROBOSOA_CURVE_LOCATION, else "
                        "location.key in the allow folder)")


def _curve(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--curve-secret", metavar="FILE", help="CURVE: this participant's "
                        "certificate, NAME.key_secret (default $ROBOSOA_CURVE_SECRET)")
    parser.add_argument("--curve-allow", metavar="DIR", help="CURVE: folder of the public "
                        "certificates allowed on the bus (default $ROBOSOA_CURVE_ALLOW)")


def _payload(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("pairs", nargs="*", metavar="key=value",
                        help="payload fields; values are parsed as JSON when possible")
    parser.add_argument("--json", metavar="PAYLOAD", help="payload as a JSON object")


def _location_limits(p: argparse.ArgumentParser) -> None:
    """What the location service accepts from peers (docs/security.md)."""
    limits = Limits()
    p.add_argument("--max-message", type=int, default=MAX_MESSAGE, metavar="BYTES",
                   help=f"largest frame taken from a peer (default {MAX_MESSAGE})")
    p.add_argument("--max-depth", type=int, default=MAX_DEPTH,
                   help=f"deepest JSON nesting taken from a peer (default {MAX_DEPTH})")
    p.add_argument("--max-ttl", type=float, default=limits.max_ttl, metavar="S",
                   help=f"longer TTLs are cut to this (default {limits.max_ttl:g})")
    p.add_argument("--max-entries", type=int, default=limits.max_entries,
                   help=f"registrations in total (default {limits.max_entries})")
    p.add_argument("--max-per-peer", type=int, default=limits.max_per_peer,
                   help=f"registrations from one host (default {limits.max_per_peer})")
    p.add_argument("--max-peers", type=int, default=limits.max_peers,
                   help=f"federated location services (default {limits.max_peers})")
    p.add_argument("--federation-timeout", type=float, default=limits.federation_timeout,
                   metavar="S", help="seconds one lookup waits for all federated services "
                   f"(default {limits.federation_timeout:g})")


def _server_commands(sub: Any) -> None:
    p = sub.add_parser("location", help="run a location service")
    p.add_argument("--bind", default="tcp://127.0.0.1:5555", help="location endpoint")
    p.add_argument("--announce", help="endpoint of announcements of new publishers "
                   "(default: port+1 or PATH.announce)")
    p.add_argument("--ttl", type=float, default=3.0, help="default entry TTL in seconds")
    p.add_argument("--federate", action="append", metavar="ENDPOINT",
                   help="also answer for services of this location service (repeatable)")
    p.add_argument("--accept-federate", action="store_true",
                   help="let clients add federation peers (anyone who can reach this "
                   "service; refused with CURVE)")
    _location_limits(p)
    _curve(p)
    p.set_defaults(run=commands.cmd_location)

    p = sub.add_parser("keys", help="make CURVE certificates (NAME.key, NAME.key_secret)")
    p.add_argument("folder", help="where to write them")
    p.add_argument("names", nargs="+", metavar="NAME", help="one certificate per name")
    p.set_defaults(run=commands.cmd_keys)

    p = sub.add_parser("route", help="run a content-based router from a rules file")
    p.add_argument("rules", help="rules file (.toml or .json)")
    p.add_argument("--service", default="router", help="service name of the router")
    _location(p)
    p.set_defaults(run=commands.cmd_route)

    p = sub.add_parser("bridge", help="join two buses (protocol bridge)")
    p.add_argument("--source", required=True, help="bus whose services/topics are offered")
    p.add_argument("--target", required=True, help="bus they are offered on")
    p.add_argument("--service", action="append", help="service to bridge (repeatable)")
    p.add_argument("--topic", action="append", help="topic to forward (repeatable)")
    p.add_argument("--event", action="append", help="event to forward (repeatable)")
    p.add_argument("--both-ways", action="store_true", help="forward topics/events back too")
    p.set_defaults(run=commands.cmd_bridge)

    sub.add_parser("gen", help="generate code from a service descriptor (robosoa gen --help)")
    sub.add_parser("validate", help="check a service descriptor (robosoa validate --help)")


def _inspect_commands(sub: Any) -> None:
    p = sub.add_parser("services", help="list live services")
    p.add_argument("--name", help="only this service")
    p.add_argument("--json", action="store_true", help="JSON output")
    p.add_argument("--health", action="store_true", help="ping every instance (_ping)")
    _location(p)
    p.set_defaults(run=commands.cmd_services)

    p = sub.add_parser("stats", help="counters and latencies of every provider instance")
    p.add_argument("--name", help="only this service")
    p.add_argument("--json", action="store_true", help="JSON output")
    p.add_argument("--timeout", type=float, default=2.0)
    _location(p)
    p.set_defaults(run=commands.cmd_stats)

    p = sub.add_parser("echo", help="print the messages of a topic as JSON lines")
    p.add_argument("topic")
    p.add_argument("--count", type=int, help="stop after N messages")
    p.add_argument("--timeout", type=float, help="stop after S seconds (exit 1 if short)")
    p.add_argument("--event", action="store_true", help="listen to an event instead")
    _location(p)
    p.set_defaults(run=commands.cmd_echo)


def _message_commands(sub: Any) -> None:
    p = sub.add_parser("call", help="request/response: print the reply as JSON")
    p.add_argument("service")
    p.add_argument("operation")
    _payload(p)
    p.add_argument("--timeout", type=float, default=5.0)
    p.add_argument("--version", help="version range, e.g. '>=1.0,<2'")
    _location(p)
    p.set_defaults(run=commands.cmd_call)

    p = sub.add_parser("publish", help="publish to a topic (or emit an event)")
    p.add_argument("topic")
    _payload(p)
    p.add_argument("--count", type=int, default=1)
    p.add_argument("--interval", type=float, default=0.1, metavar="S")
    p.add_argument("--event", action="store_true", help="emit a lightweight event instead")
    _location(p)
    p.set_defaults(run=commands.cmd_publish)


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of every subcommand."""
    parser = argparse.ArgumentParser(prog="robosoa", description="robosoa service bus tools")
    parser.add_argument("--log-level", default="WARNING", help="robosoa log level")
    parser.add_argument("--log-text", action="store_true", help="plain-text logs, not JSON")
    sub = parser.add_subparsers(dest="command", required=True)
    _server_commands(sub)
    _inspect_commands(sub)
    _message_commands(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``robosoa`` console script."""
    words = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser()
    if words[:1] in (["gen"], ["validate"]):  # the descriptor tools parse their own arguments
        return _guard(lambda: commands.run_gen(words))
    args = parser.parse_args(words)
    logs.configure(args.log_level, json_lines=not args.log_text)
    return _guard(lambda: int(args.run(args)))


def _guard(run: Callable[[], int]) -> int:
    """Run a command; user-facing failures become one line on stderr and an exit status."""
    try:
        return run()
    except ModuleNotFoundError as exc:  # pyzmq or lxml: the runtime extra
        said = missing(exc, "this command")
        if said is None:
            raise
        print(f"robosoa: error: {said}", file=sys.stderr)
        return 2
    except UsageError as exc:
        print(f"robosoa: error: {exc}", file=sys.stderr)
        return 2
    except (RobosoaError, OSError, ValueError) as exc:
        print(f"robosoa: error: {exc}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 130
