"""Code Climate JSON for GitLab Code Quality: every failed gate and threshold an issue with
the fields GitLab reads, located where it is, with a fingerprint stable across runs."""

from __future__ import annotations

import json
from typing import Any

import pytest

from archmetrics.cli import main
from tests.gitrepo import GitRepo

BRANCHY = "def f(a, b):\n    if a:\n        return 1\n    if b:\n        return 2\n    return 3\n"
FIELDS = {"type", "check_name", "description", "categories", "fingerprint", "severity", "location"}


def _issues(capsys: pytest.CaptureFixture[str], *argv: str, status: int) -> list[Any]:
    assert main([*argv, "--format", "codeclimate", "-q", "--no-cache"]) == status
    issues: list[Any] = json.loads(capsys.readouterr().out)
    for issue in issues:
        assert set(issue) == FIELDS
        assert issue["severity"] in {"info", "minor", "major", "critical", "blocker"}
        assert isinstance(issue["location"]["path"], str)
        assert issue["location"]["lines"]["begin"] >= 1
    return issues


def test_a_scan_threshold_is_an_issue_at_its_function_or_file(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    repo.commit("one", files={"src/m.py": "import os\n\n\n" + BRANCHY, "src/ok.py": "x = 1\n"})
    argv = ["scan", str(repo.root), "--fail-on", "vg(function) > 2", "--fail-on", "loc(file) > 5"]
    issues = _issues(capsys, *argv, status=1)
    located = {
        (i["check_name"], i["location"]["path"], i["location"]["lines"]["begin"]) for i in issues
    }
    assert located == {
        ("archmetrics vg(function) > 2", "src/m.py", 4),
        ("archmetrics loc(file) > 5", "src/m.py", 1),
    }
    again = _issues(capsys, *argv, status=1)
    assert [i["fingerprint"] for i in again] == [i["fingerprint"] for i in issues]
    assert len({i["fingerprint"] for i in issues}) == 2
    assert _issues(capsys, "scan", str(repo.root), "--fail-on", "vg(function) > 9", status=0) == []
    element = _issues(capsys, "scan", str(repo.root), "--fail-on", "vg(element) > 2", status=1)
    assert [i["location"]["path"] for i in element] == ["src/m.py"]


def test_a_failed_diff_gate_is_an_issue_at_the_file_the_change_touched_most(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    repo.commit("one", tag="v1", files={"m.py": "x = 1\n", "n.py": "y = 1\n"})
    repo.commit("two", tag="v2", files={"m.py": "x = 1\n" + BRANCHY, "n.py": "y = 2\n"})
    argv = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2"]
    [issue] = _issues(capsys, *argv, "--fail-on", "changes > 2", status=1)
    assert issue["location"] == {"path": "m.py", "lines": {"begin": 1}}
    assert issue["description"].startswith("changes > 2 (changes(total) = ")
    assert issue["description"].endswith("shown at the file it changed most)")
    assert _issues(capsys, *argv, "--fail-on", "changes > 100", status=0) == []
    staged = _issues(capsys, "series", "v1", "v2", "--repo", str(repo.root),
                     "--fail-on", "changes > 2", status=1)  # fmt: skip
    assert [i["description"].split(":")[0] for i in staged] == ["v2"]  # the stage that failed
