"""Threat: a run that dies while writing the facts cache — ``kill -9`` (a cancelled CI job)
or a full disk — must not leave a cache that makes the next run fail or report other numbers
(docs/security.md, threat table; "The facts cache").

The disk is made "full" with ``RLIMIT_FSIZE`` (and ``SIGXFSZ`` ignored, so a write fails with
``EFBIG`` as it would with ``ENOSPC``). The run that is killed or runs out of disk is a process
of its own; the runs before and after it, whose output is compared, run in this one
(tests/untrusted.py ``run_main``)."""

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
from tests.untrusted import run_main

pytestmark = pytest.mark.security

FILES = {
    f"pkg/m{k:03d}.py": "".join(f"def f{j}(a):\n    if a > {j}:\n        return a\n    return {k}\n"
                                for j in range(30))
    for k in range(10)
}  # fmt: skip
"""Ten files, each of its own content (git stores, and the cache keeps, one copy of equal
contents): their facts take the cache past 100 KB, over the 64 KB of the "full disk"."""


@pytest.fixture(scope="module")
def many(tmp_path_factory: pytest.TempPathFactory) -> GitRepo:
    """The repository every run here only reads (each has a cache of its own)."""
    repo = GitRepo(tmp_path_factory.mktemp("interrupted") / "repo")
    repo.commit("v1", files=FILES)
    return repo


@pytest.fixture(scope="module")
def expected(many: GitRepo) -> object:
    """The report measured without a cache."""
    return json.loads(_scan(many, "--no-cache")[1])


def _scan(repo: GitRepo, *extra: str) -> tuple[int, str, str]:
    run = run_main(["scan", ".", "--format", "json", *extra], repo.root)
    return run.code, run.out, run.err


def _consistent(cache: Path) -> None:
    with sqlite3.connect(cache) as db:
        assert db.execute("PRAGMA integrity_check").fetchone() == ("ok",)


def _kill_when_it_appears(repo: GitRepo, cache: Path, watched: Path) -> None:
    """Start a caching scan and SIGKILL it as soon as ``watched`` exists (polled every
    millisecond, for at most a minute): the run must still be going when it is killed."""
    assert not watched.exists()
    started = subprocess.Popen(
        [sys.executable, "-m", "archmetrics", "scan", ".", "--cache-path", str(cache)],
        cwd=repo.root, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while not watched.exists() and time.monotonic() < deadline:
            assert started.poll() is None, f"the run ended before {watched.name} appeared"
            time.sleep(0.001)
        assert started.poll() is None, "the run ended before it was killed"
        started.send_signal(signal.SIGKILL)
    finally:
        started.kill()
        started.wait(timeout=60)
    assert started.returncode == -signal.SIGKILL


@pytest.mark.parametrize("moment", ["created", "-journal"])
def test_a_run_killed_while_caching_leaves_a_cache_the_next_run_trusts(
    many: GitRepo, expected: object, tmp_path: Path, moment: str
) -> None:
    """Killed as soon as the cache file is created, or in its first write transaction
    (SQLite's rollback journal is there): the next run must measure the same."""
    cache = tmp_path / "facts.sqlite3"
    watched = cache if moment == "created" else cache.with_name(cache.name + moment)
    _kill_when_it_appears(many, cache, watched)
    code, out, err = _scan(many, "--cache-path", str(cache))
    assert code == 0, err
    assert json.loads(out) == expected
    _consistent(cache)


def _full_disk() -> None:
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
    resource.setrlimit(resource.RLIMIT_FSIZE, (64 << 10, 64 << 10))


def test_a_full_disk_is_one_line_and_leaves_the_cache_usable(
    many: GitRepo, expected: object, tmp_path: Path
) -> None:
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
