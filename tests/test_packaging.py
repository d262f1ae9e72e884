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
        "archmetrics/schemas/baseline-1.schema.json",
    ):
        assert required in names, required
    assert not [n for n in names if "__pycache__" in n or n.endswith((".pyc", ".o", ".so"))]
    # every page of docs/ ships, so `archmetrics --help` and `archmetrics docs` name files
    # the installation has (the maintainer's script study_tables.py does not)
    pages = {p.relative_to(ROOT).as_posix() for p in (ROOT / "docs").rglob("*") if p.is_file()}
    shipped = {n.removeprefix("archmetrics/") for n in names if n.startswith("archmetrics/docs/")}
    assert shipped == pages - {"docs/study_tables.py"}


@pytest.fixture(scope="module")
def installed(wheel: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """The wheel installed into a folder of its own: the environment that runs it."""
    site = tmp_path_factory.mktemp("site")
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "-q", "--no-deps", "--target", str(site),
         str(wheel)],
        check=True, capture_output=True, timeout=600,
    )  # fmt: skip
    return {**os.environ, "PYTHONPATH": str(site)}


def _run(env: dict[str, str], cwd: Path, *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [sys.executable, "-m", "archmetrics", *argv],
        env=env, capture_output=True, text=True, cwd=cwd, timeout=600,
    )  # fmt: skip


def test_help_names_the_docs_the_wheel_installed(
    installed: dict[str, str], tmp_path: Path
) -> None:
    site = Path(installed["PYTHONPATH"])
    helped = _run(installed, tmp_path, "--help")
    assert helped.returncode == 0
    docs = site / "archmetrics" / "docs"
    assert f" {docs}:" in helped.stdout.replace("\n", " ")  # wrapped, but never inside it
    said = " ".join(helped.stdout.split())
    assert f"Docs: installed in {docs}:" in said and "ci.md" in said
    page = _run(installed, tmp_path, "docs", "ci", "--path")
    assert Path(page.stdout.strip()) == docs / "ci.md"
    listed = _run(installed, tmp_path, "docs").stdout
    assert str(docs) in listed and "subjects/wdb" in listed
    text = _run(installed, tmp_path, "docs", "json").stdout
    assert text == (ROOT / "docs" / "json.md").read_text(encoding="utf-8")
    assert "Project URL" not in listed  # none until the project has a public home


@pytest.mark.slow
def test_replicate_runs_from_the_installed_wheel(
    installed: dict[str, str], tmp_path: Path
) -> None:
    site = installed["PYTHONPATH"]
    env = {**installed, "ARCHMETRICS_CACHE": str(tmp_path / "c.db")}
    where = subprocess.run(
        [sys.executable, "-c", "import archmetrics; print(archmetrics.__file__)"],
        env=env,
        capture_output=True,
        text=True,
        check=True,
        cwd=tmp_path,
    ).stdout
    assert where.startswith(site)  # the installed copy, not this checkout
    done = subprocess.run(
        [sys.executable, "-m", "archmetrics", "replicate", "--out", "study", "--quiet"],
        env=env,
        capture_output=True,
        text=True,
        cwd=tmp_path,
        timeout=900,
    )
    assert done.returncode == 0, done.stderr
    assert "Agree: as-described " in done.stdout and " of 11" in done.stdout
    assert "Cheapest integration by stage" in done.stdout
    report = json.loads((tmp_path / "study" / "report.json").read_text())
    assert report["schema"] == "archmetrics.study/2"
    assert set(report["variants"]["idiomatic"]["subjects"]) == {"wdb", "pragmatics", "legacy"}
    assert (tmp_path / "study" / "report.md").stat().st_size > 1000
    assert list((tmp_path / "study" / "charts" / "idiomatic").glob("*.png"))
