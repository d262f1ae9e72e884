"""The World Database study subject (Hestand 2011, ch. 7): every stage is complete and runs.

Real runs only: the P2P server and client are compiled and talk over 127.0.0.1, the SOA
provider and client run on the real robosoa runtime (inproc and zmq), and the Player-style
code is parsed and compiled syntax-only against the Player stand-in headers.
"""

from __future__ import annotations

import json
import os
import queue
import shutil
import socket
import sqlite3
import subprocess
import sys
import threading
import time
import tomllib
import xml.etree.ElementTree as ET
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
STUDY = REPO / "fixtures" / "study"
WDB = STUDY / "wdb"
PLAYER_STUB = STUDY / "player_stub"
STAGES = ("baseline", "first", "second")
APPROACHES = ("soa", "player", "p2p")
OPERATIONS = {"baseline": ("query",), "first": ("query", "update"),
              "second": ("query", "update", "expire")}
WDB_PROGRAMS = {"query": "wdb_query.py", "update": "wdb_update.py", "expire": "wdb_expire.py"}
STAGE_FILES = {
    "soa": ("client/wdb_client.py", "proxy/data_rep.py", "proxy/service_utilities.py",
            "service/data_service_main.py"),
    "player": ("CMakeLists.txt", "interface/160_wdbinterf.def", "interface/wdbinterf_client.h",
               "interface/wdbinterf_client.c", "driver/wdbinterf_driver.cc", "driver/wdb.cfg",
               "client/wdb_client.c", "generated/wdbinterf_interface.h",
               "generated/wdbinterf_xdr.h"),
    "p2p": ("server/wdb-server.c", "client/wdb-client.c"),
}
TIMEOUT = 20.0  # seconds any one child process may take

# world seeded before every run: name -> (type, x, y, theta, timestamp)
SEED = {"rock-1": ("rock", 1.0, 2.0, 0.5, 10.0), "rock-2": ("rock", 4.0, 5.0, 1.0, 20.0),
        "tree-1": ("tree", 7.0, 8.0, 0.0, 5.0)}


@dataclass(frozen=True, slots=True)
class Step:
    """One client call: the operation, its XML request, and a check on the XML result."""

    operation: str
    request: str
    check: Callable[[ET.Element], None]


def _names(result: ET.Element) -> list[str]:
    return [obj.get("name", "") for obj in result.iter("object")]


def _pose_x(result: ET.Element, name: str) -> float:
    pose = result.find(f"object[@name='{name}']/pose")
    assert pose is not None, f"{name} missing from result"
    return float(pose.get("x", "nan"))


def _check_first_query(r: ET.Element) -> None:
    assert (r.get("status"), r.get("count"), _names(r)) == ("ok", "2", ["rock-2", "rock-1"])
    assert _pose_x(r, "rock-1") == 1.0


def _check_update(r: ET.Element) -> None:
    assert (r.get("status"), r.get("inserted"), r.get("updated")) == ("ok", "1", "1")


def _check_moved(r: ET.Element) -> None:
    assert (r.get("count"), _names(r)) == ("2", ["rock-1", "rock-2"])
    assert _pose_x(r, "rock-1") == 1.5


def _check_expire(r: ET.Element) -> None:
    assert (r.get("status"), r.get("removed"), _names(r)) == ("ok", "2", ["rock-2", "tree-1"])


def _check_left(r: ET.Element) -> None:
    assert (r.get("count"), _names(r)) == ("2", ["rock-1", "crater-1"])


UPDATE = ('<update><object name="rock-1" type="rock" timestamp="30"><pose x="1.5" y="2.5" '
          'theta="0.25"/></object><object name="crater-1" type="crater" timestamp="25">'
          '<pose x="9" y="9"/></object></update>')
STEPS = (Step("query", '<query type="rock"/>', _check_first_query),
         Step("update", UPDATE, _check_update),
         Step("query", '<query type="rock"/>', _check_moved),
         Step("expire", '<expire before="22"/>', _check_expire),
         Step("query", "<query/>", _check_left))
# each stage runs the steps its operations allow: query; + update, query; + expire, query
SCENARIO = {"baseline": STEPS[:1], "first": STEPS[:3], "second": STEPS}
# an operation the stage does not offer yet, which every approach must refuse
MISSING = {"baseline": "update", "first": "expire"}

Outcome = tuple[int, str]  # client exit status, XML result text


