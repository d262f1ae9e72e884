"""The legacy-driver study subject (Hestand 2011, ch. 11-12): a Player-style C robot-base driver
served on robosoa without changing it.

Real runs only: each stage's driver is built as a shared library with the system cc, the
stage's provider wraps it through ctypes on the real robosoa runtime (inproc and zmq), and
the consumer API's effect is read back through the driver's own odometry function.
"""

from __future__ import annotations

import json
import math
import os
import shutil
import subprocess
import sys
import tomllib
from pathlib import Path
from typing import Any

import pytest

from tests.robosoa.procs import tcp_location

REPO = Path(__file__).resolve().parents[2]
LEGACY = REPO / "fixtures" / "study" / "legacy" / "soa"
STAGES = ("baseline", "first", "second")
OPERATIONS = {"baseline": (), "first": ("set_odometry",),
              "second": ("set_odometry", "reset_odometry")}
DRIVER_FILES = ("p2d.h", "rflex.h", "rflex.c", "Makefile")
TIMEOUT = 60.0  # seconds one harness run may take

# Runs in a child process so that each stage's modules are imported fresh. The provider side
# (driver + Position2dProvider) lives here; the consumer is either in-process (inproc bus)
# or the stage's consumer.py run as a separate process (zmq bus).
HARNESS = """
import json, subprocess, sys
stage, lib, url, plan = sys.argv[1], sys.argv[2], sys.argv[3], json.loads(sys.argv[4])
sys.path.insert(0, stage)
import robosoa
from p2d_service import binding
from p2d_service.mediator import SERVICE
from p2d_service.p2d_consumer import Position2dConsumer
from p2d_service.p2d_provider import Position2dProvider

CLI = {"set": "set-odometry", "reset": "reset-odometry", "ping": "ping"}

def in_process(bus, action):
    consumer = Position2dConsumer(bus)
    consumer.wait_ready()
    try:
        if action[0] == "ping":
            bus.request(SERVICE, "_ping", {})
        elif action[0] == "set" and hasattr(consumer, "set_odometry"):
            consumer.set_odometry(*action[1:])
        elif action[0] == "reset" and hasattr(consumer, "reset_odometry"):
            consumer.reset_odometry()
        else:  # the stage's API lacks the call: ask the provider directly
            op = {"set": "set_odometry", "reset": "reset_odometry"}[action[0]]
            fields = dict(zip(("x", "y", "yaw"), action[1:]))
            bus.request(SERVICE, op, fields)
        return "ok"
    except robosoa.RobosoaError as exc:
        return "refused: " + str(exc)

def by_process(action):
    args = [sys.executable, stage + "/consumer.py", "--bus", url, CLI[action[0]]]
    args += [str(v) for v in action[1:]]
    done = subprocess.run(args, capture_output=True, text=True, timeout=20)
    return "ok" if done.returncode == 0 else "refused: " + done.stderr.strip()[-300:]

driver = binding.RflexDriver(binding.load(lib), cycle_ms=5.0)
driver.setup()
results = {"running": driver.running, "steps": []}
provider_bus = robosoa.connect(url)
consumer_bus = robosoa.connect(url)
provider = Position2dProvider(provider_bus, driver)
provider.start()
for action in plan:
    outcome = in_process(consumer_bus, action) if url == "inproc" else by_process(action)
    results["steps"].append({"outcome": outcome, "odometry": list(driver.odometry())})
provider.stop()
consumer_bus.close()
provider_bus.close()
driver.shutdown()
results["stopped"] = not driver.running
print(json.dumps(results))
"""

# every stage runs the same plan: what the stage does not offer must be refused
PLAN: list[list[Any]] = [["ping"], ["set", 1.5, -2.0, 0.75], ["set", -0.25, 3.0, -1.0],
                         ["reset"]]


def stage_dir(stage: str) -> Path:
    return LEGACY / stage


