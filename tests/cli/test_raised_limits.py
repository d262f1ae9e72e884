"""Threat: a repository that raises its own limits (``file-mb = 1024``,
``worker-memory-mb = 65536``, ``parse-seconds = 3600`` and one 200 MB C file reached 24 GB
in a worker), and a blob larger than the size limit read whole before its size was checked
(docs/security.md, threat table).

A repository may lower its limits; raising one above its default takes
``--allow-raised-limits`` on the command line, and without it the default applies, with a
warning naming the key. A file over the size limit is never read: a work-tree file's size
comes from the file system, a blob's from git's object header."""

from __future__ import annotations

import json
import tracemalloc
from pathlib import Path

import pytest

from archmetrics.app.settings import settings_at
from archmetrics.config import LimitSettings
from tests.gitrepo import GitRepo
from tests.untrusted import run_main

pytestmark = pytest.mark.security

RAISED = """\
[tool.archmetrics.limits]
file-mb = 1024
worker-memory-mb = 65536
parse-seconds = 3600
file-seconds = 3600
nesting = 60000
"""
MIB = 1 << 20
# a C file of 17 MiB, over the default 16 MiB: one comment, then a function
BIG_C = "/*" + "x" * (17 * MIB) + "*/\nint f(void) { return 1; }\n"


def test_raised_limits_are_put_back_to_the_defaults(repo: GitRepo) -> None:
    repo.commit("v1", files={"pyproject.toml": RAISED})
    settings = settings_at(repo.root)
    assert settings.limits == LimitSettings()
    keys = ["file-seconds", "worker-memory-mb", "file-mb", "nesting", "parse-seconds"]
    assert [n.split("limits.")[1].split(" ")[0] for n in settings.notices] == keys
    allowed = settings_at(repo.root, allow_raised_limits=True)
    assert allowed.limits == LimitSettings(3600, 65536, 1024, 60_000, 3600) and not allowed.notices


def test_a_lowered_limit_holds_without_the_flag(repo: GitRepo) -> None:
    repo.commit("v1", files={"pyproject.toml": "[tool.archmetrics.limits]\nfile-mb = 0.001\n"})
    settings = settings_at(repo.root)
    assert settings.limits.file_mb == 0.001 and not settings.notices


def _file(run_out: str) -> dict[str, object]:
    document = json.loads(run_out)
    return {f["path"]: f for f in document["files"]}["big.c"]  # type: ignore[no-any-return]


def test_a_file_over_the_default_needs_the_flag(repo: GitRepo) -> None:
    """The 17 MiB file is not measured under the repository's file-mb = 1024 alone; with
    --allow-raised-limits it is. Each raised limit is one warning line."""
    repo.commit("v1", files={"pyproject.toml": RAISED, "big.c": BIG_C})
    run = run_main(["scan", ".", "--format", "json", "--no-cache"], repo.root)
    assert run.code == 0, run.err
    warnings = [line for line in run.err.splitlines() if "archmetrics: warning:" in line]
    assert len(warnings) == 5 and all("--allow-raised-limits" in w for w in warnings)
    assert "limits.file-mb = 1024 is above the default 16" in run.err
    big = _file(run.out)
    assert big["parsed"] is False
    assert "the limit is 16,777,216" in json.dumps(big["warnings"])
    allowed = run_main(
        ["scan", ".", "--format", "json", "--no-cache", "--allow-raised-limits"], repo.root
    )
    assert allowed.code == 0 and "warning" not in allowed.err, allowed.err
    assert _file(allowed.out)["parsed"] is True


@pytest.mark.parametrize("argv", [["scan", ".", "--rev", "HEAD"], ["scan", "."],
                                  ["diff", "--base", "EMPTY", "--head", "HEAD"]])  # fmt: skip
def test_a_file_over_the_limit_is_never_read(
    repo: GitRepo, tmp_path: Path, argv: list[str]
) -> None:
    """A 40 MiB blob and work-tree file: this process never holds it (tracemalloc counts
    every bytes object it allocates; the file would be 40 MiB at least once)."""
    repo.commit("v1", files={"big.c": "/*" + "y" * (40 * MIB) + "*/\n", "a.py": "x = 1\n"})
    tracemalloc.start()
    try:
        run = run_main([*argv, "--format", "json", "--no-cache"], repo.root)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert run.code == 0, run.err
    assert peak < 20 * MIB, peak
    if argv[0] == "scan":
        assert "the limit is 16,777,216" in json.dumps(_file(run.out)["warnings"])
    else:
        assert {"path": "big.c", "reason": "not_parsed"} in json.loads(run.out)["excluded"]
