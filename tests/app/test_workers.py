"""Parser processes under hostile input: a file that crashes, hangs or eats memory costs that
file, named with the reason, never the run; and no worker outlives archmetrics."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from archmetrics.app.workers import Parsed, parse_in_workers
from tests.gitrepo import GitRepo
from tests.untrusted import run_cli, run_main

PLUGIN = """
import ctypes, os, time

from archmetrics.parsers import LanguageSpec
from archmetrics.parsers.python import parse as parse_python


def parse(path, source):
    if "SEGFAULT" in source:
        ctypes.string_at(0)
    if "ABORT" in source:
        os.abort()
    if "SLEEP" in source:
        if os.environ.get("UNRULY_SLEEPING"):  # a file that says the sleep has begun
            open(os.environ["UNRULY_SLEEPING"], "w").close()
        time.sleep(600)
    if "HOG" in source:
        hog = [bytearray(1 << 20) for _ in range(1 << 16)]
    if "RAISE" in source:
        raise ZeroDivisionError("the plugin's own bug")
    return parse_python(path, source)


SPEC = LanguageSpec("unruly", parse)
"""
FINE = "def f{i}(a):\n    if a:\n        return {i}\n    return 0\n"


def _installed(site: Path, name: str, module: str) -> Path:
    """``site`` holding distribution ``name`` whose ``{name}_lang`` module (``module``)
    registers ``SPEC`` in the ``archmetrics.languages`` entry-point group."""
    (site / f"{name}-1.0.dist-info").mkdir(parents=True)
    (site / f"{name}_lang.py").write_text(module)
    (site / f"{name}-1.0.dist-info" / "METADATA").write_text(f"Name: {name}\nVersion: 1.0\n")
    (site / f"{name}-1.0.dist-info" / "entry_points.txt").write_text(
        f"[archmetrics.languages]\n{name} = {name}_lang:SPEC\n"
    )
    return site


@pytest.fixture
def plugin(tmp_path: Path) -> dict[str, str]:
    """A third-party language (as installed through the ``archmetrics.languages`` entry-point
    group) whose parser crashes, hangs, hogs memory or raises on request."""
    site = _installed(tmp_path / "site", "unruly", PLUGIN)
    path = os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")])
    return {"PYTHONPATH": path}


def _repo(repo: GitRepo, bad: dict[str, str], fine: int, limits: str = "") -> None:
    files = {f"ok{i}.py": FINE.format(i=i) for i in range(fine)}
    files.update(bad)
    config = '[tool.archmetrics]\nlanguages = { ".un" = "unruly" }\n' + limits
    repo.commit("v1", files={**files, "pyproject.toml": config})


def _measured(out: str) -> dict[str, dict[str, object]]:
    return {f["path"]: f for f in json.loads(out)["files"]}


@pytest.mark.parametrize("fine", [3, 60], ids=["forked", "fork-server"])
@pytest.mark.parametrize(
    ("trigger", "reason"),
    [
        ("SEGFAULT", "died (SIGSEGV)"),
        ("ABORT", "died (SIGABRT)"),
        ("RAISE", "ZeroDivisionError: the plugin's own bug"),
    ],
)
@pytest.mark.security
def test_a_file_that_breaks_its_parser_costs_that_file(
    repo: GitRepo, plugin: dict[str, str], trigger: str, reason: str, fine: int
) -> None:
    _repo(repo, {"bad.un": f"x = 1  # {trigger}\n", "good.un": FINE.format(i=99)}, fine)
    run = run_cli(["scan", ".", "--format", "json", "--no-cache", "-j", "2"], repo.root, plugin)
    assert run.code == 0, run.err
    files = _measured(run.out)
    assert len(files) == fine + 2
    [warning] = files["bad.un"]["warnings"]  # type: ignore[misc]
    assert reason in warning["message"] and warning["message"].startswith("not measured")
    assert files["good.un"]["vg"] == 2
    assert all(files[f"ok{i}.py"]["vg"] == 2 for i in range(fine))


@pytest.mark.security
def test_a_file_over_the_time_limit_is_cut_off(repo: GitRepo, plugin: dict[str, str]) -> None:
    limits = "[tool.archmetrics.limits]\nfile-seconds = 1\n"
    _repo(repo, {"slow.un": "# SLEEP\n", "also.un": FINE.format(i=7)}, 3, limits)
    started = time.monotonic()
    run = run_cli(["scan", ".", "--format", "json", "--no-cache"], repo.root, plugin)
    assert run.code == 0, run.err
    assert time.monotonic() - started < 60  # not the plugin's 600 s
    files = _measured(run.out)
    [warning] = files["slow.un"]["warnings"]  # type: ignore[misc]
    assert "took longer than 1 s" in warning["message"]
    assert files["also.un"]["vg"] == 2


@pytest.mark.security
def test_a_file_over_the_memory_limit_is_not_measured(
    repo: GitRepo, plugin: dict[str, str]
) -> None:
    limits = "[tool.archmetrics.limits]\nworker-memory-mb = 256\n"
    _repo(repo, {"hog.un": "# HOG\n", "also.un": FINE.format(i=7)}, 3, limits)
    run = run_cli(["scan", ".", "--format", "json", "--no-cache"], repo.root, plugin)
    assert run.code == 0, run.err
    files = _measured(run.out)
    [warning] = files["hog.un"]["warnings"]  # type: ignore[misc]
    assert "needed more than 256 MiB" in warning["message"]
    assert files["also.un"]["vg"] == 2


def test_files_cut_off_by_a_limit_are_not_cached(
    repo: GitRepo, plugin: dict[str, str], tmp_path: Path
) -> None:
    _repo(repo, {"bad.un": "# ABORT\n"}, 1)
    cache = ["--cache-path", str(tmp_path / "c.sqlite3"), "--format", "json"]
    for _ in range(2):
        run = run_cli(["scan", ".", *cache], repo.root, plugin)
        assert "died (SIGABRT)" in run.out


@pytest.mark.parametrize(
    ("limits", "problem"),
    [
        ("file-seconds = 0", "more than 0"),
        ("file-seconds = 1e9", "at most 3600"),
        ("file-seconds = nan", "more than 0"),
        ("worker-memory-mb = 1.5", "expected a number"),
        ("worker-memory-mb = true", "expected a number"),
        ("pages = 3", "unknown key 'pages'"),
    ],
)
@pytest.mark.security
def test_limits_a_repository_sets_are_checked(repo: GitRepo, limits: str, problem: str) -> None:
    """Refused while the configuration is read, before any worker starts: in process."""
    repo.commit("v1", files={"pyproject.toml": f"[tool.archmetrics.limits]\n{limits}\n"})
    run = run_main(["scan", "."], repo.root)
    assert run.code == 2
    assert problem in run.one_line_error()


def _descendants(pid: int) -> set[int]:
    children: dict[int, list[int]] = {}
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                fields = (entry / "stat").read_text().rsplit(")", 1)[1].split()
            except OSError:
                continue
            children.setdefault(int(fields[1]), []).append(int(entry.name))
    found, todo = set(), [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.add(child)
            todo.append(child)
    return found


def _alive(pids: set[int]) -> set[int]:
    alive = set()
    for pid in pids:
        try:
            state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
        except OSError:
            continue
        if state != "Z":
            alive.add(pid)
    return alive


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("fine", [3, 60], ids=["forked", "fork-server"])
@pytest.mark.security
def test_workers_exit_when_archmetrics_is_killed(
    repo: GitRepo, plugin: dict[str, str], fine: int, tmp_path: Path
) -> None:
    _repo(repo, {"slow.un": "# SLEEP\n"}, fine)
    sleeping = tmp_path / "sleeping"
    process = subprocess.Popen(
        [sys.executable, "-m", "archmetrics", "scan", ".", "--no-cache", "-j", "2"],
        cwd=repo.root,
        env={**os.environ, **plugin, "UNRULY_SLEEPING": str(sleeping)},
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 60
        while not sleeping.exists() and time.monotonic() < deadline:
            time.sleep(0.01)  # until a worker is reading the slow file
        assert sleeping.exists(), "no worker began to read the slow file"
        workers = _descendants(process.pid)
        assert workers
        os.kill(process.pid, signal.SIGKILL)
        process.wait(timeout=10)
        deadline = time.monotonic() + 20
        while _alive(workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not _alive(workers)
    finally:
        if process.poll() is None:
            process.kill()


def test_parser_limits_come_from_the_configuration_and_key_the_cache(
    repo: GitRepo, tmp_path: Path
) -> None:
    """A file over the configured size is reported, naming the key; raising the limit
    measures it at once (facts made under other limits are not served from the cache)."""
    big = "x = 1\n" * 400  # 2,400 bytes
    repo.commit("v1", files={"big.py": big, "deep.py": "y = " + "(" * 150 + "1" + ")" * 150})
    cache = ["--cache-path", str(tmp_path / "c.sqlite3"), "--format", "json"]
    config = "[tool.archmetrics.limits]\nfile-mb = 0.001\nnesting = 100\n"
    repo.write({"pyproject.toml": config})
    files = _measured(run_cli(["scan", ".", *cache], repo.root).out)
    [size] = files["big.py"]["warnings"]  # type: ignore[misc]
    assert "limits.file-mb" in size["message"] and files["big.py"]["loc"] == 0
    [depth] = files["deep.py"]["warnings"]  # type: ignore[misc]
    assert "limits.nesting" in depth["message"]
    repo.write({"pyproject.toml": "[tool.archmetrics.limits]\nnesting = 1000\n"})
    files = _measured(run_cli(["scan", ".", *cache], repo.root).out)
    assert files["big.py"]["loc"] == 400 and files["deep.py"]["loc"] == 1
    assert files["big.py"]["warnings"] == [] and files["deep.py"]["warnings"] == []


def test_configured_macros_reach_the_c_parser_and_key_the_cache(
    repo: GitRepo, tmp_path: Path
) -> None:
    """A lower-case export macro is not recognised by its spelling; listed under
    [tool.archmetrics.macros] it is, at once (facts read without the list are not reused)."""
    source = (
        "class my_export Proxy : public Base {\n  int get() { if (x) return 1; return 0; }\n};\n"
    )
    repo.commit("v1", files={"proxy.cpp": source})
    cache = ["--cache-path", str(tmp_path / "c.sqlite3"), "--format", "json"]
    files = _measured(run_cli(["scan", ".", *cache], repo.root).out)
    functions = files["proxy.cpp"]["functions"]
    # tree-sitter reads the class as a function `Proxy`; the token reading finds the
    # method, estimated, under a warning
    assert [(f["qualified_name"], f["estimated"]) for f in functions] == [("Proxy::get", True)]  # type: ignore[index]
    assert len(files["proxy.cpp"]["warnings"]) == 1
    repo.write({"pyproject.toml": '[tool.archmetrics.macros]\nattribute = ["my_export"]\n'})
    files = _measured(run_cli(["scan", ".", *cache], repo.root).out)
    functions = files["proxy.cpp"]["functions"]
    assert [(f["qualified_name"], f["vg"], f["estimated"]) for f in functions] == [  # type: ignore[index]
        ("Proxy::get", 2, False)
    ]
    assert files["proxy.cpp"]["warnings"] == []


NAPPING = """
import time