def build_driver(stage: str, tmp: Path) -> Path:
    """The stage's legacy driver, built as a shared library with the system cc."""
    lib = tmp / f"librflex-{stage}.so"
    driver = stage_dir(stage) / "driver"
    done = subprocess.run(["cc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-shared", "-fPIC",
                           "-o", str(lib), str(driver / "rflex.c"), "-lm", "-lpthread"],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return lib


def run_harness(stage: str, lib: Path, url: str) -> dict[str, Any]:
    """Run the plan against the stage on bus ``url``; the harness's JSON result."""
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    done = subprocess.run([sys.executable, "-c", HARNESS, str(stage_dir(stage)), str(lib), url,
                           json.dumps(PLAN)], capture_output=True, text=True, timeout=TIMEOUT,
                          env=env)
    assert done.returncode == 0, done.stderr[-3000:]
    result: dict[str, Any] = json.loads(done.stdout.splitlines()[-1])
    return result


def expected_odometry(stage: str) -> list[tuple[str, tuple[float, float, float] | None]]:
    """Per plan step: whether the stage accepts it, and the pose the driver must then hold
    (None: unchanged from the step before)."""
    offered = OPERATIONS[stage]
    steps: list[tuple[str, tuple[float, float, float] | None]] = []
    for action in PLAN:
        if action[0] == "ping":
            steps.append(("ok", None))
        elif action[0] == "set":
            ok = "set_odometry" in offered
            steps.append(("ok" if ok else "refused", tuple(action[1:]) if ok else None))
        else:
            ok = "reset_odometry" in offered
            steps.append(("ok" if ok else "refused", (0.0, 0.0, 0.0) if ok else None))
    return steps


def check_run(stage: str, result: dict[str, Any]) -> None:
    """The driver ran, every offered call changed its odometry, every other call was refused
    and left it alone."""
    assert result["running"] and result["stopped"]
    pose = (0.0, 0.0, 0.0)
    for step, (outcome, target) in zip(result["steps"], expected_odometry(stage), strict=True):
        assert step["outcome"].split(":")[0] == outcome, step
        pose = target if target is not None else pose
        assert all(math.isclose(a, b, abs_tol=1e-9) for a, b in
                   zip(step["odometry"], pose, strict=True)), (step, pose)


def test_manifest_parses_and_names_complete_stages() -> None:
    manifest = tomllib.loads((LEGACY / "manifest.toml").read_text(encoding="utf-8"))
    assert (manifest["subject"], manifest["approach"]) == ("legacy", "soa")
    assert tuple(manifest["stages"]) == STAGES
    assert list(manifest["locations"]) == ["new", "framework", "base"]
    for stage in manifest["stages"]:
        root = stage_dir(stage)
        assert root.is_dir()
        for globs in manifest["locations"].values():
            for glob in globs:
                pattern = glob[:-3] + "/**/*" if glob.endswith("/**") else glob
                assert any(p.is_file() for p in root.glob(pattern)), f"{stage}: {glob}"


def test_legacy_driver_is_identical_in_every_stage() -> None:
    """The integration must not change the driver (p. 138)."""
    for name in DRIVER_FILES:
        texts = {(stage_dir(s) / "driver" / name).read_bytes() for s in STAGES}
        assert len(texts) == 1, name


@pytest.mark.parametrize("stage", STAGES)
def test_stage_exposes_only_its_operations(stage: str) -> None:
    service = (stage_dir(stage) / "service" / "position2d.xml").read_text(encoding="utf-8")
    provider = (stage_dir(stage) / "p2d_service" / "p2d_provider.py").read_text(encoding="utf-8")
    for operation in ("set_odometry", "reset_odometry"):
        offered = operation in OPERATIONS[stage]
        assert (f'name="{operation}"' in service) == offered
        assert (f"def {operation}(" in provider) == offered


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
@pytest.mark.parametrize("stage", STAGES)
def test_stage_on_inproc_bus_changes_the_driver(stage: str, tmp_path: Path) -> None:
    check_run(stage, run_harness(stage, build_driver(stage, tmp_path), "inproc"))


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
@pytest.mark.parametrize("stage", STAGES)
def test_stage_on_zmq_bus_changes_the_driver(stage: str, tmp_path: Path) -> None:
    lib = build_driver(stage, tmp_path)
    location, url = tcp_location()
    try:
        check_run(stage, run_harness(stage, lib, url))
    finally:
        location.stop()
