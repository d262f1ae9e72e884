"""`archmetrics history` on a real Dask cluster: a scheduler and two workers started as their
own processes on 127.0.0.1, one of them killed mid-run; the result equals the run on this
machine, commit for commit."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from archmetrics.app.collect import open_cache
from archmetrics.app.diff_options import DiffRequest
from archmetrics.app.history import HistoryRequest, run_history
from archmetrics.cli import main
from archmetrics.config import load_settings
from archmetrics.sources.githistory import Range
from tests.gitrepo import GitRepo

pytestmark = pytest.mark.slow
DASK = Path(sys.executable).parent / "dask"
STARTUP = 60.0  # seconds a scheduler or worker may take to start on a loaded machine


def _unit(i: int, decisions: int) -> str:
    body = "".join(f"    if (x == {k}) {{\n        x += {k};\n    }}\n" for k in range(decisions))
    return f'#include "common.h"\n\nint unit{i}(int x) {{\n{body}    return x;\n}}\n'


@pytest.fixture
def long_history(repo: GitRepo) -> GitRepo:
    """Forty C files, then thirty commits each changing three of them: enough file versions
    for several parse batches and enough commits for several ranges per worker."""
    files = {f"src/unit{i}.c": _unit(i, 1) for i in range(40)}
    repo.commit("root", files={**files, "src/common.h": "int common(void);\n"})
    for n in range(1, 31):
        changed = {f"src/unit{(n * 7 + k) % 40}.c": _unit(n * 7 + k, 1 + n % 5) for k in range(3)}
        if n % 10 == 0:
            changed["src/common.h"] = f"int common(void);\nint more{n}(void);\n"
        repo.commit(f"change {n}", files=changed)
    return repo


def _wait_for(path: Path, process: subprocess.Popen[bytes]) -> None:
    deadline = time.monotonic() + STARTUP
    while not path.exists() or not path.read_text().strip():
        if process.poll() is not None or time.monotonic() > deadline:
            raise RuntimeError(f"{process.args} did not start")
        time.sleep(0.2)


@pytest.fixture
def dask_cluster(tmp_path: Path) -> Iterator[tuple[str, list[subprocess.Popen[bytes]]]]:
    """A scheduler and two single-threaded workers, each in its own process group, all on
    127.0.0.1; stopped (killed) at the end whatever happens."""
    started: list[subprocess.Popen[bytes]] = []
    env = dict(os.environ)

    def start(*args: str) -> subprocess.Popen[bytes]:
        process = subprocess.Popen(
            [str(DASK), *args], cwd=tmp_path, env=env, start_new_session=True,
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        started.append(process)
        return process

    try:
        address_file = tmp_path / "scheduler.json"
        scheduler = start(
            "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
            "--scheduler-file", str(address_file),
        )  # fmt: skip
        _wait_for(address_file, scheduler)
        address = json.loads(address_file.read_text())["address"]
        workers = []
        for name in ("w1", "w2"):
            info = tmp_path / f"{name}.ready"
            workers.append(start(
                "worker", address, "--name", name, "--nthreads", "1", "--nworkers", "1",
                "--host", "127.0.0.1", "--no-dashboard", "--no-nanny",
                "--preload", str(_ready_file_preload(tmp_path, info)),
            ))  # fmt: skip
            _wait_for(info, workers[-1])
        yield address, workers
    finally:
        for process in started:
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGKILL)
            process.wait(timeout=30)


def _ready_file_preload(folder: Path, ready: Path) -> Path:
    """A Dask preload script that writes ``ready`` once its worker has joined."""
    script = folder / f"{ready.stem}_preload.py"
    script.write_text(
        "from pathlib import Path\n\n\n"
        "async def dask_setup(worker):\n"
        f"    Path({str(ready)!r}).write_text(str(worker.address))\n"
    )
    return script


class _KillOnce:
    """A progress port that kills ``victim`` (a worker's process group) when the cluster
    sends back its first answer while parsing: the other answers are still out."""

    def __init__(self, victim: subprocess.Popen[bytes]) -> None:
        self.victim = victim
        self.phase_name = ""
        self.killed = False

    def phase(self, description: str) -> None:
        pass

    def start(self, description: str, total: int) -> None:
        self.phase_name = description

    def advance(self, count: int = 1) -> None:
        if self.phase_name == "parsing" and not self.killed:
            os.killpg(self.victim.pid, signal.SIGKILL)
            self.killed = True

    def stop(self) -> None:
        pass


def _steps(report: Any) -> list[str]:
    return [
        json.dumps({k: s.to_dict() for k, s in e.step.summaries.items()})
        + json.dumps([x.to_dict() for x in e.step.elements])
        for e in report.entries
    ]


def test_a_cluster_that_loses_a_worker_gives_the_local_result(
    long_history: GitRepo,
    dask_cluster: tuple[str, list[subprocess.Popen[bytes]]],
    tmp_path: Path,
) -> None:
    root = long_history.root
    settings = load_settings(root)
    local = HistoryRequest(DiffRequest(root, "", "", settings, jobs=1), Range())
    with open_cache(tmp_path / "local.sqlite3", settings) as cache:
        expected = run_history(local, None, cache)
    address, workers = dask_cluster
    remote = HistoryRequest(local.diff, Range(), scheduler=address)
    killer = _KillOnce(workers[1])
    with open_cache(tmp_path / "remote.sqlite3", settings) as cache:
        found = run_history(remote, killer, cache)
    assert killer.killed
    assert workers[1].wait(timeout=30) is not None
    from distributed import Client

    with Client(address, timeout="10s") as client:  # the run went on with one worker
        assert len(client.scheduler_info()["workers"]) == 1
    assert found.measured == expected.measured == 31
    assert _steps(found) == _steps(expected)
    assert found.parsed == expected.parsed


def test_a_local_dask_cluster_from_the_command_line(
    long_history: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    root = str(long_history.root)
    argv = ["history", "-C", root, "--format", "json", "-q", "-n", "12"]
    assert main([*argv, "--cache-path", str(tmp_path / "a.sqlite3")]) == 0
    here = json.loads(capsys.readouterr().out)
    assert main([*argv, "--cache-path", str(tmp_path / "b.sqlite3"), "--workers", "2"]) == 0
    there = json.loads(capsys.readouterr().out)
    assert there["commits"] == here["commits"]


def test_no_scheduler_is_one_line(
    long_history: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["history", "-C", str(long_history.root), "--scheduler", "tcp://127.0.0.1:9", "-q"]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no Dask scheduler answers" in err[0]