from archmetrics.parsers import LanguageSpec
from archmetrics.parsers.python import parse as parse_python


def parse(path, source):
    if "NAP" in source:
        time.sleep(3)
    return parse_python(path, source)


SPEC = LanguageSpec("napping", parse)
"""


def test_a_worker_that_answers_gets_its_next_batch_while_another_is_busy(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """One worker reads a file that takes 3 s; the other must go through every other batch
    meanwhile, not wait for its colleague (or the parent's 1 s poll) between batches."""
    site = _installed(tmp_path / "site", "napping", NAPPING)
    monkeypatch.syspath_prepend(str(site))  # forked workers inherit it
    batches = [["slow"]] + [[f"fast{i}"] for i in range(12)]
    answered: list[str] = []

    def tasks(batch: list[str]) -> list[tuple[str, bytes, str]]:
        return [
            (name, b"x = 1  # NAP\n" if name == "slow" else b"y = 2\n", "napping") for name in batch
        ]

    def deliver(name: str, answer: Parsed) -> None:
        assert answer.encoded is not None, answer.failure
        answered.append(name)

    parse_in_workers(batches, tasks, deliver, workers=2)
    assert answered[-1] == "slow"
    assert sorted(answered[:-1]) == sorted(f"fast{i}" for i in range(12))


def test_a_worker_gets_its_next_batch_before_its_answers_are_delivered() -> None:
    """The parent's delivery of a batch's answers (decoding facts, caching them) must not
    keep the worker that gave them idle: its next batch is sent first."""
    events: list[str] = []

    def tasks(batch: list[str]) -> list[tuple[str, bytes, str]]:
        events.append(f"send {batch[0]}")
        return [(name, b"x = 1\n", "python") for name in batch]

    def deliver(name: str, answer: Parsed) -> None:
        assert answer.encoded is not None, answer.failure
        events.append(f"deliver {name}")

    parse_in_workers([["a"], ["b"], ["c"]], tasks, deliver, workers=1)
    assert events == ["send a", "send b", "deliver a", "send c", "deliver b", "deliver c"]
