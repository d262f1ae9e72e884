"""Authentication and encryption with CurveZMQ: only the keys of the allow folder can
register, call, publish or listen; what crosses the wire cannot be read (bytes captured by a
relay on 127.0.0.2 carry a plaintext marker without CURVE and not with it)."""

from __future__ import annotations

import shutil
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest
import zmq

import robosoa
from tests.robosoa.conftest import FAST
from tests.robosoa.procs import free_port, start_location
from tests.robosoa.relay import Relay
from tests.robosoa.test_cli import run
from tests.robosoa.util import eventually

pytestmark = [pytest.mark.timeout(120), pytest.mark.slow]

MARKER = "PLAINTEXT-MARKER-8d1c4e"


@pytest.fixture(scope="module")
def keys(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Certificates made by ``robosoa keys``; alice, bob and the location are allowed."""
    folder = tmp_path_factory.mktemp("keys")
    done = run("keys", str(folder), "location", "alice", "bob", "mallory")
    assert done.returncode == 0, done.stderr
    allow = folder / "allow"
    allow.mkdir()
    for name in ("location", "alice", "bob"):
        shutil.copy(folder / f"{name}.key", allow)
    return folder


@pytest.fixture(scope="module")
def secured(keys: Path) -> Iterator[str]:
    """A location service that admits the allowed keys only."""
    proc, url = start_location(f"tcp://127.0.0.1:{free_port()}",
                               "--announce", f"tcp://127.0.0.1:{free_port()}",
                               "--curve-secret", str(keys / "location.key_secret"),
                               "--curve-allow", str(keys / "allow"))
    yield url
    proc.stop()


def _as(keys: Path, name: str, **more: object) -> dict[str, object]:
    return {**FAST, "curve_secret": str(keys / f"{name}.key_secret"),
            "curve_allow": str(keys / "allow"), **more}


def test_allowed_keys_call_publish_and_listen(keys: Path, secured: str) -> None:
    name = f"svc-{uuid.uuid4().hex[:8]}"
    with robosoa.connect(secured, **_as(keys, "alice")) as alice, \
            robosoa.connect(secured, **_as(keys, "bob")) as bob:
        alice.provide(name, {"hello": lambda who: {"hi": who, "blob": b"\x00\xff"}})
        [info] = bob.wait_for(name)
        assert len(info.key) == 40
        assert bob.request(name, "hello", {"who": "bob"}) == {"hi": "bob", "blob": b"\x00\xff"}
        got: list[robosoa.Message] = []
        bob.subscribe(name, got.append)
        eventually(lambda: alice.publish(name, {"n": 1}) or got, timeout=20)


def test_an_unknown_key_is_refused_everywhere(keys: Path, secured: str) -> None:
    name = f"svc-{uuid.uuid4().hex[:8]}"
    with pytest.raises(robosoa.RobosoaError, match="location service"):
        robosoa.connect(secured, **_as(keys, "mallory", location_timeout=1.0))
    with pytest.raises(robosoa.RobosoaError, match="location service"):
        robosoa.connect(secured, **{**FAST, "location_timeout": 1.0})  # no CURVE at all
    with robosoa.connect(secured, **_as(keys, "alice")) as alice:
        handle = alice.provide(name, {"hello": lambda: {"hi": 1}})
        ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context()
        mallory = ctx.socket(zmq.DEALER)
        public, secret = zmq.auth.load_certificate(str(keys / "mallory.key_secret"))
        mallory.curve_publickey, mallory.curve_secretkey = public, secret  # type: ignore[attr-defined]
        mallory.curve_serverkey = handle.info.key.encode()  # type: ignore[attr-defined]
        mallory.setsockopt(zmq.IMMEDIATE, 1)
        mallory.setsockopt(zmq.LINGER, 0)
        try:
            mallory.connect(handle.endpoint)
            assert not mallory.poll(1500, zmq.POLLOUT)  # the handshake was refused
        finally:
            mallory.close(0)
            ctx.term()
        assert alice.request(name, "hello") == {"hi": 1}


@pytest.mark.parametrize("encrypted", [True, False])
def test_traffic_through_a_relay_is_readable_only_without_curve(
        keys: Path, secured: str, zmq_url: str, encrypted: bool) -> None:
    url = secured if encrypted else zmq_url
    where = {"provider_bind": "tcp://127.0.0.1", "advertise_host": "127.0.0.2"}
    alice_options = _as(keys, "alice", **where) if encrypted else {**FAST, **where}
    bob_options = _as(keys, "bob") if encrypted else FAST
    name = f"svc-{uuid.uuid4().hex[:8]}"
    with robosoa.connect(url, **alice_options) as alice, \
            robosoa.connect(url, **bob_options) as bob:
        handle = alice.provide(name, {"echo": lambda text: {"text": text}})
        port = int(handle.endpoint.rpartition(":")[2])
        with Relay(("127.0.0.2", port), ("127.0.0.1", port), record=True) as relay:
            reply = bob.request(name, "echo", {"text": MARKER}, timeout=20)
            assert reply == {"text": MARKER}
            seen = relay.seen()
    assert len(seen) > len(MARKER)  # the request and the reply went through the relay
    assert (MARKER.encode() in seen) is not encrypted


def test_keys_command_never_overwrites(tmp_path: Path) -> None:
    assert run("keys", str(tmp_path), "robot").returncode == 0
    assert (tmp_path / "robot.key").is_file() and (tmp_path / "robot.key_secret").is_file()
    assert (tmp_path / "robot.key_secret").stat().st_mode & 0o077 == 0
    again = run("keys", str(tmp_path), "robot")
    assert again.returncode == 2 and "not overwritten" in again.stderr
    bad = run("keys", str(tmp_path), "../escape")
    assert bad.returncode == 2 and "key name" in bad.stderr


def test_a_missing_certificate_is_a_usage_error(tmp_path: Path) -> None:
    done = run("services", "--curve-secret", str(tmp_path / "nope.key_secret"),
               "--curve-allow", str(tmp_path))
    assert done.returncode == 2 and "nope.key_secret" in done.stderr
    loc = run("location", "--bind", f"tcp://127.0.0.1:{free_port()}",
              "--curve-secret", str(tmp_path / "nope.key_secret"), "--curve-allow", "/nowhere")
    assert loc.returncode == 2 and "allow" in loc.stderr


