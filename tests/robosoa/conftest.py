"""Fixtures: the same tests run over an in-process bus pair and a ZeroMQ bus pair."""

from __future__ import annotations

import shutil
import subprocess
import uuid
from collections.abc import Iterator
from pathlib import Path

import pytest

import robosoa
from tests.robosoa.procs import PYTHON, REPO, Proc, _env, tcp_location

FAST = {"heartbeat": 0.2, "ttl": 1.0, "lookup_cache": 0.2, "location_timeout": 2.0}


@pytest.fixture(scope="session")
def location() -> Iterator[tuple[Proc, str]]:
    """One ZeroMQ location service process shared by the session (unique names per test)."""
    proc, url = tcp_location()
    yield proc, url
    proc.stop()


@pytest.fixture
def zmq_url(location: tuple[Proc, str]) -> str:
    """The bus URL of the shared location service."""
    return location[1]


@pytest.fixture(params=["inproc", "zmq"])
def url(request: pytest.FixtureRequest) -> str:
    """A bus URL of each transport."""
    if request.param == "inproc":
        return f"inproc://test-{uuid.uuid4().hex[:8]}"
    return str(request.getfixturevalue("zmq_url"))


@pytest.fixture
def pair(url: str) -> Iterator[tuple[robosoa.Bus, robosoa.Bus]]:
    """Two buses on the same transport: a provider side and a consumer side."""
    a = robosoa.connect(url, **FAST)
    b = robosoa.connect(url, **FAST)
    yield a, b
    b.close()
    a.close()


@pytest.fixture
def name() -> str:
    """A service/topic name no other test uses (the zmq location service is shared)."""
    return f"svc-{uuid.uuid4().hex[:8]}"


@pytest.fixture(scope="module")
def keys(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """CURVE key pairs of ``location`` and ``alice`` (``robosoa keys``), both public keys
    in the folder ``allow``."""
    folder = tmp_path_factory.mktemp("keys")
    done = subprocess.run([PYTHON, "-m", "robosoa", "keys", str(folder), "location", "alice"],
                          capture_output=True, text=True, env=_env(), cwd=REPO, timeout=30)
    assert done.returncode == 0, done.stderr
    (folder / "allow").mkdir()
    for who in ("location", "alice"):
        shutil.copy(folder / f"{who}.key", folder / "allow")
    return folder
