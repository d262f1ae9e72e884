"""The MURI Pragmatics study subject (Hestand 2011, ch. 9): every stage is complete and runs.

Real runs only: the P2P components are compiled with the system cc and talk over 127.0.0.1,
the SOA GUI, router and Backend run on the real robosoa runtime (inproc and zmq), and the
Player-style code is compiled syntax-only against the Player stand-in header. In every run
the GUI's commands reach the Backend remapped by Pragmatics, and the Backend's status comes
back to the GUI remapped into an operator report.
"""

from __future__ import annotations

import json
import math
import os
import re
import select
import shutil
import subprocess
import sys
import tomllib
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

from tests.robosoa.procs import Proc, free_port, tcp_location

REPO = Path(__file__).resolve().parents[2]
STUDY = REPO / "fixtures" / "study"
PRAGMATICS = STUDY / "pragmatics"
STAND_IN = STUDY / "player_stub" / "pragmatics_extra.h"
STAGES = ("baseline", "first", "second")
APPROACHES = ("soa", "player", "p2p")
TIMEOUT = 30.0  # seconds any one child process may take
REPORT = re.compile(r"^(drove|turned|stopped); now at \((-?[\d.]+), (-?[\d.]+)\) "
                    r"facing (-?\d+) degrees$")


@dataclass(frozen=True, slots=True)
class Expect:
    """One GUI command and the report it must produce (verb, x, y, heading in degrees)."""

    command: str
    verb: str
    x: float
    y: float
    degrees: int


DRIVE = (Expect("drive 2", "drove", 2.0, 0.0, 0),)
TURNS = (Expect("turn left 90", "turned", 2.0, 0.0, 90), Expect("drive 1", "drove", 2.0, 1.0, 90),
         Expect("turn right 45", "turned", 2.0, 1.0, 45))
STOP = (Expect("stop", "stopped", 2.0, 1.0, 45),)
SCENARIO = {"baseline": DRIVE, "first": DRIVE + TURNS, "second": DRIVE + TURNS + STOP}
# the command the next stage adds: the GUI of this stage cannot send it yet
NOT_YET = {"baseline": "turn left 90", "first": "stop"}
# messages each stage's Player interfaces carry (CMD/DATA subtypes)
PLAYER_MESSAGES = {
    "baseline": {"muripraginterf": {"DRIVE"}, "muribackendinterf": {"TRANSLATE", "STATUS"}},
    "first": {"muripraginterf": {"DRIVE", "TURN"},
              "muribackendinterf": {"TRANSLATE", "ROTATE", "STATUS"}},
    "second": {"muripraginterf": {"DRIVE", "TURN", "STOP"},
               "muribackendinterf": {"TRANSLATE", "ROTATE", "HALT", "STATUS"}},
}
PLAYER_HEADERS = ("libplayerc/playerc.h", "libplayercore/playercore.h",
                  "libplayerinterface/player.h", "libplayerinterface/functiontable.h")


def stage_dir(approach: str, stage: str) -> Path:
    return PRAGMATICS / approach / stage


def commands(stage: str) -> list[str]:
    """The stage's scenario, then the command only a later stage offers (if any)."""
    lines = [e.command for e in SCENARIO[stage]]
    return [*lines, NOT_YET[stage]] if stage in NOT_YET else lines


def check_gui_output(stage: str, status: int, lines: list[str]) -> None:
    """Every command came back as the remapped report; a later stage's command was refused."""
    expected = SCENARIO[stage]
    assert len(lines) == len(expected) + (stage in NOT_YET), lines
    for expect, line in zip(expected, lines, strict=False):
        found = REPORT.match(line)
        assert found, f"{expect.command!r}: not a report: {line!r}"
        verb, x, y, degrees = found.groups()
        assert verb == expect.verb, line
        assert math.isclose(float(x), expect.x, abs_tol=0.01), line
        assert math.isclose(float(y), expect.y, abs_tol=0.01), line
        assert int(degrees) == expect.degrees, line
    if stage in NOT_YET:
        assert lines[-1] == f"error: cannot understand '{NOT_YET[stage]}'"
        assert status != 0
    else:
        assert status == 0


# ---- manifests and completeness -----------------------------------------------------------

def _matches_files(root: Path, glob: str) -> bool:
    """Whether a manifest glob (a trailing ``/**`` means everything inside) names a file."""
    pattern = glob[:-3] + "/**/*" if glob.endswith("/**") else glob
    return any(path.is_file() for path in root.glob(pattern))


