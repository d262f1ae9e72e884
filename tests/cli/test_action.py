"""The composite GitHub Action (action.yml at the root): its shell step run as a runner runs
it, with the environment a runner sets, in a real repository (archmetrics itself is already
installed here, so the step that installs it is checked, not run)."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path
from typing import Any

import pytest
import yaml

from tests.gitrepo import GitRepo

ROOT = Path(__file__).resolve().parents[2]
ACTION: dict[str, Any] = yaml.safe_load((ROOT / "action.yml").read_text(encoding="utf-8"))


def _step(step_id: str) -> dict[str, Any]:
    return next(s for s in ACTION["runs"]["steps"] if s.get("id") == step_id)


def _inputs(given: dict[str, str]) -> dict[str, str]:
    """Every input as the runner passes it: the value given, else the default."""
    return {
        name: given.get(name, spec.get("default", "")) for name, spec in ACTION["inputs"].items()
    }


def _run(repo: GitRepo, tmp_path: Path, **given: str) -> tuple[int, str, dict[str, str], str]:
    """The measure step's script under bash, as the runner runs it: its ``env`` mapping with
    the inputs substituted, and the runner's own variables. Exit code, job summary, step
    outputs and stderr."""
    step = _step("measure")
    inputs = _inputs(given)
    env = dict(os.environ)
    for name, value in step["env"].items():
        expression = value.strip()
        assert expression.startswith("${{ inputs.") and expression.endswith("}}")
        env[name] = inputs[expression[len("${{ inputs.") : -2].strip()]
    summary, outputs = tmp_path / "summary.md", tmp_path / "outputs.txt"
    summary.write_text("")
    outputs.write_text("")
    runner = tmp_path / "runner"
    runner.mkdir(exist_ok=True)
    env.update(
        {
            "PATH": f"{Path(sys.executable).parent}{os.pathsep}{env.get('PATH', '')}",
            "GITHUB_ACTIONS": "true",
            "GITHUB_EVENT_NAME": "pull_request",
            "GITHUB_BASE_REF": "main",
            "GITHUB_HEAD_REF": "feature",
            "GITHUB_WORKSPACE": str(repo.root),
            "GITHUB_STEP_SUMMARY": str(summary),
            "GITHUB_OUTPUT": str(outputs),
            "RUNNER_TEMP": str(runner),
            "ARCHMETRICS_CACHE": str(tmp_path / "cache.sqlite3"),
        }
    )
    assert step["shell"] == "bash"
    script = runner / "step.sh"  # the runner writes the step to a file and runs it so
    script.write_text(step["run"])
    done = subprocess.run(
        ["bash", "--noprofile", "--norc", "-eo", "pipefail", str(script)],
        cwd=repo.root,
        env=env,
        capture_output=True,
        text=True,
        timeout=600,
    )
    values = dict(line.split("=", 1) for line in outputs.read_text().splitlines() if "=" in line)
    return done.returncode, summary.read_text(), values, done.stderr


@pytest.fixture
def pull_request(repo: GitRepo) -> GitRepo:
    """A repository checked out on a pull request's head, its base branch fetched as
    origin/main (what actions/checkout with fetch-depth 0 leaves)."""
    base = repo.commit("base", files={"src/app.py": "def f(a):\n    return a\n"})
    repo.git("update-ref", "refs/remotes/origin/main", base)
    repo.commit(
        "feature",
        files={"src/app.py": "def f(a):\n    if a:\n        return a\n    return 0\n"},
    )
    return repo


def test_the_report_goes_to_the_job_summary(pull_request: GitRepo, tmp_path: Path) -> None:
    code, summary, outputs, _ = _run(pull_request, tmp_path)
    assert code == 0
    assert "archmetrics" in summary and "| E |" in summary  # the Markdown report
    assert outputs["status"] == "0"
    document = json.loads(Path(outputs["json"]).read_text())
    assert document["schema"] == "archmetrics.diff/1"
    assert document["base"] == "origin/main"  # the pull request's base branch by default
    assert Path(outputs["report"]).read_text() in summary


def test_a_gate_that_fails_fails_the_step_with_the_report(
    pull_request: GitRepo, tmp_path: Path
) -> None:
    code, summary, outputs, stderr = _run(
        pull_request, tmp_path, **{"fail-on": "  changes > 0\n\nloc_post(total) < 0\n"}
    )
    assert code == 1 and outputs["status"] == "1"
    assert "gate failed: changes > 0" in summary
    assert stderr.count("gate failed: changes > 0") == 1  # printed once
    assert "loc_post(total) < 0" not in stderr  # the other gate holds


def test_a_table_is_fenced_and_arguments_reach_the_diff(
    pull_request: GitRepo, tmp_path: Path
) -> None:
    code, summary, _, _ = _run(
        pull_request, tmp_path, format="table", args="--new src/** --base HEAD~1"
    )
    assert code == 0
    assert summary.startswith("```\n") and summary.rstrip().endswith("```")
    document = json.loads((tmp_path / "runner" / "archmetrics" / "archmetrics.json").read_text())
    assert document["base"] == "HEAD~1"  # given later in args, it wins
    new = document["locations"]["new"]
    assert new["loc_post"] > 0  # src/** counted as new code


def test_what_cannot_be_measured_exits_2_without_a_summary(
    pull_request: GitRepo, tmp_path: Path
) -> None:
    code, summary, outputs, stderr = _run(pull_request, tmp_path, base="no-such-revision")
    assert code == 2 and outputs["status"] == "2"
    assert summary == ""
    assert "no-such-revision" in stderr
    code, _, _, stderr = _run(pull_request, tmp_path, format="sarif")
    assert code == 2 and "format must be markdown or table" in stderr


def test_the_install_step_installs_the_action_itself() -> None:
    step = next(s for s in ACTION["runs"]["steps"] if s["name"] == "install archmetrics")
    assert step["env"]["ARCHMETRICS_SOURCE"] == "${{ github.action_path }}"
    assert '"$ARCHMETRICS_SOURCE"' in step["run"] and "pip install" in step["run"]
    assert ACTION["runs"]["using"] == "composite"
    assert set(ACTION["inputs"]) == {"base", "head", "fail-on", "format", "args"}
