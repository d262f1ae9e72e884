"""The MURI Pragmatics subjects as the thesis describes them (Hestand 2011, pp. 125-135): the
baseline wires GUI, Pragmatics and Backend with no domain messages, the first stage introduces
drive (-> translate) and its status, the second turn (-> rotate) and its status.

Real runs only: the SOA GUI, Pragmatics application and Backend run on the real robosoa
runtime (inproc and zmq). Each stage is also checked against the sentence it follows.
"""

from __future__ import annotations

import ast
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from archmetrics.study.manifest import load_manifest
from tests.robosoa.procs import Proc, free_port, tcp_location
from tests.study.test_pragmatics_subjects import DRIVE, REPORT, TURNS, Expect
from tests.study.test_wdb_subjects import Proc as ChildProc

REPO = Path(__file__).resolve().parents[2]
DESCRIBED = REPO / "fixtures" / "study" / "as-described" / "pragmatics"
STAGES = ("baseline", "first", "second")
TIMEOUT = 30.0  # seconds any one child process may take
# the stage's scenario: nothing at the baseline, then drive, then drive and turn
SCENARIO: dict[str, tuple[Expect, ...]] = {"baseline": (), "first": DRIVE,
                                           "second": DRIVE + TURNS}  # fmt: skip
NOT_YET = {"baseline": "drive 2", "first": "turn left 90", "second": "stop"}
# per stage, the messages each messaging component creates (one method, one bus.send each)
SENDS = {
    "baseline": {"GuiMessages": set(), "PragMessages": set(), "BackendMessages": set()},
    "first": {"GuiMessages": {"drive"}, "PragMessages": {"translate", "report"},
              "BackendMessages": {"translated"}},
    "second": {"GuiMessages": {"drive", "turn"}, "PragMessages": {"translate", "report", "rotate"},
               "BackendMessages": {"translated", "rotated"}},
}


def stage_dir(approach: str, stage: str) -> Path:
    return DESCRIBED / approach / stage


def commands(stage: str) -> list[str]:
    return [*(e.command for e in SCENARIO[stage]), NOT_YET[stage]]


def check_output(stage: str, status: int, lines: list[str]) -> None:
    """Every command of the stage came back as its report; the next stage's was refused."""
    expected = SCENARIO[stage]
    assert len(lines) == len(expected) + 1, lines
    for expect, line in zip(expected, lines, strict=False):
        found = REPORT.match(line)
        assert found, f"{expect.command!r}: not a report: {line!r}"
        verb, x, y, degrees = found.groups()
        assert verb == expect.verb, line
        assert math.isclose(float(x), expect.x, abs_tol=0.01), line
        assert math.isclose(float(y), expect.y, abs_tol=0.01), line
        assert int(degrees) == expect.degrees, line
    assert lines[-1] == f"error: cannot understand '{NOT_YET[stage]}'"
    assert status != 0


@pytest.mark.parametrize("approach", ["soa"])
def test_manifest_quotes_a_sentence_and_page_for_every_stage(approach: str) -> None:
    manifest = load_manifest(DESCRIBED / approach)
    assert (manifest.subject, manifest.variant) == ("pragmatics", "as-described")
    assert [f.stage for f in manifest.follows] == list(STAGES)
    assert all(125 <= f.page <= 135 for f in manifest.follows)


def _methods(path: Path, cls: str) -> dict[str, ast.FunctionDef]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == cls)
    return {n.name: n for n in found.body if isinstance(n, ast.FunctionDef)}


def _sends(method: ast.FunctionDef) -> int:
    return sum(isinstance(n, ast.Call) and isinstance(n.func, ast.Attribute)
               and n.func.attr == "send" for n in ast.walk(method))  # fmt: skip


@pytest.mark.parametrize("stage", STAGES)
def test_soa_messages_are_created_in_the_messaging_components(stage: str) -> None:
    """P. 132: "the commands and status updates are dynamically created in the messaging
    component": every command and status method creates and sends its own message, and the
    interface implementation of each component dispatches by message name."""
    root = stage_dir("soa", stage) / "muri_soa"
    files = {"GuiMessages": "gui_messages.py", "PragMessages": "prag_messages.py",
             "BackendMessages": "backend_messages.py"}
    for cls, file in files.items():
        methods = _methods(root / file, cls)
        sending = {name for name, m in methods.items() if _sends(m)}
        assert sending == SENDS[stage][cls], cls
        assert all(_sends(methods[name]) == 1 for name in sending)
    # p. 125: three request operations differing in their argument lists, one reply
    impl = _methods(root / "prag_messages.py", "PragPragmaticsImpl")
    assert {"request", "request_values", "request_text", "reply"} <= set(impl)
    # p. 126-127: the Pragmatics component is code, and its mapping is in the prag application
    assert not (stage_dir("soa", stage) / "pragmatics").exists()
    mapping = _methods(stage_dir("soa", stage) / "prag.py", "Pragmatics")
    assert set(mapping) - {"__init__"} == {
        "baseline": set(), "first": {"drive", "translated"},
        "second": {"drive", "translated", "turn", "rotated"}}[stage]


