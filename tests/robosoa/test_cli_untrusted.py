"""Bad command-line input: one line on stderr, exit status 2, no traceback, nothing bound."""

from __future__ import annotations

import socket
import subprocess
from pathlib import Path

import pytest

from tests.robosoa.procs import free_port
from tests.robosoa.test_cli import run

pytestmark = [pytest.mark.timeout(120), pytest.mark.slow]


def refused(done: subprocess.CompletedProcess[str], *words: str) -> None:
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and done.stderr.startswith("robosoa: error: ")
    assert "Traceback" not in done.stderr and done.stdout == ""
    for word in words:
        assert word in done.stderr


@pytest.mark.parametrize(("bind", "why"), [
    ("tcp://256.1.1.1:5", "'256.1.1.1' is not an IP address"),
    ("tcp://127.0.0.1:99999", "port '99999' is not 0-65535"),
    ("tcp://127.0.0.1:-1", "port '-1'"),
    ("tcp://:5555", "'' is not an IP address"),
    ("udp://127.0.0.1:5", "expected tcp://HOST:PORT"),
])
def test_location_refuses_bad_bind_endpoints(bind: str, why: str) -> None:
    refused(run("location", "--bind", bind), "--bind", why)


def test_location_refuses_a_missing_ipc_folder(tmp_path: Path) -> None:
    missing = tmp_path / "no" / "such" / "dir"
    refused(run("location", "--bind", f"ipc://{missing}/loc"), f"folder '{missing}'")
    assert not (tmp_path / "no").exists()


def test_location_refuses_a_port_in_use() -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        refused(run("location", "--bind", f"tcp://127.0.0.1:{port}",
                    "--announce", f"tcp://127.0.0.1:{free_port()}"), "cannot bind")
        refused(run("location", "--bind", f"tcp://127.0.0.1:{free_port()}",
                    "--announce", f"tcp://127.0.0.1:{port}"), "cannot bind")


@pytest.mark.parametrize(("flag", "value"), [
    ("--ttl", "nan"), ("--ttl", "-1"), ("--max-ttl", "inf"), ("--announce", "tcp://x:99999"),
    ("--max-message", "-5"), ("--max-entries", "0"), ("--federation-timeout", "nan"),
    ("--federate", "tcp://999.0.0.1:1"),
])
def test_location_refuses_bad_limits(flag: str, value: str) -> None:
    refused(run("location", "--bind", f"tcp://127.0.0.1:{free_port()}", flag, value), flag)


def test_call_refuses_deep_json_and_empty_values() -> None:
    deep = "[" * 10_000 + "]" * 10_000
    loc = ["--location", f"tcp://127.0.0.1:{free_port()}", "--connect-timeout", "0.3"]
    refused(run("call", "svc", "op", "--json", '{"a": ' + deep + "}", *loc), "--json",
            "nested deeper")
    refused(run("call", "svc", "op", f"a={deep}", *loc), "a: ", "nested deeper")
    refused(run("call", "svc", "op", "a=", *loc), "'a='")
    refused(run("call", "svc", "op", "=1", *loc), "'=1'")
    refused(run("publish", "topic", "--json", "NaN", *loc), "--json")
    refused(run("services", "--location", "tcp://127.0.0.1:99999"), "--location")
    refused(run("bridge", "--source", "tcp://1.2.3.256:5", "--target", "inproc"), "--source")