@pytest.mark.parametrize("approach", APPROACHES)
def test_manifest_parses_and_names_existing_stages(approach: str) -> None:
    manifest = tomllib.loads((PRAGMATICS / approach / "manifest.toml").read_text("utf-8"))
    assert (manifest["subject"], manifest["approach"]) == ("pragmatics", approach)
    assert tuple(manifest["stages"]) == STAGES
    assert list(manifest["locations"]) == ["new", "framework", "base"]
    for stage in manifest["stages"]:
        root = stage_dir(approach, stage)
        assert root.is_dir()
        for location, globs in manifest["locations"].items():
            for glob in globs:
                assert _matches_files(root, glob), f"{stage}: {location} {glob} matches nothing"
        for glob in manifest["exclude"]["paths"]:
            assert _matches_files(root, glob), f"{stage}: exclude {glob} matches nothing"


@pytest.mark.parametrize("stage", STAGES)
def test_new_code_is_the_same_for_player_and_p2p(stage: str) -> None:
    """The Backend capability and the Pragmatics mapping are reached unchanged by both."""
    for folder in ("backend", "pragmatics"):
        texts = {a: {p.name: p.read_bytes() for p in (stage_dir(a, stage) / folder).iterdir()}
                 for a in ("player", "p2p")}
        assert texts["player"] == texts["p2p"], folder


# ---- Player: compiled syntax-only against the stand-in header -----------------------------

