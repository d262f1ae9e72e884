"""Three tiny approaches to one integration task, each a real git repository of three stages.

Like the thesis's WDB task in miniature: a base client, a framework and the new integration code
(``wdb/``), integrated the SOA way (a bus), the Player way (a message switch) and the P2P way
(sockets). Used by the chart tests to get real SeriesReport / CompareReport values.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from archmetrics.app.diff_options import DiffRequest
from archmetrics.app.series import SeriesRequest, run_compare
from archmetrics.config import Settings
from archmetrics.reports.model import CompareReport
from tests.gitrepo import GitRepo

STAGES = ("baseline", "first", "second")
APPROACHES = ("SOA", "Player", "P2P")

_SOA_BUS = """import robosoa


def open_bus(url):
    return robosoa.connect(url)


def call(bus, service, operation, payload):
    reply = bus.request(service, operation, payload)
    if reply.get("error"):
        raise RuntimeError(reply["error"])
    return reply
"""


def _ops(names: list[str], body: str) -> str:
    return "".join(body.format(op=name) for name in names)


def soa(ops: list[str]) -> dict[str, str]:
    service = "import robosoa\n\n\ndef serve(bus):\n    bus.provide('wdb', handle)\n\n\n"
    service += "def handle(message):\n    op = message.context['op']\n"
    service += "    return {'op': op, 'rows': run(op, message.payload)}\n\n\n"
    service += "def run(op, payload):\n    return [op, payload]\n"
    client = "from fw import bus as fw\n\n\ndef main(bus):\n    out = []\n"
    client += _ops(ops, "    out.append(fw.call(bus, 'wdb', '{op}', {{}}))\n")
    client += "    return out\n"
    return {"fw/bus.py": _SOA_BUS, "wdb/service.py": service, "app/client.py": client}


def player(ops: list[str]) -> dict[str, str]:
    driver = "MESSAGES = {}\n\n\ndef process(kind, data):\n"
    driver += _ops(ops, "    if kind == '{op}':\n        if not data:\n            return None\n"
                   "        return handle_{op}(data)\n")  # fmt: skip
    driver += "    return None\n"
    driver += _ops(ops, "\n\ndef handle_{op}(data):\n    return ['{op}', data]\n")
    framework = "def dispatch(handlers, kind, data):\n    for h in handlers:\n"
    framework += "        result = h(kind, data)\n        if result is not None:\n"
    framework += "            return result\n    return None\n"
    client = "from fw import server\nfrom wdb import driver\n\n\ndef main():\n    out = []\n"
    client += _ops(ops, "    out.append(server.dispatch([driver.process], '{op}', 1))\n")
    client += "    return out\n"
    return {"fw/server.py": framework, "wdb/driver.py": driver, "app/client.py": client}


def p2p(ops: list[str]) -> dict[str, str]:
    server = "import socket\n\n\ndef serve(port):\n    s = socket.socket()\n"
    server += "    s.bind(('127.0.0.1', port))\n    s.listen()\n"
    server += _ops(ops, "    conn, _ = s.accept()\n    data = conn.recv(1024)\n"
                   "    if not data:\n        conn.close()\n    else:\n"
                   "        conn.send(b'{op}:' + data)\n")  # fmt: skip
    client = "import socket\n\n\ndef main(port):\n    out = []\n"
    client += _ops(ops, "    c = socket.create_connection(('127.0.0.1', port))\n"
                   "    c.send(b'{op}')\n    out.append(c.recv(1024))\n")  # fmt: skip
    client += "    return out\n"
    return {"wdb/server.py": server, "app/client.py": client}


def build_repo(root: Path, make: Callable[[list[str]], dict[str, str]]) -> GitRepo:
    """A repository whose tags baseline, first, second hold 1, 2 and 3 operations."""
    repo = GitRepo(root)
    operations = ["query", "update", "delete"]
    for n, stage in enumerate(STAGES, start=1):
        repo.commit(stage, tag=stage, files=make(operations[:n]))
    return repo


def series_request(
    root: Path, stages: tuple[str, ...] = STAGES, labels: tuple[str, ...] = ()
) -> SeriesRequest:
    """Tags ``stages`` in order, labelled ``labels`` (default: the tags)."""
    diff = DiffRequest(root, "", "", Settings(), new=("wdb/**",), framework=("fw/**",))
    return SeriesRequest(diff, stages, labels or stages)


def build_study(folder: Path) -> CompareReport:
    """SOA, Player and P2P measured stage by stage by the real pipeline."""
    makers = {"SOA": soa, "Player": player, "P2P": p2p}
    for name, make in makers.items():
        build_repo(folder / name.lower(), make)
    return run_compare([(name, series_request(folder / name.lower())) for name in makers])
