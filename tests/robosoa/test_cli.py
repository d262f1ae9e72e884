"""The real ``robosoa`` command in subprocesses, against a real location service."""

from __future__ import annotations

import json
import queue
import subprocess
from pathlib import Path

import pytest

import robosoa
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import PYTHON, REPO, Proc, _env, free_port, tcp_location
from tests.robosoa.util import eventually

pytestmark = [pytest.mark.timeout(90), pytest.mark.slow]


def run(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([PYTHON, "-m", "robosoa", *args], capture_output=True, text=True,
                          env=_env(), cwd=REPO, timeout=30)


def _loc(zmq_url: str) -> list[str]:
    return ["--location", zmq_url]


def test_services_call_and_stats(zmq_url: str, name: str) -> None:
    with robosoa.connect(zmq_url, **FAST) as bus:
        bus.provide(name, {"add": lambda a, b: {"sum": a + b}}, version="1.3.0", group="g")
        listed = run("services", "--name", name, *_loc(zmq_url))
        assert listed.returncode == 0, listed.stderr
        assert f"{name} 1.3.0 [request-response] add" in listed.stdout
        as_json = json.loads(run("services", "--json", "--name", name, *_loc(zmq_url)).stdout)
        assert [(s["name"], s["group"]) for s in as_json] == [(name, "g")]
        healthy = run("services", "--health", "--name", name, *_loc(zmq_url))
        assert healthy.returncode == 0 and " ok " in healthy.stdout
        called = run("call", name, "add", "a=2", "--json", '{"b": 40}', *_loc(zmq_url))
        assert (called.returncode, json.loads(called.stdout)) == (0, {"sum": 42})
        stats = run("stats", "--json", "--name", name, *_loc(zmq_url))
        rows = json.loads(stats.stdout)
        mine = [r for r in rows if r.get("key") == name and r.get("role") == "provider"]
        assert mine and mine[0]["count"] >= 1
        table = run("stats", "--name", name, *_loc(zmq_url))
        assert "P99_MS" in table.stdout and name in table.stdout


def test_errors_are_one_line_with_exit_codes(zmq_url: str, name: str) -> None:
    missing = run("call", name, "op", *_loc(zmq_url))
    assert missing.returncode == 1
    assert missing.stderr.strip().count("\n") == 0 and name in missing.stderr
    assert "Traceback" not in missing.stderr
    bad_pair = run("call", name, "op", "novalue", *_loc(zmq_url))
    assert (bad_pair.returncode, "key=value" in bad_pair.stderr) == (2, True)
    bad_json = run("call", name, "op", "--json", "{", *_loc(zmq_url))
    assert bad_json.returncode == 2 and "--json" in bad_json.stderr
    assert run("frobnicate").returncode == 2
    dead = run("services", "--location", f"tcp://127.0.0.1:{free_port()}",
               "--connect-timeout", "0.3")
    assert dead.returncode == 1 and "location service" in dead.stderr
    assert "Traceback" not in dead.stderr
    gen = run("gen", "--help")
    assert "Traceback" not in gen.stderr


def test_publish_and_echo(zmq_url: str, name: str) -> None:
    with robosoa.connect(zmq_url, **FAST) as bus:
        got: list[robosoa.Message] = []
        bus.subscribe(name, got.append)
        published = run("publish", name, "x=1", "label=hi", "--count", "3", "--interval",
                        "0.05", *_loc(zmq_url))
        assert published.returncode == 0, published.stderr
        eventually(lambda: got)
        assert got[0].payload == {"x": 1, "label": "hi"}

        echo = Proc([PYTHON, "-m", "robosoa", "echo", name + "-e", "--count", "2",
                     "--timeout", "20", *_loc(zmq_url)])
        try:
            def step() -> str | None:
                bus.publish(name + "-e", {"n": 5})
                try:
                    return echo.lines.get(timeout=0.05)
                except queue.Empty:
                    return None

            line = eventually(step, timeout=15)
            assert json.loads(line) == {"topic": name + "-e", "payload": {"n": 5}}
            eventually(lambda: bus.publish(name + "-e", {"n": 5}) or echo.popen.poll() == 0)
        finally:
            echo.stop()


def test_route_command_runs_a_router(zmq_url: str, name: str, tmp_path: Path) -> None:
    rules = tmp_path / "rules.json"
    rules.write_text(json.dumps({"rules": [{"operation": "ping", "to": [
        {"kind": "request", "service": name + "-target", "operation": "pong",
         "fields": {"v": "v + 1"}}]}]}), encoding="utf-8")
    router = Proc([PYTHON, "-m", "robosoa", "route", str(rules), "--service", name,
                   *_loc(zmq_url)])
    try:
        router.wait_line("router")
        with robosoa.connect(zmq_url, **FAST) as bus:
            bus.provide(name + "-target", {"pong": lambda v: {"v": v}})
            bus.wait_for(name)
            reply = bus.request(name, "ping", {"v": 1})
            assert reply["routed"][0]["reply"] == {"v": 2}
    finally:
        router.stop()
    assert router.popen.returncode == 0


def test_bridge_command_joins_two_location_services(zmq_url: str, name: str) -> None:
    other, other_url = tcp_location()
    bridge: Proc | None = None
    try:
        with robosoa.connect(zmq_url, **FAST) as here, robosoa.connect(other_url, **FAST) as there:
            here.provide(name, {"hi": lambda who: {"hello": who}})
            bridge = Proc([PYTHON, "-m", "robosoa", "bridge", "--source", zmq_url,
                           "--target", other_url, "--service", name, "--topic", name + "-t"])
            bridge.wait_line("bridge")
            there.wait_for(name)
            assert there.request(name, "hi", {"who": "b"}) == {"hello": "b"}
            got: list[robosoa.Message] = []
            there.subscribe(name + "-t", got.append)
            eventually(lambda: here.publish(name + "-t", {"x": 1}) or got)
    finally:
        if bridge is not None:
            bridge.stop()
        other.stop()
    assert bridge is not None and bridge.popen.returncode == 0
