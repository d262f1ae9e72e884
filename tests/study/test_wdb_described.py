"""The World Database subjects as the thesis describes them (Hestand 2011, pp. 114-123): every
stage follows its quoted sentence, and builds and runs as the idiomatic subjects do.

Real runs only: the P2P server and client are compiled and talk over 127.0.0.1, the SOA
provider and client run on the real robosoa runtime, and the Player code is parsed and
compiled syntax-only against the Player stand-in headers. Each stage is also checked against
the sentence it follows (docs/study.md, "As described").
"""

from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from archmetrics.study.manifest import load_manifest
from tests.study.test_wdb_subjects import (
    OPERATIONS,
    PLAYER_STUB,
    SCENARIO,
    STAGES,
    STEPS,
    TIMEOUT,
    WDB_PROGRAMS,
    Outcome,
    Proc,
    _compile,
    _parses_cleanly,
    _python3_on_path,
    _soa_env,
    check_outcomes,
    free_port,
    procs,  # noqa: F401  (the fixture)
    seed_world,
    stage_dir,
    write_requests,
)

REPO = Path(__file__).resolve().parents[2]
DESCRIBED = REPO / "fixtures" / "study" / "as-described" / "wdb"
APPROACHES = ("soa", "player", "p2p")


def described(approach: str, stage: str) -> Path:
    return DESCRIBED / approach / stage


@pytest.mark.parametrize("approach", APPROACHES)
def test_manifest_quotes_a_sentence_and_page_for_every_stage(approach: str) -> None:
    manifest = load_manifest(DESCRIBED / approach)
    assert (manifest.subject, manifest.approach, manifest.variant) == (
        "wdb", approach, "as-described")  # fmt: skip
    assert [f.stage for f in manifest.follows] == list(STAGES)
    assert all(len(f.sentence) > 40 and 90 <= f.page <= 145 for f in manifest.follows)


@pytest.mark.parametrize("stage", STAGES)
def test_new_code_is_the_idiomatic_subjects_new_code(stage: str) -> None:
    """The control: the WDB programs are byte-identical to the idiomatic variant's."""
    idiomatic = {p.name: p.read_bytes() for p in (stage_dir("soa", stage) / "wdb").iterdir()}
    for approach in APPROACHES:
        ours = {p.name: p.read_bytes() for p in (described(approach, stage) / "wdb").iterdir()}
        assert ours == idiomatic, approach


# ---- Player: p. 96, 120, 122 ----------------------------------------------------------------


def _function(text: str, name: str) -> str:
    """The body of one C function, from its signature to the closing brace in column 0."""
    match = re.search(rf"^\w[^\n;]*\b{name}\(.*?^}}", text, re.S | re.M)
    assert match, name
    return match.group(0)


@pytest.mark.skipif(shutil.which("gcc") is None or shutil.which("g++") is None,
                    reason="needs gcc and g++")
@pytest.mark.parametrize("stage", STAGES)
def test_player_stage_compiles_and_follows_its_sentences(stage: str) -> None:
    root = described("player", stage)
    includes = ["-I", str(PLAYER_STUB), "-I", str(root / "generated"),
                "-I", str(root / "interface")]
    flags = ["-fsyntax-only", "-Wall", "-Wextra", "-Werror"]
    sources = [(root / "interface" / "wdbinterf_client.c", "gcc", "c"),
               (root / "client" / "wdb_client.c", "gcc", "c"),
               (root / "driver" / "wdbinterf_driver.cc", "g++", "cpp")]
    for path, compiler, language in sources:
        assert _parses_cleanly(path, language), path
        done = subprocess.run([compiler, *flags, *includes, str(path)], capture_output=True,
                              text=True, timeout=60)
        assert done.returncode == 0, done.stderr
    proxy = (root / "interface" / "wdbinterf_client.c").read_text(encoding="utf-8")
    driver = (root / "driver" / "wdbinterf_driver.cc").read_text(encoding="utf-8")
    # p. 120: "a new interface implementation in the client proxy and the driver code": each
    # proxy function makes its own request, each message has its own block in the driver
    assert proxy.count("playerc_client_request(") == len(OPERATIONS[stage])
    assert driver.count("Message::MatchMessage(") == len(OPERATIONS[stage])
    blocks = driver.split("if (Message::MatchMessage(")[1:]
    for operation, block in zip(OPERATIONS[stage], blocks, strict=True):
        constant = f"PLAYER_WDBINTERF_REQ_{operation.upper()}"
        assert constant in _function(proxy, f"wdbinterf_{operation}")
        # p. 122: "the same for each message except for the defined constant"
        generic = block.replace(constant, "C").replace(operation, "op")
        first = blocks[0].replace("PLAYER_WDBINTERF_REQ_QUERY", "C").replace("query", "op")
        assert generic.split("  return -1;")[0].rstrip() == first.split("  return -1;")[0].rstrip()
        assert f'"{WDB_PROGRAMS[operation]}"' in block


def test_player_counts_the_generated_plugin_header() -> None:
    """P. 96: the definition is copied into the generated plugin header, which is counted."""
    manifest = load_manifest(DESCRIBED / "player")
    assert not manifest.exclude_generated
    assert "interface/*.def" in manifest.exclude
    assert not any("wdbinterf_interface" in glob for glob in manifest.exclude)


