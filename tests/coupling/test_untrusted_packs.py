"""Rule packs a repository brings are untrusted: slow patterns are cut off and reported,
and a configured pack is a small regular file inside the repository."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from archmetrics.coupling import patterns
from tests.gitrepo import GitRepo
from tests.untrusted import run_cli, run_main_past_fifos

pytestmark = pytest.mark.security

PACK = """
[pack]
name = "ours"
description = "a bus whose endpoint pattern backtracks"

[[rules]]
id = "send"
language = ["python"]
match = ["bus.send"]
kind = "messaging"
role = "initiate"
endpoint = {{ type = "name", arg = 0, pattern = '{pattern}' }}

[[rules]]
id = "serve"
language = ["python"]
match = ["bus.serve"]
kind = "messaging"
role = "receive"
endpoint = {{ type = "name", arg = 0, pattern = '(\\w+)' }}
"""
CLIENT = "import bus\n\n\ndef ask():\n" + "".join(
    f"    bus.send('{'a' * 60}b{i}')\n" for i in range(50)
)
SERVER = "import bus\n\n\ndef serve():\n    bus.serve('work')\n"


def _repo(repo: GitRepo, pattern: str) -> None:
    repo.commit(
        "v1",
        files={
            "pack.toml": PACK.format(pattern=pattern),
            "pyproject.toml": '[tool.archmetrics.coupling]\nrule-packs = ["pack.toml"]\n',
            "client.py": CLIENT,
            "server.py": SERVER,
        },
    )


def test_a_backtracking_pattern_is_cut_off_and_reported(repo: GitRepo) -> None:
    """Processes of their own: a pattern that ran out of time is not tried again in the
    same process (patterns._slow), and each run must find out for itself."""
    _repo(repo, "^(a|aa)+$")
    run = run_cli(["scan", ".", "--by", "link", "--format", "json", "--no-cache"], repo.root)
    assert run.code == 0, run.err
    sites = [s for e in json.loads(run.out)["elements"] for s in e["link_sites"]]
    sent = [s for s in sites if s["rule"] == "ours/send"]
    assert len(sent) == 50
    assert all(s["endpoint"] is None and "gave up after" in s["note"] for s in sent)
    [served] = [s for s in sites if s["rule"] == "ours/serve"]
    assert served["endpoint"] == "name:work" and served["note"] is None
    table = run_cli(["scan", ".", "--by", "link", "--no-cache"], repo.root, {"COLUMNS": "300"})
    assert "gave up after" in table.out


def test_a_search_that_runs_out_of_time_raises_and_is_not_retried() -> None:
    pattern = "(x|xx)+$"
    with pytest.raises(patterns.SlowPattern, match="gave up after"):
        patterns.search(pattern, "x" * 80 + "!")
    with pytest.raises(patterns.SlowPattern):
        patterns.search(pattern, "x")  # would be quick, but the pattern is known to be slow
    assert patterns.search(r"PLAYER_([A-Z0-9]+)_CMD_", "PLAYER_POSITION2D_CMD_VEL")


@pytest.mark.parametrize(
    ("packs", "problem"),
    [
        ('["/etc/hostname"]', "must be inside the repository"),
        ('["../outside.toml"]', "must be inside the repository"),
        ('["link.toml"]', "must be inside the repository"),
        ('["fifo.toml"]', "not a regular file"),
        ('["big.toml"]', "larger than 1048576 bytes"),
        ('["deep.toml"]', "nested too deeply"),
        ('["bad.toml"]', "bad regular expression"),
    ],
)
def test_a_configured_pack_that_cannot_be_trusted_is_refused(
    repo: GitRepo, tmp_path: Path, packs: str, problem: str
) -> None:
    (tmp_path / "outside.toml").write_text("[pack]\n")
    repo.write(
        {
            "pyproject.toml": f"[tool.archmetrics.coupling]\nrule-packs = {packs}\n",
            "a.py": SERVER,
            "big.toml": "# " + "x" * (1 << 20) + "\n",
            "deep.toml": "x = " + "[" * 5000 + "]" * 5000 + "\n",
            "bad.toml": PACK.format(pattern="(unclosed"),
        }
    )
    (repo.root / "link.toml").symlink_to(tmp_path / "outside.toml")
    os.mkfifo(repo.root / "fifo.toml")
    # a diff reads its base's configuration: EMPTY has none, so the head's is named
    # (rules loads the packs as scan does)
    diff = ["diff", "--base", "EMPTY", "--config-from", "head"]
    for argv in (["scan", "."], diff):  # a regression that waits on the FIFO fails in 60 s
        run = run_main_past_fifos(argv, repo.root, [repo.root / "fifo.toml"])
        assert run.code == 2, (argv, run.err)
        assert problem in run.one_line_error()
