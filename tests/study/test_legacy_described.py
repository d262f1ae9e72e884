"""The legacy-driver subject as the thesis describes it (Hestand 2011, pp. 137-142): the seven
classes the thesis lists, with the ctypes mirror of the driver's header moved to its own module
and left out of the measurement, as the thesis left out generated definitions.

Real runs only: each stage's driver is built with the system cc and served on the real robosoa
runtime (inproc and zmq), with the harness of the idiomatic subject's tests.
"""

from __future__ import annotations

import ast
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest

from archmetrics.study.manifest import load_manifest
from tests.robosoa.procs import tcp_location
from tests.study.test_legacy_subject import HARNESS, PLAN, STAGES, TIMEOUT, check_run

REPO = Path(__file__).resolve().parents[2]
DESCRIBED = REPO / "fixtures" / "study" / "as-described" / "legacy" / "soa"
IDIOMATIC = REPO / "fixtures" / "study" / "legacy" / "soa"
# the seven classes and applications of p. 141-142, and where they are
SEVEN = ("consumer.py", "provider.py", "p2d_service/mediator.py",
         "p2d_service/consumer_mediator.py", "p2d_service/provider_mediator.py",
         "p2d_service/p2d_consumer.py", "p2d_service/p2d_provider.py")


def build_driver(stage: str, tmp: Path) -> Path:
    lib = tmp / f"librflex-{stage}.so"
    driver = DESCRIBED / stage / "driver"
    done = subprocess.run(["cc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC",
                           "-o", str(lib), str(driver / "rflex.c"), "-lm", "-lpthread"],
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    assert done.returncode == 0, done.stderr
    return lib


def run_harness(stage: str, lib: Path, url: str) -> dict[str, Any]:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    done = subprocess.run([sys.executable, "-c", HARNESS, str(DESCRIBED / stage), str(lib), url,
                           json.dumps(PLAN)], capture_output=True, text=True, timeout=TIMEOUT,
                          env=env)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    result: dict[str, Any] = json.loads(done.stdout.splitlines()[-1])
    return result


def test_manifest_quotes_a_sentence_and_page_for_every_stage() -> None:
    manifest = load_manifest(DESCRIBED)
    assert (manifest.subject, manifest.variant) == ("legacy", "as-described")
    assert [f.stage for f in manifest.follows] == list(STAGES)
    assert "p2d_service/p2d_defs.py" in manifest.exclude


@pytest.mark.parametrize("stage", STAGES)
def test_the_seven_classes_and_the_excluded_definitions(stage: str) -> None:
    """P. 141-142: measurements on the seven classes; the header mirror holds only
    definitions (constants and ctypes structures), no code that runs."""
    root = DESCRIBED / stage
    assert all((root / name).is_file() for name in SEVEN)
    tree = ast.parse((root / "p2d_service" / "p2d_defs.py").read_text(encoding="utf-8"))
    kinds = {type(node).__name__ for node in tree.body}
    assert kinds <= {"Expr", "ImportFrom", "Assign", "ClassDef"}
    for node in tree.body:
        if isinstance(node, ast.ClassDef):
            assert all(isinstance(n, ast.Expr | ast.Assign) for n in node.body), node.name
    # the driver is the idiomatic subject's, byte for byte
    for path in (IDIOMATIC / stage / "driver").iterdir():
        assert (root / "driver" / path.name).read_bytes() == path.read_bytes()


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
@pytest.mark.parametrize("stage", STAGES)
def test_stage_on_inproc_bus_changes_the_driver(stage: str, tmp_path: Path) -> None:
    check_run(stage, run_harness(stage, build_driver(stage, tmp_path), "inproc"))


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
@pytest.mark.parametrize("stage", STAGES)
def test_stage_on_zmq_bus_changes_the_driver(stage: str, tmp_path: Path) -> None:
    lib = build_driver(stage, tmp_path)
    location, url = tcp_location()
    try:
        check_run(stage, run_harness(stage, lib, url))
    finally:
        location.stop()
