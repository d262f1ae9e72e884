"""The code's own checks run as tests: ruff, mypy --strict, and the import-layer contracts."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BIN = Path(sys.executable).parent


def _run(*command: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=600)


def test_ruff() -> None:
    done = _run(
        str(BIN / "ruff"), "check", "archmetrics", "robosoa", "tests", "benchmarks", "action"
    )
    assert done.returncode == 0, done.stdout + done.stderr


def test_mypy_strict() -> None:
    done = _run(str(BIN / "mypy"))
    assert done.returncode == 0, done.stdout + done.stderr
    action = _run(str(BIN / "mypy"), "--strict", "action/run.py")  # the action's steps
    assert action.returncode == 0, action.stdout + action.stderr


def test_import_layers() -> None:
    done = _run(str(BIN / "lint-imports"))
    assert done.returncode == 0, done.stdout + done.stderr


@pytest.mark.parametrize("package", ["archmetrics", "robosoa"])
def test_packages_import_cleanly(package: str) -> None:
    done = _run(sys.executable, "-c", f"import {package}")
    assert done.returncode == 0, done.stderr
