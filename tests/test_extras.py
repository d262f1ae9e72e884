"""A CI-only install is the analyzer and its CLI: running `archmetrics diff` imports neither
pandas, matplotlib, pyzmq nor lxml, and whatever needs one of them says which extra brings
it. A module is made missing the way Python knows it: ``sys.modules[name] = None`` makes its
import raise ModuleNotFoundError, in a subprocess of its own."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from tests.gitrepo import GitRepo

EXTRAS = ("pandas", "matplotlib", "zmq", "lxml")


def _python(
    code: str, cwd: Path, blocked: tuple[str, ...] = ()
) -> subprocess.CompletedProcess[str]:
    prologue = "import sys\n" + "".join(f"sys.modules[{name!r}] = None\n" for name in blocked)
    return subprocess.run(
        [sys.executable, "-c", prologue + code], cwd=cwd, capture_output=True, text=True,
        timeout=300,
    )  # fmt: skip


def test_a_diff_through_the_cli_imports_no_extra(repo: GitRepo, tmp_path: Path) -> None:
    c_file = "int g(void) { return 0; }\n"
    repo.commit("v1", tag="v1", files={"a.py": "def f(a):\n    return a\n", "b.c": c_file})
    branchy = "def f(a):\n    if a:\n        return 1\n    return a\n"
    repo.commit("v2", tag="v2", files={"a.py": branchy})
    code = (
        "import archmetrics.cli\n"
        f"status = archmetrics.cli.main(['diff', '-C', {str(repo.root)!r}, '--base', 'v1',"
        " '--head', 'v2', '--format', 'json', '-q', '--no-cache', '-o', 'out.json',"
        " '--fail-on', 'vg(function) > 1'])\n"
        f"print(status, [m for m in {EXTRAS!r} if sys.modules.get(m) is not None])\n"
    )
    done = _python(code, tmp_path)
    assert done.stdout.strip() == "1 []", done.stderr  # the gate fails, nothing extra loaded
    assert json.loads((tmp_path / "out.json").read_text())["locations"]["total"]["added"] == 2
    blocked = _python(code, tmp_path, EXTRAS)  # and with them all missing, the same
    assert blocked.stdout.strip() == "1 []", blocked.stderr


def test_what_needs_an_extra_names_it(repo: GitRepo, tmp_path: Path) -> None:
    repo.commit("v1", files={"a.py": "x = 1\n"})
    frame = _python(f"import archmetrics.api\narchmetrics.api.scan({str(repo.root)!r})", tmp_path,
                    ("pandas",))  # fmt: skip
    assert "pip install 'archmetrics[api]'" in frame.stderr
    chart = _python(
        "import archmetrics.cli\n"
        f"sys.exit(archmetrics.cli.main(['diff', '-C', {str(repo.root)!r}, '--base', 'HEAD',"
        " '--head', 'HEAD', '--chart', 'c.png', '-q']))", tmp_path, ("matplotlib",),
    )  # fmt: skip
    assert chart.returncode == 2
    assert "--chart: charts need matplotlib, which is not installed: pip install" in chart.stderr
    bus = _python(
        "import robosoa\n"
        "try:\n    robosoa.connect('zmq://tcp://127.0.0.1:9')\n"
        "except robosoa.RobosoaError as error:\n    print(error)", tmp_path, ("zmq",),
    )  # fmt: skip
    assert bus.stdout.strip() == (
        "the transport robosoa.transports.zmq_adapter needs pyzmq, which is not installed:"
        " pip install 'archmetrics[runtime]'"
    ), bus.stderr
    inproc = _python("import robosoa\nbus = robosoa.connect('inproc')\nbus.close()\nprint('ok')",
                     tmp_path, ("zmq", "lxml"))  # fmt: skip
    assert inproc.stdout.strip() == "ok", inproc.stderr
    gen = subprocess.run(
        [sys.executable, "-c", "import sys\nsys.modules['lxml'] = None\n"
         "from robosoa.cli import main\nsys.exit(main(['validate', 'x.xml']))"],
        cwd=tmp_path, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert gen.returncode == 1  # robosoa's exit for a failed command
    assert gen.stderr == (
        "robosoa: error: code generation needs lxml, which is not installed:"
        " pip install 'archmetrics[runtime]'\n"
    )