@pytest.fixture(scope="module")
def player_includes(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An include folder mapping Player's header paths onto the stand-in header."""
    root = tmp_path_factory.mktemp("player-includes")
    for header in PLAYER_HEADERS:
        path = root / header
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(f'#include "{STAND_IN}"\n', encoding="utf-8")
    return root


def _defined_messages(definition: str) -> set[str]:
    return set(re.findall(r"message\s*\{\s*(?:CMD|DATA),\s*(\w+),", definition))


@pytest.mark.parametrize("stage", STAGES)
def test_player_generated_headers_are_marked_and_match_definitions(stage: str) -> None:
    for definition in sorted((stage_dir("player", stage) / "interfaces").glob("*/*.def")):
        header = definition.with_name(f"{definition.stem}_interface.h").read_text("utf-8")
        first = header.splitlines()[0]
        assert first.startswith("/* @generated") and "do not edit" in first
        messages = _defined_messages(definition.read_text("utf-8"))
        prefix = f"PLAYER_{definition.stem.upper()}_"
        generated = set(re.findall(rf"#define {prefix}(?:CMD|DATA)_(\w+) ", header))
        assert generated == messages, definition
        wanted = PLAYER_MESSAGES[stage].get(definition.stem)
        assert wanted is None or messages == wanted, (definition.stem, messages)


@pytest.mark.skipif(shutil.which("gcc") is None or shutil.which("g++") is None,
                    reason="needs gcc and g++")
@pytest.mark.parametrize("stage", STAGES)
def test_player_stage_compiles_against_the_player_api(stage: str, player_includes: Path) -> None:
    root = stage_dir("player", stage)
    sources = sorted(root.rglob("*.c")) + sorted(root.rglob("*.cc"))
    assert len(sources) == 11  # 3 proxies, 3 drivers, 3 clients, motion, remap
    for source in sources:
        compiler = ["g++"] if source.suffix == ".cc" else ["gcc", "-std=c99"]
        done = subprocess.run([*compiler, "-fsyntax-only", "-Wall", "-Wextra", "-Werror",
                               "-I", str(player_includes), str(source)],
                              capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, f"{source}:\n{done.stderr}"


# ---- P2P: compiled with the system cc, run over 127.0.0.1 -----------------------------------

def _compile(output: Path, *sources: Path) -> None:
    done = subprocess.run(["cc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-o", str(output),
                           *map(str, sources), "-lm"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr


@pytest.fixture
def children() -> Iterator[list[subprocess.Popen[str]]]:
    """Background processes of one test, terminated (then killed) at its end."""
    started: list[subprocess.Popen[str]] = []
    yield started
    for child in started:
        if child.poll() is None:
            child.terminate()
            try:
                child.wait(timeout=5)
            except subprocess.TimeoutExpired:
                child.kill()
                child.wait(timeout=5)
        if child.stdout is not None:
            child.stdout.close()


def _start_server(args: list[str], env: dict[str, str], log: Path,
                  children: list[subprocess.Popen[str]]) -> None:
    """Start a P2P component and wait until it says it is listening."""
    with log.open("w") as errors:
        child = subprocess.Popen(args, env=env, stdout=subprocess.PIPE, stderr=errors, text=True)
    children.append(child)
    assert child.stdout is not None
    ready, _, _ = select.select([child.stdout], [], [], TIMEOUT)
    line = child.stdout.readline() if ready else ""
    assert "waiting" in line, f"{args[0]} did not start: {log.read_text()}"


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
@pytest.mark.parametrize("stage", STAGES)
def test_p2p_stage_remaps_commands_and_status(stage: str, tmp_path: Path,
                                               children: list[subprocess.Popen[str]]) -> None:
    root = stage_dir("p2p", stage)
    backend, prag, gui = tmp_path / "muri-backend", tmp_path / "muri-prag", tmp_path / "gui-prag"
    _compile(backend, root / "muri-backend.c", root / "backend" / "motion.c")
    _compile(prag, root / "muri-prag.c", root / "pragmatics" / "remap.c")
    _compile(gui, root / "gui-prag.c")
    env = {**os.environ, "MURI_BACKEND_PORT": str(free_port()),
           "MURI_PRAG_PORT": str(free_port()), "MURI_GUI_PORT": str(free_port()),
           "MURI_PRAG_HOST": "127.0.0.1", "MURI_PEER_HOST": "127.0.0.1",
           "MURI_REPLY_TIMEOUT": "10"}
    _start_server([str(backend)], env, tmp_path / "backend.log", children)
    _start_server([str(prag)], env, tmp_path / "prag.log", children)
    done = subprocess.run([str(gui)], input="\n".join(commands(stage)) + "\n", env=env,
                          capture_output=True, text=True, timeout=TIMEOUT)
    check_gui_output(stage, done.returncode, done.stdout.splitlines())


# ---- SOA: GUI, router and Backend on the real robosoa runtime ------------------------------

# Runs in a child process so that each stage's modules are imported fresh; the three
# components each hold their own connection to the in-process bus.
SOA_INPROC = """
import io, json, sys
stage, lines = sys.argv[1], json.loads(sys.argv[2])
sys.path.insert(0, stage)
import robosoa
from robosoa.router import Router
import gui
from backend.motion import MotionBase
from backend_app import RobotBackend
from muri_soa.backend_messages import BackendMessages
from muri_soa.gui_messages import GuiMessages
from muri_soa.service_utilities import PRAGMATICS_SERVICE
backend_bus, router_bus, gui_bus = (robosoa.connect("inproc") for _ in range(3))
backend = RobotBackend(MotionBase())
backend.messages = BackendMessages(backend_bus, backend)
router = Router.from_file(stage + "/pragmatics/rules.toml").attach(router_bus,
                                                                   PRAGMATICS_SERVICE)
messages = GuiMessages(gui_bus)
out = io.StringIO()
failures = gui.run(messages, lines, out, 10.0)
messages.close(); router.close(); backend.messages.close()
for bus in (gui_bus, router_bus, backend_bus):
    bus.close()
print(json.dumps({"failures": failures, "lines": out.getvalue().splitlines()}))
"""


def _soa_env() -> dict[str, str]:
    env = {**os.environ, "PYTHONPATH": str(REPO)}
    env.pop("MURI_BUS", None)
    return env


@pytest.mark.parametrize("stage", STAGES)
def test_soa_stage_on_inproc_bus(stage: str) -> None:
    done = subprocess.run([sys.executable, "-c", SOA_INPROC, str(stage_dir("soa", stage)),
                           json.dumps(commands(stage))], capture_output=True, text=True,
                          timeout=TIMEOUT, env=_soa_env())
    assert done.returncode == 0, done.stderr[-3000:]
    result = json.loads(done.stdout.splitlines()[-1])
    check_gui_output(stage, 2 if result["failures"] else 0, result["lines"])


@pytest.mark.parametrize("stage", STAGES)
def test_soa_stage_on_zmq_bus(stage: str) -> None:
    """Location service, router, Backend and GUI as four processes over ZeroMQ."""
    root = stage_dir("soa", stage)
    location, url = tcp_location()
    started: list[Proc] = [location]
    try:
        router = Proc([sys.executable, "-m", "robosoa", "route", str(root / "pragmatics" /
                       "rules.toml"), "--service", "muri.pragmatics",
                       "--location", url.removeprefix("zmq://")])
        started.append(router)
        router.wait_line("router muri.pragmatics running", timeout=TIMEOUT)
        backend = Proc([sys.executable, str(root / "backend_app.py"), "--bus", url])
        started.append(backend)
        backend.wait_line("backend ready", timeout=TIMEOUT)
        done = subprocess.run([sys.executable, str(root / "gui.py"), "--bus", url,
                               "--timeout", "10"], input="\n".join(commands(stage)) + "\n",
                              capture_output=True, text=True, timeout=TIMEOUT, env=_soa_env())
        check_gui_output(stage, done.returncode, done.stdout.splitlines())
    finally:
        for proc in reversed(started):
            proc.stop()
