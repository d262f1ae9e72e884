"""How much memory one multipart message from an unauthenticated peer makes a provider hold.

Starts a location service and a provider process (its options from the command line), sends
the provider ONE message of a JSON frame and ``--frames`` frames of ``--size`` bytes from a
raw DEALER on 127.0.0.1, waits until the provider's connection is cut (its `wire/inbox`
budget drop), it answers, or ``--seconds`` pass, and prints the provider's peak RSS (VmHWM)
before and after. Linux only (reads /proc).

Run:  .venv/bin/python benchmarks/multipart_memory.py [--frames 3000] [--size 1048576]
          [--max-message 1048576] [--inbox-size 1] [--hwm 1] [--seconds 120]
Not part of the tests (tests/robosoa/test_multipart_memory.py asserts the bound).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import textwrap
import time
from pathlib import Path

import zmq

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import robosoa  # noqa: E402
from tests.robosoa.procs import PYTHON, Proc, tcp_location  # noqa: E402

PROVIDER = textwrap.dedent('''
    import json, os, signal, sys, threading, robosoa
    bus = robosoa.connect(sys.argv[1], **json.loads(sys.argv[2]))
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    handle = bus.provide("victim", {"size": lambda d: {"n": len(d)}})
    print("ready", handle.endpoint, os.getpid(), flush=True)
    stop.wait()
    bus.close()
''')


def peak(pid: int) -> int:
    with open(f"/proc/{pid}/status") as status:
        return 1024 * int(next(ln for ln in status if ln.startswith("VmHWM:")).split()[1])


def cut(url: str) -> bool:
    """Whether the provider counted a connection cut for its budget (False while it is too
    busy to answer: its ZeroMQ thread may be decoding the flood)."""
    with robosoa.connect(url, location_timeout=5.0) as bus:
        for info in bus.services("victim"):
            try:
                figures = bus.channel("victim", info.instance).request("_stats", {}, 5.0)
            except robosoa.RobosoaError:
                return False
            for row in figures.get("figures", []):
                if row["role"] == "wire" and row["drops"].get("budget"):
                    return True
    return False


def run(args: argparse.Namespace) -> None:
    options = {"max_message": args.max_message, "inbox_size": args.inbox_size,
               "hwm": args.hwm}
    location, url = tcp_location()
    provider = Proc([PYTHON, "-c", PROVIDER, url, json.dumps(options)])
    try:
        _, endpoint, pid = provider.wait_line("ready").split()
        before = peak(int(pid))
        ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
        sock = ctx.socket(zmq.DEALER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.SNDHWM, 0)
        sock.connect(endpoint)
        data = b"x" * args.size
        head = {"kind": "request", "service": "victim", "operation": "size",
                "payload": {"d": None}, "blobs": [["d"]]}
        sock.send(json.dumps(head).encode(), zmq.SNDMORE)
        for n in range(args.frames):
            sock.send(data, zmq.SNDMORE if n < args.frames - 1 else 0, copy=False)
        start = time.monotonic()
        outcome = "nothing within the time"
        while time.monotonic() - start < args.seconds:
            if sock.poll(500):
                outcome = "answered"
                break
            if cut(url):
                outcome = "connection cut"
                break
        after = peak(int(pid))
        sock.close(0)
        ctx.term()
    finally:
        provider.stop()
        location.stop()
    print(f"machine: nproc={os.cpu_count()} load average {os.getloadavg()[0]:.1f}")
    print(f"command: {' '.join(sys.argv)}")
    print(f"one message of {args.frames:,} frames of {args.size:,} bytes, provider options "
          f"{options}: {outcome} after {time.monotonic() - start:.1f} s")
    print(f"provider peak RSS: {before / 1e6:.1f} MB before, {after / 1e6:.1f} MB after")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--frames", type=int, default=3000)
    parser.add_argument("--size", type=int, default=1024 * 1024, help="bytes per frame")
    parser.add_argument("--max-message", type=int, default=1024 * 1024)
    parser.add_argument("--inbox-size", type=int, default=1)
    parser.add_argument("--hwm", type=int, default=1)
    parser.add_argument("--seconds", type=float, default=120.0)
    run(parser.parse_args())


if __name__ == "__main__":
    main()