# ---- P2P: p. 115, 120, 123 ------------------------------------------------------------------


@pytest.mark.parametrize("stage", STAGES)
def test_p2p_every_message_has_its_own_accept_recv_and_send(stage: str) -> None:
    """P. 120: "each new message adds an accept, send, and recv operation"."""
    server = (described("p2p", stage) / "server" / "wdb-server.c").read_text(encoding="utf-8")
    for operation in OPERATIONS[stage]:
        handler = _function(server, f"serve_{operation}")
        for call in ("accept(", "recv(", "send("):
            assert handler.count(call) == 1, (operation, call)
    for call in ("accept(", "recv(", "send("):
        assert server.count(call) == len(OPERATIONS[stage]), call
    # p. 123: the protocol for function returns comes with the second message
    assert ('"status %d\\n"' in server) == (stage != "baseline")


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("cc") is None, reason="needs a C compiler")
@pytest.mark.parametrize("stage", STAGES)
def test_p2p_stage_serves_every_operation(stage: str, tmp_path: Path,
                                          procs: list[Proc]) -> None:  # noqa: F811
    root = described("p2p", stage)
    server, client = tmp_path / "wdb-server", tmp_path / "wdb-client"
    _compile(root / "server" / "wdb-server.c", server)
    _compile(root / "client" / "wdb-client.c", client)
    db = tmp_path / "world.db"
    seed_world(root, db)
    ports = [free_port()]
    while len(ports) < 3:  # message i listens on port + i
        ports = [free_port()]
        ports += [p for p in (ports[0] + 1, ports[0] + 2) if _free(p)]
    port = str(ports[0])
    env = {**os.environ, "WDB_DIR": str(root / "wdb"), "WDB_DATABASE": str(db),
           "PATH": _python3_on_path(tmp_path)}
    env.pop("WDB_PORT", None)
    procs.append(Proc([str(server), "-p", port, "-b", "127.0.0.1"], tmp_path, env,
                      tmp_path / "server.log"))
    procs[-1].wait_line("waiting for connections")

    def call(operation: str, request: Path) -> Outcome:
        args = [str(client), "-p", port, "127.0.0.1", str(request)]
        if stage != "baseline":  # with the second message, the client names the message
            args.insert(-1, operation)
        done = subprocess.run(args, capture_output=True, text=True, timeout=TIMEOUT)
        return done.returncode, done.stdout

    requests = write_requests(tmp_path, SCENARIO[stage])
    check_outcomes(stage, [call(s.operation, r) for s, r in zip(SCENARIO[stage], requests,
                                                                  strict=True)])
    if stage == "first":  # a message the stage does not offer yet is refused by the client
        status, text = call("expire", requests[0])
        assert (status, text) == (2, "")


def _free(port: int) -> bool:
    import socket

    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as sock:
        try:
            sock.bind(("127.0.0.1", port))
        except OSError:
            return False
    return True


# ---- SOA: p. 119, 122 -----------------------------------------------------------------------

INPROC_RUN = """
import json, sys
stage, db, requests, out = sys.argv[1:5]
sys.path.insert(0, stage)
import robosoa
from client import wdb_client
from service import data_service_main as provider
with robosoa.connect("inproc") as bus:
    provider.serve(bus, provider.DataService(stage + "/wdb", db))
    print(json.dumps(wdb_client.main(["--bus", "inproc", "--out", out, requests])))
"""


@pytest.mark.parametrize("stage", STAGES)
def test_soa_client_adds_two_sequential_lines_an_operation(stage: str) -> None:
    """P. 122: "two lines in the client (one to call the service, the other to read the
    results) and a single line in the service provider code to dispatch the request"."""
    client = (described("soa", stage) / "client" / "wdb_client.py").read_text(encoding="utf-8")
    calls = re.findall(r'^ +result = wdb.execute\("(\w+)", .*\n +su.write_document\(', client,
                       re.M)  # fmt: skip
    assert calls == list(OPERATIONS[stage])
    provider = (described("soa", stage) / "service" / "data_service_main.py").read_text(
        encoding="utf-8")  # fmt: skip
    for operation in OPERATIONS[stage]:
        assert f'    "{operation}": "{WDB_PROGRAMS[operation]}",\n' in provider


@pytest.mark.slow
@pytest.mark.parametrize("stage", STAGES)
def test_soa_stage_runs_every_operation_on_the_bus(stage: str, tmp_path: Path) -> None:
    root = described("soa", stage)
    db = tmp_path / "world.db"
    seed_world(root, db)
    requests, out = tmp_path / "requests", tmp_path / "results"
    requests.mkdir()
    out.mkdir()
    # the client runs each operation once, in order: query, update, expire
    steps = {s.operation: s for s in reversed(STEPS[:4])}
    for operation in OPERATIONS[stage]:
        (requests / f"{operation}.xml").write_text(steps[operation].request, encoding="utf-8")
    done = subprocess.run([sys.executable, "-c", INPROC_RUN, str(root), str(db), str(requests),
                           str(out)], capture_output=True, text=True, timeout=2 * TIMEOUT,
                          env=_soa_env())  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout.splitlines()[-1]) == 0
    for operation in OPERATIONS[stage]:
        result = ET.fromstring((out / f"{operation}.xml").read_text(encoding="utf-8"))
        assert (result.tag, result.get("operation")) == ("result", operation)
        steps[operation].check(result)
