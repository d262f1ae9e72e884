"""Real processes for the robosoa tests: a location service and small provider scripts."""

from __future__ import annotations

import os
import queue
import socket
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

PYTHON = sys.executable
REPO = Path(__file__).resolve().parents[2]


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


def _env() -> dict[str, str]:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(REPO) + os.pathsep + env.get("PYTHONPATH", "")
    env.pop("ROBOSOA_LOCATION", None)
    return env


class Proc:
    """A child process whose stdout lines are read on a thread; killed for sure on stop."""

    def __init__(self, args: list[str]) -> None:
        self.args = args
        self.popen = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                      text=True, env=_env(), cwd=REPO)
        self.lines: queue.Queue[str] = queue.Queue()
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.popen.stdout is not None
        for line in self.popen.stdout:
            self.lines.put(line.rstrip("\n"))

    def wait_line(self, contains: str, timeout: float = 10.0) -> str:
        """The first stdout line containing ``contains``; fails with stderr after timeout."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                line = self.lines.get(timeout=0.1)
            except queue.Empty:
                if self.popen.poll() is not None:
                    break
                continue
            if contains in line:
                return line
        self.stop()
        err = self.popen.stderr.read() if self.popen.stderr else ""
        raise AssertionError(f"{self.args} did not print {contains!r}: {err[-2000:]}")

    def kill(self) -> None:
        """SIGKILL: the process gets no chance to unregister anything."""
        if self.popen.poll() is None:
            self.popen.kill()
        self.popen.wait(timeout=10)

    def stop(self) -> None:
        """SIGTERM, then SIGKILL if it does not exit within 5 s."""
        if self.popen.poll() is None:
            self.popen.terminate()
            try:
                self.popen.wait(timeout=5)
            except subprocess.TimeoutExpired:
                self.popen.kill()
                self.popen.wait(timeout=5)
        for stream in (self.popen.stdout, self.popen.stderr):
            if stream is not None:
                stream.close()


def start_location(bind: str, *extra: str) -> tuple[Proc, str]:
    """Run ``python -m robosoa location`` and return it with its bus URL."""
    proc = Proc([PYTHON, "-m", "robosoa", "location", "--bind", bind, *extra])
    proc.wait_line("robosoa location service on")
    return proc, f"zmq://{bind}"


def tcp_location(*extra: str) -> tuple[Proc, str]:
    """A location service on two free 127.0.0.1 ports (requests, announcements)."""
    ports = [free_port() for _ in range(2)]
    return start_location(f"tcp://127.0.0.1:{ports[0]}",
                          "--announce", f"tcp://127.0.0.1:{ports[1]}", *extra)


PROVIDER = textwrap.dedent('''
    import signal, sys, threading, robosoa
    url, name, version = sys.argv[1], sys.argv[2], sys.argv[3]
    group = sys.argv[4] if len(sys.argv) > 4 and sys.argv[4] else None
    bus = robosoa.connect(url, heartbeat=0.2, ttl=1.0)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    seen = []
    def handle(msg):
        if msg.operation == "seen":
            return {"seen": list(seen)}
        seen.append(msg.payload.get("n"))
        return {"pid": __import__("os").getpid(), "echo": msg.payload, "version": version}
    bus.provide(name, handle, version=version, operations=("echo", "note", "seen"),
                group=group)
    print("ready", flush=True)
    stop.wait()
    bus.close()
''')


def start_provider(url: str, name: str, version: str = "1.0.0", group: str = "") -> Proc:
    """A provider of ``name`` in its own process (operations echo, note, seen)."""
    proc = Proc([PYTHON, "-c", PROVIDER, url, name, version, group])
    proc.wait_line("ready")
    return proc


WORKER = textwrap.dedent('''
    import os, signal, sys, threading, time, robosoa
    url, name, role, idempotent, advertise = sys.argv[1:6]
    where = {"provider_bind": "tcp://127.0.0.1", "advertise_host": advertise} if advertise else {}
    bus = robosoa.connect(url, heartbeat=0.2, ttl=1.0, **where)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    def work(n):
        if role == "victim":
            print("busy", n, flush=True)
            stop.wait(60)
        return {"pid": os.getpid(), "n": n, "role": role}
    bus.provide(name, {"work": work}, idempotent=("work",) if idempotent == "yes" else ())
    print("ready", os.getpid(), flush=True)
    stop.wait()
    bus.close()
''')


def start_worker(url: str, name: str, role: str, idempotent: bool,
                 advertise: str = "") -> Proc:
    """A provider of ``name`` whose ``work`` hangs (role ``victim``: prints ``busy`` first)
    or answers at once (``spare``); ``work`` is registered idempotent or not. With
    ``advertise`` (e.g. 127.0.0.2) it binds 127.0.0.1 and registers that host instead, so
    consumers reach it only through a relay listening there."""
    proc = Proc([PYTHON, "-c", WORKER, url, name, role, "yes" if idempotent else "no",
                 advertise])
    proc.wait_line("ready")
    return proc


TICKER = textwrap.dedent('''
    import os, signal, sys, threading, robosoa
    url, topic, every, lifespan, advertise = sys.argv[1:6]
    where = {"provider_bind": "tcp://127.0.0.1", "advertise_host": advertise} if advertise else {}
    bus = robosoa.connect(url, heartbeat=0.2, ttl=1.0, **where)
    every = float(every)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    bus.advertise(topic, robosoa.QoS(lifespan=float(lifespan)))
    print("ready", os.getpid(), flush=True)
    n = 0
    while not stop.wait(every):
        n += 1
        bus.publish(topic, {"n": n, "pid": os.getpid()})
    bus.close()
''')


def start_ticker(url: str, topic: str, every: float = 0.02, lifespan: float = 0.0,
                 advertise: str = "") -> Proc:
    """A process publishing ``{"n": 1, 2, ...}`` on ``topic`` every ``every`` seconds, with
    that ``lifespan`` (0: none); ``advertise`` as for ``start_worker``."""
    proc = Proc([PYTHON, "-c", TICKER, url, topic, str(every), str(lifespan), advertise])
    proc.wait_line("ready")
    return proc


FLOODER = textwrap.dedent('''
    import os, signal, sys, threading, robosoa
    url, topic, count, size, go = sys.argv[1:6]
    count, size = int(count), int(size)
    bus = robosoa.connect(url, heartbeat=0.2, ttl=1.0)
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    bus.advertise(topic)
    print("ready", flush=True)
    while not os.path.exists(go) and not stop.wait(0.02):
        bus.publish(topic + "-probe", {})
    data = os.urandom(size)
    for n in range(count):
        bus.publish(topic, {"n": n, "data": data})
    print("sent", count, flush=True)
    stop.wait()
    bus.close()
''')


def start_flooder(url: str, topic: str, count: int, size: int, go: str) -> Proc:
    """A process that publishes probes on ``topic-probe`` until the file ``go`` exists, then
    ``count`` messages of ``size`` random bytes on ``topic`` as fast as it can."""
    proc = Proc([PYTHON, "-c", FLOODER, url, topic, str(count), str(size), go])
    proc.wait_line("ready")
    return proc
