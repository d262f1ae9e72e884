"""Threat: a run that dies while writing the facts cache — ``kill -9`` (a cancelled CI job)
or a full disk — must not leave a cache that makes the next run fail or report other numbers
(docs/security.md, threat table; "The facts cache").

The disk is made "full" with ``RLIMIT_FSIZE`` (and ``SIGXFSZ`` ignored, so a write fails with
``EFBIG`` as it would with ``ENOSPC``)."""

from __future__ import annotations

import json
import resource
import signal
import sqlite3
import subprocess
import sys
import time
from pathlib import Path

import pytest

from tests.gitrepo import GitRepo
from tests.untrusted import run_cli

pytestmark = pytest.mark.security

FILES = {
    f"pkg/m{k:03d}.py": "".join(f"def f{j}(a):\n    if a > {j}:\n        return a\n    return {j}\n"
                                for j in range(30))
    for k in range(80)
}  # fmt: skip


@pytest.fixture
def many(repo: GitRepo) -> GitRepo:
    repo.commit("v1", files=FILES)
    return repo


def _scan(repo: GitRepo, *extra: str) -> tuple[int, str, str]:
    run = run_cli(["scan", ".", "--format", "json", *extra], repo.root)
    return run.code, run.out, run.err


def _consistent(cache: Path) -> None:
    with sqlite3.connect(cache) as db:
        assert db.execute("PRAGMA integrity_check").fetchone() == ("ok",)


def test_a_run_killed_while_caching_leaves_a_cache_the_next_run_trusts(
    many: GitRepo, tmp_path: Path
) -> None:
    expected = json.loads(_scan(many, "--no-cache")[1])
    cache = tmp_path / "facts.sqlite3"
    for delay in (0.5, 2.0):  # killed earlier or later in the run: the same must hold
        started = subprocess.Popen(
            [sys.executable, "-m", "archmetrics", "scan", ".", "--cache-path", str(cache)],
            cwd=many.root, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
        time.sleep(delay)
        started.send_signal(signal.SIGKILL)
        started.wait(timeout=60)
        code, out, err = _scan(many, "--cache-path", str(cache))
        assert code == 0, err
        assert json.loads(out) == expected
        if cache.exists():
            _consistent(cache)


def _full_disk() -> None:
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (64 << 10, 64 << 10))


def test_a_full_disk_is_one_line_and_leaves_the_cache_usable(
    many: GitRepo, tmp_path: Path
) -> None:
    expected = json.loads(_scan(many, "--no-cache")[1])
    cache = tmp_path / "facts.sqlite3"
    done = subprocess.run(
        [sys.executable, "-m", "archmetrics", "scan", ".", "--format", "json",
         "--cache-path", str(cache)],
        cwd=many.root, capture_output=True, text=True, preexec_fn=_full_disk, timeout=300,
        check=False,
    )  # fmt: skip
    assert done.returncode in (0, 2), done.stderr
    assert "Traceback" not in done.stderr
    if done.returncode == 2:
        assert done.stderr.count("archmetrics: error") == 1, done.stderr
    else:  # the cache gave up and the run went on without it: the numbers are right
        assert json.loads(done.stdout) == expected
    code, out, err = _scan(many, "--cache-path", str(cache))
    assert code == 0, err
    assert json.loads(out) == expected
    _consistent(cache)
