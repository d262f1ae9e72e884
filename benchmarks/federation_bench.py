"""How long a location service takes to answer local lookups while slow federation peers
are being asked: the case of 32 peers added with `federate`, each answering every request
with 1,000 entries just inside its time budget, and a client keeping federated listings in
flight. Reports the latency of lookups of a name registered locally (p50, p99, max), how
long new buses take to connect, and the largest listing reply.

Run:  .venv/bin/python benchmarks/federation_bench.py [--peers 32] [--entries 1000]
          [--size 900] [--delay 0.2] [--depth 8] [--seconds 8] [--budget 0.5]
Not part of the tests (tests/robosoa/test_slow_federation.py asserts the bound).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import robosoa  # noqa: E402
from tests.robosoa.fakepeers import FakePeers, Listings, entries  # noqa: E402
from tests.robosoa.procs import tcp_location  # noqa: E402

FAST = {"heartbeat": 0.2, "ttl": 1.0, "lookup_cache": 0.2, "location_timeout": 10.0}


def pct(samples: list[float], fraction: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(fraction * (len(ordered) - 1)))]


def run(args: argparse.Namespace) -> None:
    def make(n: int) -> list[dict[str, object]]:
        return entries(args.entries, f"far-{n}", size=args.size)

    with FakePeers(args.peers, args.delay, make) as peers:
        flags = [a for address in peers.endpoints for a in ("--federate", address)]
        proc, url = tcp_location(*flags, "--federation-timeout", str(args.budget))
        flood = None
        lookups: list[float] = []
        starts: list[float] = []
        try:
            with robosoa.connect(url, **FAST) as near:
                near.provide("near", {"hi": lambda: {"hi": 1}})
                flood = Listings(url.removeprefix("zmq://"), args.depth)
                until = time.monotonic() + args.seconds
                while time.monotonic() < until:
                    start = time.monotonic()
                    near.adapter.location({"op": "lookup", "name": "near"}, 60.0)
                    lookups.append(time.monotonic() - start)
                    if len(lookups) % 5 == 0:
                        start = time.monotonic()
                        robosoa.connect(url, **FAST).close()
                        starts.append(time.monotonic() - start)
                    time.sleep(0.1)
                stats = near.adapter.location({"op": "stats"}, 60.0)["figures"][0]
        finally:
            if flood is not None:
                flood.stop()
            proc.stop()
    ms = [1000 * s for s in lookups]
    print(f"machine: nproc={os.cpu_count()} load average {os.getloadavg()[0]:.1f}")
    print(f"command: {' '.join(sys.argv)}")
    print(f"local lookups: {len(ms)}, p50 {statistics.median(ms):.1f} ms, "
          f"p99 {pct(ms, 0.99):.1f} ms, max {max(ms):.1f} ms")
    print(f"new buses: {len(starts)}, max {1000 * max(starts or [0]):.1f} ms")
    print(f"federated listings answered: {flood.answered if flood else 0}, "
          f"largest reply {flood.largest if flood else 0:,} bytes")
    print(f"location drops: {stats.get('drops')}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--peers", type=int, default=32)
    parser.add_argument("--entries", type=int, default=1000)
    parser.add_argument("--size", type=int, default=900, help="characters per entry")
    parser.add_argument("--delay", type=float, default=0.2, help="each peer's answer delay")
    parser.add_argument("--depth", type=int, default=8, help="federated listings in flight")
    parser.add_argument("--seconds", type=float, default=8.0)
    parser.add_argument("--budget", type=float, default=0.5, help="--federation-timeout")
    run(parser.parse_args())


if __name__ == "__main__":
    main()
