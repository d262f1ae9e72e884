"""The wheel carries what a plain `pip install` user needs; replicate runs from it."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


@pytest.fixture(scope="module")
def wheel(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "wheel",
            "-q",
            "--no-deps",
            "--no-build-isolation",
            "-w",
            str(out),
            str(ROOT),
        ],
        check=True,
        capture_output=True,
        timeout=600,
    )
    [built] = out.glob("archmetrics-*.whl")
    return built


def test_wheel_contents(wheel: Path) -> None:
    names = set(zipfile.ZipFile(wheel).namelist())
    for required in (
        "archmetrics/py.typed",
        "robosoa/py.typed",
        "archmetrics/data/sample/python/odometry.py",
        "archmetrics/coupling/rules/posix-sockets.toml",
        "archmetrics/study_subjects/wdb/soa/manifest.toml",
        "archmetrics/study/causes.toml",
        "archmetrics/study_subjects/player_stub/libplayerc/playerc.h",
        "robosoa/data/descriptor.xsd",
        "archmetrics/schemas/scan-1.schema.json",
        "archmetrics/schemas/diff-1.schema.json",
        "archmetrics/schemas/series-1.schema.json",
        "archmetrics/schemas/compare-1.schema.json",
        "archmetrics/schemas/plan-1.schema.json",
        "archmetrics/schemas/estimate-1.schema.json",
        "archmetrics/schemas/graph-1.schema.json",
        "archmetrics/schemas/rules-1.schema.json",
        "archmetrics/schemas/study-2.schema.json",
    ):
        assert required in names, required
    assert not [n for n in names if "__pycache__" in n or n.endswith((".pyc", ".o", ".so"))]


@pytest.mark.slow
def test_replicate_runs_from_the_installed_wheel(wheel: Path, tmp_path: Path) -> None:
    site = tmp_path / "site"
    subprocess.run(
        [
            sys.executable,
            "-m",
            "pip",
            "install",
            "-q",
            "--no-deps",
            "--target",
            str(site),
            str(wheel),
        ],
        check=True,
        capture_output=True,
        timeout=600,
    )
    env = {**os.environ, "PYTHONPATH": str(site), "ARCHMETRICS_CACHE": str(tmp_path / "c.db")}
    where = subprocess.run(
        [sys.executable, "-c", "import archmetrics; print(archmetrics.__file__)"],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
    ).stdout
    assert where.startswith(str(site))  # the installed copy, not this checkout
    done = subprocess.run(
        [sys.executable, "-m", "archmetrics", "replicate", "--out", "study", "--quiet"],
        env=env,
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=900,
    )
    assert done.returncode == 0, done.stderr
    assert "idiomatic: " in done.stdout and " of 11 agree" in done.stdout
    report = json.loads((tmp_path / "study" / "report.json").read_text())
    assert report["schema"] == "archmetrics.study/2"
    assert set(report["variants"]["idiomatic"]["subjects"]) == {"wdb", "pragmatics", "legacy"}
    assert (tmp_path / "study" / "report.md").stat().st_size > 1000
    assert list((tmp_path / "study" / "charts" / "idiomatic").glob("*.png"))
