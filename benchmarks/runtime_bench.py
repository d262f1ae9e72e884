"""robosoa runtime benchmark, side by side with raw pyzmq doing the same work in one run.

Four scenarios, each measured in alternating rounds (raw, robosoa, raw, robosoa, ...) so that
the load of a shared machine hits both alike; the provider / publisher always runs in a
separate process, over tcp on 127.0.0.1:

* request/response, a JSON payload of four fields: raw REQ/REP with json vs bus.request;
  round-trip p50/p99 (goal: robosoa p50 within 1.5x of raw);
* request/response carrying 1 MB of bytes (reply: its length): raw REQ/REP sending a JSON
  frame and the bytes as a second frame vs bus.request({"data": bytes}); p50/p99, MB/s;
* publish/subscribe, the same small JSON payload, DEFAULT settings on both sides (queues of
  1000: nothing enlarged): raw PUB->SUB vs bus.publish/subscribe; msgs/s per round (median
  and worst), messages received, and the age of each message when its subscriber got it
  (p50/p99) (goal: robosoa >= 0.8x of raw);
* publish/subscribe of 1 MB messages: MB/s (goal for the 1 MB cases: >= 0.7x of raw).

Run:  .venv/bin/python benchmarks/runtime_bench.py [--rounds 5] [--requests 2000]
                                                   [--messages 20000] [--big 200]
Not part of the tests; prints Markdown tables for docs/runtime.md.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import os
import platform
import socket
import statistics
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import zmq

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

import robosoa  # noqa: E402

PAYLOAD = {"x": 1.0, "y": 2.0, "theta": 0.5, "frame": "map"}
MB = 1024 * 1024
Samples = list[float]


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def pct(samples: Samples, fraction: float) -> float:
    ordered = sorted(samples)
    return ordered[min(len(ordered) - 1, int(fraction * (len(ordered) - 1)))] if ordered else 0.0


# --- child processes --------------------------------------------------------------------
def raw_rep_server(endpoint: str, ready: Any, stop: Any) -> None:
    ctx = zmq.Context()
    rep = ctx.socket(zmq.REP)
    rep.bind(endpoint)
    ready.set()
    while not stop.is_set():
        if rep.poll(100):
            frames = rep.recv_multipart()
            request = json.loads(frames[0])
            if len(frames) > 1:  # the bytes frame: answer its length
                rep.send(json.dumps({"n": len(frames[1])}).encode())
            else:
                rep.send(json.dumps({"echo": request}).encode())
    rep.close(0)
    ctx.term()


def robosoa_provider(url: str, ready: Any, stop: Any) -> None:
    with robosoa.connect(url) as bus:
        bus.provide("bench", {"echo": lambda **kw: {"echo": kw},
                              "size": lambda data: {"n": len(data)}})
        ready.set()
        stop.wait()


def raw_publisher(endpoint: str, n: int, size: int, ready: Any, go: Any) -> None:
    ctx = zmq.Context()
    pub = ctx.socket(zmq.PUB)
    pub.bind(endpoint)
    ready.set()
    blob = os.urandom(size) if size else b""
    while not go.wait(0.02):
        pub.send_multipart([b"t:probe\0", b"{}"])
    for seq in range(n):
        head = json.dumps({**PAYLOAD, "seq": seq, "t": time.time()}).encode()
        pub.send_multipart([b"t:pose\0", head, blob] if size else [b"t:pose\0", head])
    time.sleep(1.0)
    pub.close(0)
    ctx.term()


def robosoa_publisher(url: str, n: int, size: int, ready: Any, go: Any) -> None:
    with robosoa.connect(url) as bus:
        bus.advertise("pose")
        ready.set()
        blob = os.urandom(size) if size else b""
        while not go.wait(0.02):
            bus.publish("probe", {})
        for seq in range(n):
            body = {**PAYLOAD, "seq": seq, "data": blob} if size else {**PAYLOAD, "seq": seq}
            bus.publish("pose", body)
        time.sleep(1.0)


def start(target: Callable[..., None], *args: Any) -> tuple[Any, Any]:
    spawn = mp.get_context("spawn")
    ready, flag = spawn.Event(), spawn.Event()
    proc = spawn.Process(target=target, args=(*args, ready, flag), daemon=True)
    proc.start()
    if not ready.wait(30):
        raise RuntimeError(f"{target.__name__} did not start")
    return proc, flag


# --- request/response -------------------------------------------------------------------
def reqrep(url: str, n: int, rounds: int, big: bool) -> dict[str, Samples]:
    """Round trips of raw REQ/REP and robosoa over tcp, in alternating rounds."""
    endpoint = f"tcp://127.0.0.1:{free_port()}"
    raw_proc, raw_stop = start(raw_rep_server, endpoint)
    our_proc, our_stop = start(robosoa_provider, url)
    ctx = zmq.Context()
    req = ctx.socket(zmq.REQ)
    req.connect(endpoint)
    blob = os.urandom(MB)
    header = json.dumps({"op": "size"}).encode()

    def raw_call() -> Any:
        if big:
            req.send_multipart([header, blob], copy=False)
        else:
            req.send(json.dumps(PAYLOAD).encode())
        return json.loads(req.recv())

    samples: dict[str, Samples] = {"raw": [], "robosoa": []}
    try:
        with robosoa.connect(url) as bus:
            bus.wait_for("bench")
            calls = {"raw": raw_call,
                     "robosoa": (lambda: bus.request("bench", "size", {"data": blob}))
                     if big else (lambda: bus.request("bench", "echo", PAYLOAD))}
            for call in calls.values():  # warm-up
                for _ in range(20 if big else 200):
                    call()
            for _ in range(rounds):
                for key, call in calls.items():
                    for _ in range(max(1, n // rounds)):
                        began = time.perf_counter()
                        call()
                        samples[key].append(time.perf_counter() - began)
    finally:
        raw_stop.set()
        our_stop.set()
        raw_proc.join(5)
        our_proc.join(5)
        req.close(0)
        ctx.term()
    return samples


# --- publish/subscribe ------------------------------------------------------------------
def _count(receive: Callable[[], float | None], n: int) -> tuple[float, int, Samples]:
    """Receive until n messages or 2 s of silence: (msgs/s, received, ages in s)."""
    got, first, last = 0, 0.0, 0.0
    ages: Samples = []
    while got < n:
        sent = receive()
        now = time.perf_counter()
        if sent is None:
            if (got and now - last > 2.0) or (not got and first and now - first > 20):
                break
            first = first or now
            continue
        ages.append(time.time() - sent)
        if got == 0:
            first = now
        got += 1
        last = now
    rate = (got - 1) / (last - first) if got > 1 and last > first else 0.0
    return rate, got, ages


def raw_pubsub(n: int, size: int) -> tuple[float, int, Samples]:
    ctx = zmq.Context()
    sub = ctx.socket(zmq.SUB)  # default high-water marks, as the publisher's
    sub.setsockopt(zmq.SUBSCRIBE, b"t:pose\0")
    sub.setsockopt(zmq.SUBSCRIBE, b"t:probe\0")
    endpoint = f"tcp://127.0.0.1:{free_port()}"
    proc, go = start(raw_publisher, endpoint, n, size)
    sub.connect(endpoint)
    while not (sub.poll(100) and sub.recv_multipart()[0] == b"t:probe\0"):
        pass
    go.set()

    def receive() -> float | None:
        while sub.poll(100):
            frames = sub.recv_multipart()
            if frames[0] == b"t:pose\0":
                return float(json.loads(frames[1])["t"])
        return None

    try:
        return _count(receive, n)
    finally:
        proc.join(10)
        sub.close(0)
        ctx.destroy(0)


def robosoa_pubsub(url: str, n: int, size: int) -> tuple[float, int, Samples]:
    with robosoa.connect(url) as bus:  # default settings: queue 1000, 64 MiB, hwm 1000
        sub = bus.subscribe("pose")
        probe = bus.subscribe("probe")
        proc, go = start(robosoa_publisher, url, n, size)
        while probe.get(timeout=0.1) is None:
            pass
        go.set()

        def receive() -> float | None:
            msg = sub.get(timeout=0.1)
            return None if msg is None else msg.timestamp

        try:
            return _count(receive, n)
        finally:
            proc.join(10)


def pubsub(url: str, n: int, rounds: int, size: int) -> dict[str, list[tuple[float, int, Samples]]]:
    results: dict[str, list[tuple[float, int, Samples]]] = {"raw": [], "robosoa": []}
    for _ in range(rounds):
        results["raw"].append(raw_pubsub(n, size))
        results["robosoa"].append(robosoa_pubsub(url, n, size))
    return results


# --- report -----------------------------------------------------------------------------
def report_reqrep(title: str, data: dict[str, Samples], unit: float, name: str) -> float:
    print(f"\n| {title} | p50 ({name}) | p99 ({name}) | calls |\n|---|---:|---:|---:|")
    for key, samples in data.items():
        print(f"| {key} | {pct(samples, 0.5) * unit:,.2f} | {pct(samples, 0.99) * unit:,.2f} "
              f"| {len(samples)} |")
    return pct(data["robosoa"], 0.5) / pct(data["raw"], 0.5)


def report_pubsub(title: str, data: dict[str, list[tuple[float, int, Samples]]], n: int,
                  scale: float, unit: str) -> float:
    print(f"\n| {title} | {unit} median | {unit} worst | received (least of {n}) | "
          "age p50 (ms) | age p99 (ms) |\n|---|---:|---:|---:|---:|---:|")
    medians = {}
    for key, runs in data.items():
        rates = [r * scale for r, _, _ in runs]
        ages = [a for _, _, run_ages in runs for a in run_ages]
        medians[key] = statistics.median(rates)
        print(f"| {key} | {medians[key]:,.1f} | {min(rates):,.1f} | "
              f"{min(g for _, g, _ in runs)} | {pct(ages, 0.5) * 1e3:.1f} | "
              f"{pct(ages, 0.99) * 1e3:.1f} |")
    return medians["robosoa"] / medians["raw"] if medians["raw"] else 0.0


def location() -> tuple[subprocess.Popen[str], str]:
    ports = [free_port() for _ in range(2)]
    proc = subprocess.Popen([sys.executable, "-m", "robosoa", "location", "--bind",
                             f"tcp://127.0.0.1:{ports[0]}", "--announce",
                             f"tcp://127.0.0.1:{ports[1]}"], stdout=subprocess.PIPE,
                            stderr=subprocess.DEVNULL, text=True, cwd=ROOT)
    assert proc.stdout is not None
    proc.stdout.readline()
    return proc, f"zmq://tcp://127.0.0.1:{ports[0]}"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--rounds", type=int, default=5, help="alternating rounds per scenario")
    parser.add_argument("--requests", type=int, default=2000, help="small round trips per side")
    parser.add_argument("--big-requests", type=int, default=200, help="1 MB round trips per side")
    parser.add_argument("--messages", type=int, default=20000, help="small messages per run")
    parser.add_argument("--big", type=int, default=200, help="1 MB messages per run")
    args = parser.parse_args()
    proc, url = location()
    try:
        small = reqrep(url, args.requests, args.rounds, big=False)
        large = reqrep(url, args.big_requests, args.rounds, big=True)
        flows = pubsub(url, args.messages, args.rounds, 0)
        big_flows = pubsub(url, args.big, args.rounds, MB)
    finally:
        proc.terminate()
        proc.wait(10)
    load = os.getloadavg()
    print(f"machine: nproc={os.cpu_count()} python={platform.python_version()} "
          f"pyzmq={zmq.__version__} libzmq={zmq.zmq_version()} {platform.machine()} "
          f"load average {load[0]:.1f} {load[1]:.1f} {load[2]:.1f}")
    print(f"command: .venv/bin/python benchmarks/runtime_bench.py --rounds {args.rounds} "
          f"--requests {args.requests} --big-requests {args.big_requests} "
          f"--messages {args.messages} --big {args.big}")
    ratios = {
        "request/response p50 (goal <= 1.5)": report_reqrep(
            "request/response, 4-field JSON", small, 1e6, "µs"),
        "1 MB request/response p50 (goal: time <= 1/0.7 = 1.43)": report_reqrep(
            "request/response, 1 MB of bytes", large, 1e3, "ms"),
        "pub/sub throughput (goal >= 0.8)": report_pubsub(
            "publish/subscribe, default settings", flows, args.messages, 1.0, "msgs/s"),
        "1 MB pub/sub throughput (goal >= 0.7)": report_pubsub(
            "publish/subscribe, 1 MB messages", big_flows, args.big, 1.0, "MB/s"),
    }
    print("\nrobosoa / raw pyzmq:")
    for label, ratio in ratios.items():
        print(f"  {label}: {ratio:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