SOA_INPROC = """
import io, json, sys
stage, lines = sys.argv[1], json.loads(sys.argv[2])
sys.path.insert(0, stage)
import robosoa
import gui
import prag
from backend.motion import MotionBase
from backend_app import RobotBackend
from muri_soa.backend_messages import BackendMessages
from muri_soa.gui_messages import GuiMessages
from muri_soa.prag_messages import PragMessages
backend_bus, prag_bus, gui_bus = (robosoa.connect("inproc") for _ in range(3))
backend = RobotBackend(MotionBase())
backend.messages = BackendMessages(backend_bus, backend)
pragmatics = prag.Pragmatics()
pragmatics.messages = PragMessages(prag_bus, pragmatics)
messages = GuiMessages(gui_bus)
out = io.StringIO()
failures = gui.run(messages, lines, out, 10.0)
messages.close(); pragmatics.messages.close(); backend.messages.close()
for bus in (gui_bus, prag_bus, backend_bus):
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
                          timeout=TIMEOUT, env=_soa_env())  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    result = json.loads(done.stdout.splitlines()[-1])
    check_output(stage, 2 if result["failures"] else 0, result["lines"])


@pytest.mark.slow
@pytest.mark.parametrize("stage", STAGES)
def test_soa_stage_on_zmq_bus(stage: str) -> None:
    """Location service, Pragmatics, Backend and GUI as four processes over ZeroMQ."""
    root = stage_dir("soa", stage)
    location, url = tcp_location()
    started: list[Proc] = [location]
    try:
        pragmatics = Proc([sys.executable, str(root / "prag.py"), "--bus", url])
        started.append(pragmatics)
        pragmatics.wait_line("pragmatics ready", timeout=TIMEOUT)
        backend = Proc([sys.executable, str(root / "backend_app.py"), "--bus", url])
        started.append(backend)
        backend.wait_line("backend ready", timeout=TIMEOUT)
        done = subprocess.run([sys.executable, str(root / "gui.py"), "--bus", url,
                               "--timeout", "10"], input="\n".join(commands(stage)) + "\n",
                              capture_output=True, text=True, timeout=TIMEOUT, env=_soa_env())
        check_output(stage, done.returncode, done.stdout.splitlines())
    finally:
        for proc in reversed(started):
            proc.stop()


# ---- P2P: p. 120, 132, 135 ------------------------------------------------------------------

P2P_HANDLERS = {  # per stage: each component's handlers, one per message it sends or receives
    "baseline": {"muri-backend.c": [], "muri-prag.c": [], "gui-prag.c": []},
    "first": {"muri-backend.c": ["serve_translate"],
              "muri-prag.c": ["serve_drive", "serve_translated"],
              "gui-prag.c": ["send_drive", "await_drove"]},
    "second": {"muri-backend.c": ["serve_translate", "serve_rotate"],
               "muri-prag.c": ["serve_drive", "serve_translated", "serve_turn", "serve_rotated"],
               "gui-prag.c": ["send_drive", "await_drove", "send_turn", "await_turned"]},
}


def _c_function(text: str, name: str) -> str:
    start = text.index(f" {name}(")
    return text[start : text.index("\n}\n", start)]


@pytest.mark.parametrize("stage", STAGES)
def test_p2p_every_message_has_its_own_accept_recv_and_send(stage: str) -> None:
    """P. 132: "the addition of accept, recv, and send operations for each of the GUI,
    Pragmatics, and Backend components"."""
    root = stage_dir("p2p", stage)
    for file, handlers in P2P_HANDLERS[stage].items():
        text = (root / file).read_text(encoding="utf-8")
        for name in handlers:
            body = _c_function(text, name)
            calls = {"send": ("send(",), "await": ("accept(", "recv(")}.get(
                name.split("_")[0], ("accept(", "recv(", "send("))
            for call in calls:
                found = body.count(f" {call}") + body.count(f"({call}")
                assert found == 1, (file, name, call)
        for call in ("accept(", "recv("):
            receivers = [h for h in handlers if not h.startswith("send_")]
            assert text.count(f"{call}") == len(receivers), (file, call)


def _compile(output: Path, *sources: Path) -> None:
    done = subprocess.run(["cc", "-std=c99", "-Wall", "-Wextra", "-Werror", "-o", str(output),
                           *map(str, sources), "-lm"], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr


@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
@pytest.mark.parametrize("stage", STAGES)
def test_p2p_stage_remaps_commands_and_status(stage: str, tmp_path: Path) -> None:
    root = stage_dir("p2p", stage)
    backend, prag, gui = tmp_path / "muri-backend", tmp_path / "muri-prag", tmp_path / "gui-prag"
    _compile(backend, root / "muri-backend.c", root / "backend" / "motion.c")
    remap = [root / "pragmatics" / "remap.c"] if stage != "baseline" else []
    _compile(prag, root / "muri-prag.c", *remap)
    _compile(gui, root / "gui-prag.c")
    env = {**os.environ, "MURI_PORT_BASE": str(_free_port_block()), "MURI_PEER_HOST": "127.0.0.1",
           "MURI_REPLY_TIMEOUT": "10"}
    started: list[ChildProc] = []
    try:
        for program in (backend, prag):
            log = tmp_path / f"{program.name}.log"
            started.append(ChildProc([str(program)], tmp_path, env, log))
            started[-1].wait_line("waiting for messages", timeout=TIMEOUT)
        done = subprocess.run([str(gui)], input="\n".join(commands(stage)) + "\n", env=env,
                              capture_output=True, text=True, timeout=TIMEOUT)  # fmt: skip
        check_output(stage, done.returncode, done.stdout.splitlines())
    finally:
        for proc in reversed(started):
            proc.stop()


def _free_port_block() -> int:
    """A base port whose message offsets (0-1, 10-11, 20-21, 30-31) were all free just now."""
    import socket

    for _ in range(50):
        base = free_port()
        if base + 31 > 65535:
            continue
        ports = [base + offset for offset in (0, 1, 10, 11, 20, 21, 30, 31)]
        try:
            socks = []
            for port in ports:
                sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
                socks.append(sock)
                sock.bind(("127.0.0.1", port))
            return base
        except OSError:
            continue
        finally:
            for sock in socks:
                sock.close()
    raise AssertionError("no free block of ports")