def seed_world(stage: Path, db: Path) -> None:
    """A fresh world database (schema made by the stage's own WDB query program)."""
    subprocess.run([sys.executable, str(stage / "wdb" / "wdb_query.py"), "--db", str(db)],
                   input="<query/>", capture_output=True, text=True, check=True, timeout=TIMEOUT)
    with sqlite3.connect(db) as conn:
        conn.executemany("INSERT INTO objects (name, type, x, y, theta, timestamp) "
                         "VALUES (?, ?, ?, ?, ?, ?)", [(k, *v) for k, v in SEED.items()])
    conn.close()


def check_outcomes(stage: str, outcomes: list[Outcome]) -> None:
    """Every step of the stage's scenario succeeded with the expected XML result."""
    assert len(outcomes) == len(SCENARIO[stage])
    for step, (status, text) in zip(SCENARIO[stage], outcomes, strict=True):
        assert status == 0, f"{step.operation} exited {status}: {text}"
        result = ET.fromstring(text)
        assert (result.tag, result.get("operation")) == ("result", step.operation)
        step.check(result)


def write_requests(tmp: Path, steps: tuple[Step, ...]) -> list[Path]:
    """The request documents of the steps, as files."""
    paths = []
    for number, step in enumerate(steps):
        path = tmp / f"request-{number}-{step.operation}.xml"
        path.write_text(step.request, encoding="utf-8")
        paths.append(path)
    return paths


def free_port() -> int:
    """A TCP port on 127.0.0.1 that was free a moment ago."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        sock.bind(("127.0.0.1", 0))
        return int(sock.getsockname()[1])


class Proc:
    """A background child in its own session; its stdout lines are read on a thread."""

    def __init__(self, args: list[str], cwd: Path, env: dict[str, str], log: Path) -> None:
        self.args = args
        self._log = log.open("w")
        self.popen = subprocess.Popen(args, cwd=cwd, env=env, stdout=subprocess.PIPE,
                                      stderr=self._log, text=True, start_new_session=True)
        self.lines: queue.Queue[str] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.popen.stdout is not None
        for line in self.popen.stdout:
            self.lines.put(line)

    def wait_line(self, text: str, timeout: float = TIMEOUT) -> None:
        """Block until a stdout line contains ``text``; fail with the child's stderr."""
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            try:
                if text in self.lines.get(timeout=0.1):
                    return
            except queue.Empty:
                if self.popen.poll() is not None:
                    break
        self._log.flush()
        log = Path(self._log.name).read_text()
        raise AssertionError(f"{self.args} never printed {text!r}; stderr: {log[-2000:]}")

    def stop(self) -> None:
        """SIGTERM to the child's process group (it and its forks), SIGKILL if it lingers."""
        if self.popen.poll() is None:
            os.killpg(self.popen.pid, 15)
            try:
                self.popen.wait(timeout=5)
            except subprocess.TimeoutExpired:
                os.killpg(self.popen.pid, 9)
                self.popen.wait(timeout=5)
        self._log.close()


@pytest.fixture
def procs() -> Iterator[list[Proc]]:
    """Background processes of one test, all stopped at its end."""
    started: list[Proc] = []
    yield started
    for proc in reversed(started):
        proc.stop()


def stage_dir(approach: str, stage: str) -> Path:
    """The snapshot folder of one stage of one approach."""
    return WDB / approach / stage


# ---- manifests and completeness -----------------------------------------------------------

def _matches_files(root: Path, glob: str) -> bool:
    """Whether a manifest glob (a trailing ``/**`` means everything inside) names a file."""
    pattern = glob[:-3] + "/**/*" if glob.endswith("/**") else glob
    return any(path.is_file() for path in root.glob(pattern))


@pytest.mark.parametrize("approach", APPROACHES)
def test_manifest_parses_and_names_complete_stages(approach: str) -> None:
    manifest = tomllib.loads((WDB / approach / "manifest.toml").read_text(encoding="utf-8"))
    assert (manifest["subject"], manifest["approach"]) == ("wdb", approach)
    assert tuple(manifest["stages"]) == STAGES
    assert list(manifest["locations"]) == ["new", "framework", "base"]
    for stage in manifest["stages"]:
        root = stage_dir(approach, stage)
        for name in STAGE_FILES[approach]:
            assert (root / name).is_file(), f"{approach}/{stage} lacks {name}"
        programs = sorted(p.name for p in (root / "wdb").glob("wdb_*.py"))
        expected = sorted(["wdb_store.py", *(WDB_PROGRAMS[op] for op in OPERATIONS[stage])])
        assert programs == expected
        for location, globs in manifest["locations"].items():
            for glob in globs:
                assert _matches_files(root, glob), f"{location} {glob} matches nothing"


