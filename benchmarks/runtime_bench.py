"""robosoa runtime benchmark: round-trip latency and pub/sub throughput, side by side with raw
pyzmq doing the same work (JSON payloads, provider / publisher in a separate process).

Run:  .venv/bin/python benchmarks/runtime_bench.py [--requests 3000] [--messages 30000]
Not part of the tests; prints a Markdown table for docs/runtime.md.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import multiprocessing as mp
import os
import platform
import socket
import statistics
import subprocess
import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import zmq

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import robosoa  # noqa: E402

PAYLOAD = {"x": 1.0, "y": 2.0, "theta": 0.5, "frame": "map"}
BIG = {"hwm": 200_000, "queue_size": 200_000}


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def percentiles(samples: list[float]) -> tuple[float, float]:
    ordered = sorted(samples)
    return (statistics.median(ordered) * 1e6, ordered[int(0.99 * (len(ordered) - 1))] * 1e6)


def time_calls(call: Callable[[], Any], n: int) -> tuple[float, float]:
    for _ in range(min(200, n)):
        call()
    samples = []
    for _ in range(n):
        start = time.perf_counter()
        call()
        samples.append(time.perf_counter() - start)
    return percentiles(samples)


# --- child processes ------------------------------------------------------------------
def raw_rep_server(endpoint: str, ready: Any, stop: Any) -> None:
    ctx = zmq.Context()
    rep = ctx.socket(zmq.REP)
    rep.bind(endpoint)
    ready.set()
    while not stop.is_set():
        if rep.poll(100):
            request = json.loads(rep.recv())
            rep.send(json.dumps({"echo": request}).encode())
    rep.close(0)
    ctx.term()


def robosoa_provider(url: str, ready: Any, stop: Any) -> None:
    with robosoa.connect(url) as bus:
        bus.provide("bench", {"echo": lambda **kw: {"echo": kw}})
        ready.set()
        stop.wait()


def robosoa_publisher(url: str, n: int, ready: Any, go: Any) -> None:
    with robosoa.connect(url, **BIG) as bus:
        ready.set()
        go.wait()
        for seq in range(n):
            bus.publish("pose", {**PAYLOAD, "seq": seq})
        time.sleep(1.0)


def start(target: Callable[..., None], *args: Any) -> tuple[Any, Any, Any]:
    spawn = mp.get_context("spawn")
    ready, flag = spawn.Event(), spawn.Event()
    proc = spawn.Process(target=target, args=(*args, ready, flag), daemon=True)
    proc.start()
    if not ready.wait(30):
        raise RuntimeError(f"{target.__name__} did not start")
    return proc, flag, ready


# --- measurements --------------------------------------------------------------------
def bench_reqrep(url: str, n: int, rounds: int = 10) -> dict[str, tuple[float, float]]:
    """Raw REQ/REP and robosoa over tcp, measured in alternating rounds so that the load of
    a shared machine hits both alike."""
    endpoint = f"tcp://127.0.0.1:{free_port()}"
    raw_proc, raw_stop, _ = start(raw_rep_server, endpoint)
    our_proc, our_stop, _ = start(robosoa_provider, url)
    ctx = zmq.Context()
    req = ctx.socket(zmq.REQ)
    req.connect(endpoint)

    def raw_call() -> Any:
        req.send(json.dumps(PAYLOAD).encode())
        return json.loads(req.recv())

    samples: dict[str, list[float]] = {"raw": [], "robosoa": []}
    try:
        with robosoa.connect(url) as bus:
            bus.wait_for("bench")
            calls = {"raw": raw_call, "robosoa": lambda: bus.request("bench", "echo", PAYLOAD)}
            for call in calls.values():
                for _ in range(200):
                    call()
            for _ in range(rounds):
                for key, call in calls.items():
                    for _ in range(max(1, n // rounds)):
                        start_at = time.perf_counter()
                        call()
                        samples[key].append(time.perf_counter() - start_at)
    finally:
        raw_stop.set()
        our_stop.set()
        raw_proc.join(5)
        our_proc.join(5)
        req.close(0)
        ctx.term()
    return {key: percentiles(values) for key, values in samples.items()}


def bench_inproc_reqrep(n: int) -> tuple[float, float]:
    with robosoa.connect("inproc://bench") as provider, robosoa.connect("inproc://bench") as bus:
        provider.provide("bench", {"echo": lambda **kw: {"echo": kw}})
        return time_calls(lambda: bus.request("bench", "echo", PAYLOAD), n)


def _count(receive: Callable[[], bool], n: int) -> tuple[float, int]:
    """Receive until n messages or 2 s of silence; returns (msgs/s, received)."""
    got, first, last = 0, 0.0, 0.0
    while got < n:
        if not receive():
            if got and time.perf_counter() - last > 2.0:
                break
            if not got and first and time.perf_counter() - first > 20:
                break
            continue
        now = time.perf_counter()
        if got == 0:
            first = now
        got += 1
        last = now
    rate = (got - 1) / (last - first) if got > 1 and last > first else 0.0
    return rate, got


def bench_raw_pubsub(n: int, through_proxy: bool) -> tuple[float, int]:
    ctx = zmq.Context()
    sub = ctx.socket(zmq.SUB)
    sub.setsockopt(zmq.RCVHWM, BIG["hwm"])
    sub.setsockopt(zmq.SUBSCRIBE, b"t:pose\0")
    proxy_thread = None
    if through_proxy:
        xsub, xpub = ctx.socket(zmq.XSUB), ctx.socket(zmq.XPUB)
        for sock in (xsub, xpub):
            sock.setsockopt(zmq.SNDHWM, BIG["hwm"])
            sock.setsockopt(zmq.RCVHWM, BIG["hwm"])
        pub_port = xsub.bind_to_random_port("tcp://127.0.0.1")
        sub_port = xpub.bind_to_random_port("tcp://127.0.0.1")
        proxy_thread = threading.Thread(target=_proxy, args=(xsub, xpub), daemon=True)
        proxy_thread.start()
        sub.connect(f"tcp://127.0.0.1:{sub_port}")
        pub_endpoint = f"tcp://127.0.0.1:{pub_port}"
    else:
        port = sub.bind_to_random_port("tcp://127.0.0.1")
        pub_endpoint = f"tcp://127.0.0.1:{port}"
    proc, go, _ = start(_raw_pub_connect, pub_endpoint, n)
    time.sleep(0.5)  # slow-joiner: let the subscription reach the publisher
    go.set()

    def receive() -> bool:
        if not sub.poll(100):
            return False
        json.loads(sub.recv_multipart()[1])
        return True

    try:
        return _count(receive, n)
    finally:
        proc.join(10)
        sub.close(0)
        ctx.destroy(0)


def _proxy(xsub: zmq.Socket[bytes], xpub: zmq.Socket[bytes]) -> None:
    with contextlib.suppress(zmq.ZMQError):  # ends when the context is destroyed
        zmq.proxy(xsub, xpub)


def _raw_pub_connect(endpoint: str, n: int, ready: Any, go: Any) -> None:
    ctx = zmq.Context()
    pub = ctx.socket(zmq.PUB)
    pub.setsockopt(zmq.SNDHWM, BIG["hwm"])
    pub.connect(endpoint)
    ready.set()
    go.wait()
    for seq in range(n):
        pub.send_multipart([b"t:pose\0", json.dumps({**PAYLOAD, "seq": seq}).encode()])
    time.sleep(1.0)
    pub.close(0)
    ctx.term()


def bench_robosoa_pubsub(url: str, n: int) -> tuple[float, int]:
    with robosoa.connect(url, **BIG) as bus:
        sub = bus.subscribe("pose")
        proc, go, _ = start(robosoa_publisher, url, n)
        time.sleep(0.5)
        go.set()
        try:
            return _count(lambda: sub.get(timeout=0.1) is not None, n)
        finally:
            proc.join(10)


def bench_inproc_pubsub(n: int) -> tuple[float, int]:
    with (
        robosoa.connect("inproc://bench-ps", **BIG) as a,
        robosoa.connect("inproc://bench-ps", **BIG) as b,
    ):
        sub = b.subscribe("pose")

        def publish() -> None:
            for seq in range(n):
                a.publish("pose", {**PAYLOAD, "seq": seq})

        thread = threading.Thread(target=publish)
        thread.start()
        result = _count(lambda: sub.get(timeout=0.1) is not None, n)
        thread.join()
        return result


def pubsub_rounds(url: str, n: int, rounds: int) -> list[tuple[str, tuple[float, int]]]:
    """Each pub/sub variant ``rounds`` times, alternating; the median rate, the least received."""
    variants: dict[str, Callable[[], tuple[float, int]]] = {
        "raw pyzmq PUB->SUB tcp": lambda: bench_raw_pubsub(n, False),
        "raw pyzmq PUB->XSUB/XPUB->SUB tcp": lambda: bench_raw_pubsub(n, True),
        "robosoa zmq publish/subscribe": lambda: bench_robosoa_pubsub(url, n),
        "robosoa inproc publish/subscribe": lambda: bench_inproc_pubsub(n),
    }
    results: dict[str, list[tuple[float, int]]] = {label: [] for label in variants}
    for _ in range(rounds):
        for label, run in variants.items():
            results[label].append(run())
    return [(label, (statistics.median(r for r, _ in got), min(g for _, g in got)))
            for label, got in results.items()]


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--requests", type=int, default=3000)
    parser.add_argument("--messages", type=int, default=30000)
    parser.add_argument("--rounds", type=int, default=3, help="pub/sub repetitions (median)")
    args = parser.parse_args()
    ports = [free_port() for _ in range(3)]
    location = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "robosoa",
            "location",
            "--bind",
            f"tcp://127.0.0.1:{ports[0]}",
            "--xsub",
            f"tcp://127.0.0.1:{ports[1]}",
            "--xpub",
            f"tcp://127.0.0.1:{ports[2]}",
            "--hwm",
            str(BIG["hwm"]),
        ],
        stdout=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    assert location.stdout is not None
    location.stdout.readline()
    url = f"zmq://tcp://127.0.0.1:{ports[0]}"
    try:
        tcp = bench_reqrep(url, args.requests)
        rows = [
            ("raw pyzmq REQ/REP tcp", tcp["raw"]),
            ("robosoa zmq tcp request", tcp["robosoa"]),
            ("robosoa inproc request", bench_inproc_reqrep(args.requests)),
        ]
        flows = pubsub_rounds(url, args.messages, args.rounds)
    finally:
        location.terminate()
        location.wait(10)
    print(
        f"machine: nproc={os.cpu_count()} python={platform.python_version()} "
        f"pyzmq={zmq.__version__} libzmq={zmq.zmq_version()} {platform.machine()}"
    )
    print(
        f"command: .venv/bin/python benchmarks/runtime_bench.py --requests {args.requests} "
        f"--messages {args.messages} --rounds {args.rounds}\n"
    )
    print("| request/response round trip | p50 (µs) | p99 (µs) |\n|---|---:|---:|")
    for label, (p50, p99) in rows:
        print(f"| {label} | {p50:.0f} | {p99:.0f} |")
    print(f"\n| publish/subscribe ({args.messages} msgs, median of {args.rounds}) | msgs/s | "
          "received (least) |\n|---|---:|---:|")
    for label, (rate, got) in flows:
        print(f"| {label} | {rate:,.0f} | {got} |")
    raw50, ours50 = rows[0][1][0], rows[1][1][0]
    print(f"\nzmq round-trip p50 ratio robosoa/raw: {ours50 / raw50:.2f} (goal <= 2)")
    print(
        f"pub/sub throughput ratio robosoa/raw direct: {flows[2][1][0] / flows[0][1][0]:.2f} "
        f"(goal >= 0.5)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
