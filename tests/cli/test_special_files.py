"""Threat: a file the repository names that is a FIFO, a device or a link to one (reading a
FIFO waits for a writer forever; ``/dev/zero`` never ends; ``estimate`` on a plan linked to
``/dev/stdin`` blocked). Every file archmetrics opens for the repository — a plan, a
sketch's patch, the configuration, a rule pack, a source file, a plain folder's
``.gitignore`` — is refused (or, for a source file or ``.gitignore``, skipped) unless it is
a regular file, without waiting (docs/security.md, threat table).

A regression must fail, not hang: FIFOs are read past by tests/untrusted.py
``run_main_past_fifos`` once TIMEOUT has passed (the runs are in this process); the plan
linked to ``/dev/stdin`` and the ``/dev/zero`` configuration are processes of their own with
a time limit (a pipe to this process's stdin, and a read that never ends, cannot be ended
from outside)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.gitrepo import GitRepo
from tests.untrusted import run_cli, run_main_past_fifos

pytestmark = pytest.mark.security

SOURCE = "def f(a):\n    if a:\n        return 1\n    return 2\n"
TIMEOUT = 60


def _fifos(root: Path) -> list[Path]:
    return [path for path in root.rglob("*") if path.is_fifo()]


def _one_line(argv: list[str], cwd: Path, *problems: str) -> None:
    run = run_main_past_fifos(argv, cwd, _fifos(cwd), TIMEOUT)
    assert run.code == 2, run.err
    line = run.one_line_error()
    assert all(problem in line for problem in problems), line


@pytest.fixture
def committed(repo: GitRepo) -> GitRepo:
    repo.commit("v1", files={"a.py": SOURCE})
    return repo


def test_a_fifo_plan_is_refused(committed: GitRepo) -> None:
    os.mkfifo(committed.root / "plan.toml")
    problems = ("plan.toml: cannot read: ", "a FIFO, not a regular file")
    _one_line(["estimate", "plan.toml"], committed.root, *problems)


def test_a_plan_linked_to_stdin_does_not_wait(committed: GitRepo, tmp_path: Path) -> None:
    """stdin is a pipe nobody writes to or closes: reading it would wait forever."""
    (tmp_path / "plan.toml").symlink_to("/dev/stdin")
    done = subprocess.Popen(
        [sys.executable, "-m", "archmetrics", "estimate", str(tmp_path / "plan.toml"),
         "-C", str(committed.root)],
        stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
    )  # fmt: skip
    try:
        err = done.communicate(timeout=TIMEOUT)[1]
    finally:
        done.kill()
    assert done.returncode == 2, err
    assert b"not a regular file" in err and err.count(b"\n") == 1, err


def test_a_fifo_patch_is_refused(committed: GitRepo) -> None:
    plan = '[architecture.a]\nsketch = { patch = "change.patch" }\n'
    committed.write({"plan.toml": plan})
    os.mkfifo(committed.root / "change.patch")
    _one_line(["estimate", "plan.toml"], committed.root, "a FIFO, not a regular file")


@pytest.mark.parametrize("name", ["archmetrics.toml", "pyproject.toml"])
def test_a_fifo_configuration_is_refused(committed: GitRepo, name: str) -> None:
    """scan and rules read the configuration on disk; a diff reads its base revision's
    blobs (git keeps no FIFO), so it goes on without waiting."""
    os.mkfifo(committed.root / name)
    for argv in (["scan", "."], ["rules"]):
        _one_line(argv, committed.root, f"{name}: cannot read: ")
    run = run_main_past_fifos(["diff", "--no-cache"], committed.root, _fifos(committed.root))
    assert run.code == 0, run.err


def test_a_device_configuration_is_refused(committed: GitRepo) -> None:
    """/dev/zero, linked from inside the repository's folder as its configuration."""
    (committed.root / "archmetrics.toml").symlink_to("/dev/zero")
    run = run_cli(["scan", "."], committed.root, timeout=TIMEOUT)
    assert run.code == 2, run.err
    assert "archmetrics.toml" in run.one_line_error()


def test_a_fifo_source_file_and_gitignore_are_skipped(tmp_path: Path) -> None:
    """A plain folder: a FIFO with a source ending is no file to measure, a FIFO .gitignore
    counts as none."""
    (tmp_path / "a.py").write_text(SOURCE)
    os.mkfifo(tmp_path / "b.py")
    os.mkfifo(tmp_path / ".gitignore")
    argv = ["scan", ".", "--format", "csv", "--no-cache"]
    run = run_main_past_fifos(argv, tmp_path, _fifos(tmp_path), TIMEOUT)
    assert run.code == 0, run.err
    assert "a.py" in run.out and "b.py" not in run.out


def test_an_untracked_fifo_in_a_work_tree_is_skipped(committed: GitRepo) -> None:
    fifo = committed.root / "c.py"
    os.mkfifo(fifo)
    for argv in (["scan", "."], ["diff", "--format", "json"]):
        run = run_main_past_fifos([*argv, "--no-cache"], committed.root, [fifo], TIMEOUT)
        assert run.code == 0, run.err
        assert "c.py" not in run.out