@pytest.mark.parametrize("stage", STAGES)
def test_new_code_is_the_same_in_every_approach(stage: str) -> None:
    """The WDB programs are the one new capability, reached by each approach unchanged."""
    texts = {a: {p.name: p.read_bytes() for p in (stage_dir(a, stage) / "wdb").iterdir()
                 if p.is_file()} for a in APPROACHES}
    assert texts["soa"] == texts["player"] == texts["p2p"]


def test_generated_code_is_marked_and_excluded() -> None:
    manifest = tomllib.loads((WDB / "player" / "manifest.toml").read_text(encoding="utf-8"))
    assert "generated/**" in manifest["exclude"]["paths"]
    for stage in STAGES:
        for path in (stage_dir("player", stage) / "generated").iterdir():
            first = path.read_text(encoding="utf-8").splitlines()[0]
            assert first.startswith("/* @generated") and "do not edit" in first, path


# ---- P2P: compiled with the system cc, run over 127.0.0.1 -----------------------------------

def _compile(source: Path, output: Path) -> None:
    done = subprocess.run(["cc", "-Wall", "-Wextra", "-Werror", "-o", str(output), str(source)],
                          capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr


def _python3_on_path(tmp: Path) -> str:
    """A PATH whose python3 is this interpreter (the servers run the WDB programs with it)."""
    bindir = tmp / "bin"
    bindir.mkdir(exist_ok=True)
    (bindir / "python3").symlink_to(sys.executable)
    return f"{bindir}{os.pathsep}{os.environ.get('PATH', '')}"


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
@pytest.mark.parametrize("stage", STAGES)
def test_p2p_stage_serves_every_operation(stage: str, tmp_path: Path,
                                          procs: list[Proc]) -> None:
    root = stage_dir("p2p", stage)
    server, client = tmp_path / "wdb-server", tmp_path / "wdb-client"
    _compile(root / "server" / "wdb-server.c", server)
    _compile(root / "client" / "wdb-client.c", client)
    db = tmp_path / "world.db"
    seed_world(root, db)
    port = str(free_port())
    env = {**os.environ, "WDB_DIR": str(root / "wdb"), "WDB_DATABASE": str(db),
           "PATH": _python3_on_path(tmp_path)}
    env.pop("WDB_PORT", None)
    procs.append(Proc([str(server), "-p", port, "-b", "127.0.0.1"], tmp_path, env,
                      tmp_path / "server.log"))
    procs[-1].wait_line("waiting for connections")

    def call(operation: str, request: Path) -> Outcome:
        args = [str(client), "-p", port, "127.0.0.1", str(request)]
        if stage != "baseline":  # the operation line of the protocol came with the 2nd message
            args.insert(-1, operation)
        done = subprocess.run(args, capture_output=True, text=True, timeout=TIMEOUT)
        return done.returncode, done.stdout

    requests = write_requests(tmp_path, SCENARIO[stage])
    check_outcomes(stage, [call(s.operation, r) for s, r in zip(SCENARIO[stage], requests,
                                                                  strict=True)])
    if stage == "first":  # the baseline protocol carries no operation name at all
        status, text = call(MISSING[stage], requests[0])
        assert status == 1 and ET.fromstring(text).get("status") == "error"


# ---- Player: parsed and compiled syntax-only against the stand-in headers ----------------

def _parses_cleanly(path: Path, language: str) -> bool:
    """Whether tree-sitter parses the file without an error node."""
    import tree_sitter
    import tree_sitter_c
    import tree_sitter_cpp

    grammar = tree_sitter_c.language() if language == "c" else tree_sitter_cpp.language()
    parser = tree_sitter.Parser(tree_sitter.Language(grammar))
    return not parser.parse(path.read_bytes()).root_node.has_error


@pytest.mark.skipif(shutil.which("gcc") is None or shutil.which("g++") is None,
                    reason="needs gcc and g++")
@pytest.mark.parametrize("stage", STAGES)
def test_player_stage_compiles_against_the_player_api(stage: str) -> None:
    root = stage_dir("player", stage)
    includes = ["-I", str(PLAYER_STUB), "-I", str(root / "generated"),
                "-I", str(root / "interface")]
    flags = ["-fsyntax-only", "-Wall", "-Wextra", "-Werror"]
    c_files = [root / "interface" / "wdbinterf_client.c", root / "client" / "wdb_client.c"]
    cc_file = root / "driver" / "wdbinterf_driver.cc"
    for path in c_files:
        assert _parses_cleanly(path, "c"), path
        done = subprocess.run(["gcc", *flags, *includes, str(path)], capture_output=True,
                              text=True, timeout=60)
        assert done.returncode == 0, done.stderr
    assert _parses_cleanly(cc_file, "cpp")
    done = subprocess.run(["g++", *flags, *includes, str(cc_file)], capture_output=True,
                          text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    # one request subtype, client proxy call and driver branch per operation of the stage
    proxy = (root / "interface" / "wdbinterf_client.c").read_text(encoding="utf-8")
    driver = cc_file.read_text(encoding="utf-8")
    for operation in OPERATIONS[stage]:
        assert f"PLAYER_WDBINTERF_REQ_{operation.upper()}" in proxy
        assert f'"{WDB_PROGRAMS[operation]}"' in driver
    assert driver.count("Message::MatchMessage") == len(OPERATIONS[stage])


# ---- SOA: provider and client on the real robosoa runtime ---------------------------------

INPROC_RUN = """
import json, sys
stage, db, steps = sys.argv[1], sys.argv[2], json.loads(sys.argv[3])
sys.path.insert(0, stage)
import robosoa
from client import wdb_client
from service import data_service_main as provider
with robosoa.connect("inproc") as bus:
    provider.serve(bus, provider.DataService(stage + "/wdb", db))
    codes = [wdb_client.main(["--bus", "inproc", op, req, res]) for op, req, res in steps]
print(json.dumps(codes))
"""


def _soa_env() -> dict[str, str]:
    env = {**os.environ, "PYTHONPATH": str(REPO), "PYTHONDONTWRITEBYTECODE": "1"}
    env.pop("ROBOSOA_BUS", None)
    return env


@pytest.mark.slow
@pytest.mark.parametrize("stage", STAGES)
def test_soa_stage_on_inproc_bus(stage: str, tmp_path: Path) -> None:
    root = stage_dir("soa", stage)
    db = tmp_path / "world.db"
    seed_world(root, db)
    steps = list(SCENARIO[stage])
    if stage in MISSING:
        steps.append(Step(MISSING[stage], steps[0].request, lambda _r: None))
    requests = write_requests(tmp_path, tuple(steps))
    results = [r.with_suffix(".result.xml") for r in requests]
    plan = [[s.operation, str(q), str(r)] for s, q, r in zip(steps, requests, results,
                                                             strict=True)]
    done = subprocess.run([sys.executable, "-c", INPROC_RUN, str(root), str(db),
                           json.dumps(plan)], capture_output=True, text=True,
                          timeout=2 * TIMEOUT, env=_soa_env())
    assert done.returncode == 0, done.stderr
    codes = json.loads(done.stdout.splitlines()[-1])
    n = len(SCENARIO[stage])
    check_outcomes(stage, [(c, r.read_text(encoding="utf-8"))
                           for c, r in zip(codes[:n], results[:n], strict=True)])
    if stage in MISSING:
        assert codes[n] == 2 and "unknown" in done.stderr


@pytest.mark.slow
@pytest.mark.parametrize("stage", STAGES)
def test_soa_stage_on_zmq_bus(stage: str, tmp_path: Path, procs: list[Proc]) -> None:
    root = stage_dir("soa", stage)
    db = tmp_path / "world.db"
    seed_world(root, db)
    env = _soa_env()
    location = f"tcp://127.0.0.1:{free_port()}"
    bus = f"zmq://{location}"
    procs.append(Proc([sys.executable, "-c", "import sys; from robosoa.cli import main; "
                       "sys.exit(main())", "location", "--bind", location,
                       "--announce", "tcp://127.0.0.1:0"],
                      tmp_path, env, tmp_path / "location.log"))
    procs[-1].wait_line("location service")
    procs.append(Proc([sys.executable, "-m", "service.data_service_main", "--bus", bus,
                       "--db", str(db)], root, env, tmp_path / "provider.log"))
    procs[-1].wait_line("wdb service ready")

    def call(operation: str, request: Path) -> tuple[int, str, str]:
        done = subprocess.run([sys.executable, "-m", "client.wdb_client", "--bus", bus,
                               "--wait", "10", operation, str(request)], cwd=root, env=env,
                              capture_output=True, text=True, timeout=TIMEOUT)
        return done.returncode, done.stdout, done.stderr

    requests = write_requests(tmp_path, SCENARIO[stage])
    calls = [call(s.operation, r) for s, r in zip(SCENARIO[stage], requests, strict=True)]
    check_outcomes(stage, [(status, out) for status, out, _err in calls])
    if stage in MISSING:
        status, _out, err = call(MISSING[stage], requests[0])
        assert status == 2 and "unknown" in err
