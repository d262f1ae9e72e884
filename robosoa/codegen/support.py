"""Runtime helpers imported by generated code: wire conversion, executables, platform, main.

Generated modules stay short and readable by delegating the generic parts here, the way the
thesis' generated CallProxy/MessagingProxy lean on ServiceUtilities (p. 87).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import shlex
import signal
import subprocess
import sys
import threading
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import robosoa
from robosoa.codegen import textual, xmlcodec
from robosoa.descriptor import Encoding, ServiceDescriptor
from robosoa.errors import InvalidMessage
from robosoa.wire import LimitExceeded, load_json, load_object

_PLATFORMS = {
    "linux": ("linux",),
    "macos": ("darwin",),
    "windows": ("win32", "cygwin"),
    "posix": ("linux", "darwin", "freebsd", "openbsd", "netbsd", "sunos", "aix"),
}


def to_wire(value: object) -> Any:
    """Typed value -> JSON-like wire value: dataclasses become dicts (None fields left out)."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return payload_of(value)
    if isinstance(value, list | tuple):
        return [to_wire(item) for item in value]
    if isinstance(value, Mapping):
        return {str(k): to_wire(v) for k, v in value.items() if v is not None}
    return value


def payload_of(value: object) -> dict[str, Any]:
    """The wire payload (a dict) of a dataclass instance or a mapping of typed values."""
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        fields = {f.name: getattr(value, f.name) for f in dataclasses.fields(value)}
        return {k: to_wire(v) for k, v in fields.items() if v is not None}
    if isinstance(value, Mapping):
        return {str(k): to_wire(v) for k, v in value.items() if v is not None}
    raise TypeError(f"expected a dataclass or a mapping, got {type(value).__name__}")


def check_platform(required: str) -> None:
    """Refuse to run generated code outside the descriptor's operating system."""
    if required != "any" and not sys.platform.startswith(_PLATFORMS[required]):
        raise RuntimeError(f"generated for {required}, running on {sys.platform}")


class ExecutableRunner:
    """Runs a provider program per request: request on stdin, result on stdout (p. 94)."""

    def __init__(
        self, descriptor: ServiceDescriptor, encoding: str, timeout: float, cwd: str | None
    ) -> None:
        self._descriptor = descriptor
        self._encoding = Encoding(encoding)
        self._timeout = timeout
        self._cwd = cwd

    def run(self, operation: str, command: str, payload: Mapping[str, Any]) -> dict[str, Any]:
        """Run ``command`` for one request of ``operation``; return the reply payload."""
        argv = shlex.split(command)
        env = {**os.environ, "ROBOSOA_SERVICE": self._descriptor.name}
        env["ROBOSOA_OPERATION"] = operation
        done = subprocess.run(
            argv,
            input=self._encode(operation, payload),
            capture_output=True,
            timeout=self._timeout,
            cwd=self._cwd,
            env=env,
            check=False,
        )
        if done.returncode != 0:
            last = (done.stderr.decode(errors="replace").strip().splitlines() or [""])[-1]
            raise RuntimeError(f"{argv[0]} exited with status {done.returncode}: {last}")
        return self._decode(operation, done.stdout)

    def _encode(self, operation: str, payload: Mapping[str, Any]) -> bytes:
        if self._encoding is Encoding.TEXT:
            return str(next(iter(payload.values()), "")).encode()
        if self._encoding is Encoding.XML:
            return xmlcodec.encode_request(self._descriptor.name, operation, payload)
        return json.dumps(dict(payload), default=textual.to_text).encode()

    def _decode(self, operation: str, output: bytes) -> dict[str, Any]:
        op = self._descriptor.operation(operation)
        returns = op.returns if op is not None else ()
        if not returns:
            return {}
        if self._encoding is Encoding.TEXT:
            return {returns[0].name: output.decode()}
        if self._encoding is Encoding.XML:
            return xmlcodec.decode_result(self._descriptor, returns, output)
        try:
            return textual.fields_from_text(self._descriptor, returns,
                                            load_object(output or b"{}"))
        except (InvalidMessage, ValueError) as exc:
            why = f"{operation}: the program must print a JSON object ({exc})"
            raise RuntimeError(why) from None


def serve_main(
    argv: Sequence[str] | None,
    description: str,
    start: Callable[[robosoa.Bus, argparse.Namespace], object],
    add_arguments: Callable[[argparse.ArgumentParser], None] | None = None,
) -> int:
    """Entry point of a generated provider: connect, ``start(bus, args)``, wait for a signal."""
    parser = argparse.ArgumentParser(description=description)
    parser.add_argument("--bus", default=os.environ.get("ROBOSOA_BUS", "inproc"), help="bus URL")
    if add_arguments is not None:
        add_arguments(parser)
    args = parser.parse_args(argv)
    stop = threading.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        signal.signal(signum, lambda *_: stop.set())
    bus = robosoa.connect(args.bus)
    try:
        start(bus, args)
        print(f"serving on {args.bus}; Ctrl-C to stop", file=sys.stderr, flush=True)
        stop.wait()
    finally:
        bus.close()
    return 0


def _argument(descriptor: ServiceDescriptor, operation: str, item: str) -> tuple[str, Any]:
    name, sep, text = item.partition("=")
    if not sep:
        raise ValueError(f"argument {item!r}: expected name=value")
    op = descriptor.operation(operation)
    declared = next((p for p in op.parameters if p.name == name), None) if op else None
    if declared is not None and declared.type.name == "string":
        return name, text
    if declared is not None and declared.type.name == "bytes":
        return name, textual.from_base64(text, name)
    try:
        return name, load_json(text)
    except LimitExceeded as exc:
        raise ValueError(f"argument {name!r}: {exc}") from None
    except InvalidMessage:
        return name, text


def client_main(
    argv: Sequence[str] | None, descriptor: ServiceDescriptor, proxy: Callable[..., object]
) -> int:
    """Entry point of a generated consumer: call ``OPERATION name=value...``, print the JSON."""
    parser = argparse.ArgumentParser(description=f"Call service {descriptor.name!r}.")
    parser.add_argument("--bus", default=os.environ.get("ROBOSOA_BUS", "inproc"), help="bus URL")
    parser.add_argument("--timeout", type=float, default=5.0, help="seconds to wait for a reply")
    parser.add_argument("operation", choices=[op.name for op in descriptor.operations])
    parser.add_argument("arguments", nargs="*", metavar="name=value")
    args = parser.parse_args(argv)
    try:
        kwargs = dict(_argument(descriptor, args.operation, a) for a in args.arguments)
    except ValueError as exc:
        parser.error(str(exc))
    bus = robosoa.connect(args.bus)
    try:
        result = getattr(proxy(bus, timeout=args.timeout), args.operation)(**kwargs)
    except (robosoa.RobosoaError, TypeError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    finally:
        bus.close()
    print(json.dumps(to_wire(result), default=textual.to_text))
    return 0
