"""The composite GitHub Action (action.yml at the root): its shell steps run as a runner runs
them (``bash --noprofile --norc -eo pipefail`` on a file), with the variables a runner sets
(GITHUB_EVENT_NAME, GITHUB_EVENT_PATH holding a real event's JSON, GITHUB_STEP_SUMMARY,
GITHUB_OUTPUT, GITHUB_ENV, GITHUB_ACTION_PATH, RUNNER_TEMP ...), in real repositories: a pull
request behind main, a push of three commits, a branch's first push, a shallow clone, quoted
arguments. archmetrics itself is already installed here, so the steps that `uses:` another
action or install archmetrics are checked, not run.

Every count is derived by hand from the files: a statement is a logical line (the ``def``
line counts as one), so ``def f(a): return a`` is 2 statements.
"""

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
RUN = ["check Python", "name the caches", "measure"]  # the steps that run here, in order
A_MAIN = "def f(a):\n    return a\n"
A_FEATURE = "def f(a):\n    if a:\n        return 1\n    return a\n"  # +2 statements
B_MAIN = "def g(b):\n    for i in b:\n        print(i)\n    return b\n"  # 4 statements


def _inputs(given: dict[str, str]) -> dict[str, str]:
    """Every input as the runner passes it: the value given, else the default."""
    return {
        name: given.get(name, spec.get("default", "")) for name, spec in ACTION["inputs"].items()
    }


class Runner:
    """The runner's files and variables for one job; each run's summary, outputs and log."""

    def __init__(self, tmp_path: Path, event_name: str, event: dict[str, Any]) -> None:
        self.tmp = tmp_path
        self.temp = tmp_path / "runner"
        self.temp.mkdir(parents=True, exist_ok=True)
        self.summary, self.output, self.env_file = (
            tmp_path / "summary.md", tmp_path / "output.txt", tmp_path / "env.txt",
        )  # fmt: skip
        for path in (self.summary, self.output, self.env_file):
            path.write_text("")
        event_path = tmp_path / "event.json"
        event_path.write_text(json.dumps(event))
        self.variables = {
            "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}",
            "GITHUB_ACTIONS": "true",
            "GITHUB_EVENT_NAME": event_name,
            "GITHUB_EVENT_PATH": str(event_path),
            "GITHUB_STEP_SUMMARY": str(self.summary),
            "GITHUB_OUTPUT": str(self.output),
            "GITHUB_ENV": str(self.env_file),
            "GITHUB_ACTION_PATH": str(ROOT),
            "GITHUB_RUN_ID": "7",
            "RUNNER_TEMP": str(self.temp),
            "RUNNER_OS": "Linux",
        }

    def run(self, workspace: Path, **given: str) -> tuple[int, str]:
        """The action's steps that run here, in order, as the runner runs them: each step's
        ``env`` with the inputs substituted, what earlier steps wrote to GITHUB_ENV. The last
        step's exit status and the log."""
        inputs = _inputs(given)
        steps = {s.get("name"): s for s in ACTION["runs"]["steps"]}
        log = ""
        for name in RUN:
            step = steps[name]
            env = {**os.environ, **self.variables, **self._job_env()}
            if name == "name the caches":  # the tests' private cache is not the runner's
                env.pop("ARCHMETRICS_CACHE", None)
            for key, value in step.get("env", {}).items():
                expression = value.strip()
                assert expression.startswith("${{ inputs.") and expression.endswith("}}")
                env[key] = inputs[expression[len("${{ inputs.") : -2].strip()]
            assert step["shell"] == "bash"
            script = self.temp / "step.sh"  # the runner writes the step to a file
            script.write_text(step["run"])
            self.output = self.tmp / f"output-{RUN.index(name)}.txt"  # one file per step
            self.output.write_text("")
            env["GITHUB_OUTPUT"] = str(self.output)
            done = subprocess.run(
                ["bash", "--noprofile", "--norc", "-eo", "pipefail", str(script)],
                cwd=workspace, env=env, capture_output=True, text=True, timeout=600,
            )  # fmt: skip
            log += done.stdout + done.stderr
            if done.returncode != 0:
                return done.returncode, log
        return 0, log

    def _job_env(self) -> dict[str, str]:
        lines = self.env_file.read_text().splitlines()
        return dict(line.split("=", 1) for line in lines if "=" in line)

    def outputs(self, step: str = "measure") -> dict[str, str]:
        """What a step set as its outputs (the measure step's by default)."""
        path = self.tmp / f"output-{RUN.index(step)}.txt"
        lines = path.read_text().splitlines() if path.is_file() else []
        return dict(line.split("=", 1) for line in lines if "=" in line)

    def document(self) -> Any:
        return json.loads(Path(self.outputs()["json"]).read_text())


def _totals(document: Any) -> tuple[int, int, int]:
    total = document["locations"]["total"]
    return total["added"], total["removed"], total["modified"]


def _behind(repo: GitRepo) -> tuple[str, str]:
    """A branch ``feature`` checked out behind ``main``; main's tip and the merge base."""
    merge_base = repo.commit("base", files={"a.py": A_MAIN})
    repo.git("checkout", "-q", "-b", "feature")
    repo.commit("feature", files={"a.py": A_FEATURE})
    repo.git("checkout", "-q", "main")
    main_tip = repo.commit("main moves on", files={"b.py": B_MAIN})
    repo.git("checkout", "-q", "feature")
    return main_tip, merge_base


def _pull_request(base: str) -> dict[str, Any]:
    return {"number": 3, "pull_request": {"number": 3, "base": {"ref": "main", "sha": base},
                                          "head": {"ref": "feature"}}}  # fmt: skip


def test_a_pull_request_behind_main_reports_only_its_changes(
    repo: GitRepo, tmp_path: Path
) -> None:
    main_tip, merge_base = _behind(repo)
    runner = Runner(tmp_path, "pull_request", _pull_request(main_tip))
    code, log = runner.run(repo.root)
    assert code == 0, log
    document = runner.document()
    assert _totals(document) == (2, 0, 0)  # not main's b.py, reversed
    assert document["base"] == f"{main_tip}...HEAD" and document["base_commit"] == merge_base
    summary = runner.summary.read_text()
    assert summary.startswith("## archmetrics: ") and "| E |" in summary
    outputs = runner.outputs()
    assert outputs["status"] == "0" and Path(outputs["report"]).read_text() in summary
    cache = Path(runner._job_env()["ARCHMETRICS_CACHE"])  # the facts cache the job keeps
    assert cache.parent == tmp_path / "runner" / "archmetrics-facts" and cache.is_file()


def test_a_push_of_three_commits_measures_all_three(repo: GitRepo, tmp_path: Path) -> None:
    before = repo.commit("before", files={"a.py": A_MAIN})
    repo.commit("one", files={"c1.py": "x = 1\n"})
    repo.commit("two", files={"c2.py": "x = 1\ny = 2\n"})
    after = repo.commit("three", files={"c3.py": "x = 1\ny = 2\nz = 3\n"})
    event = {"ref": "refs/heads/main", "before": before, "after": after,
             "repository": {"default_branch": "main"}}  # fmt: skip
    runner = Runner(tmp_path, "push", event)
    code, log = runner.run(repo.root)
    assert code == 0, log
    document = runner.document()
    assert _totals(document) == (6, 0, 0)  # 1 + 2 + 3: not only the last commit's 3
    assert (document["base_commit"], document["head_commit"]) == (before, after)


def test_a_branch_s_first_push_counts_from_where_it_left_the_default_branch(
    repo: GitRepo, tmp_path: Path
) -> None:
    main_tip, merge_base = _behind(repo)
    repo.git("update-ref", "refs/remotes/origin/main", main_tip)
    head = repo.git("rev-parse", "HEAD").strip()
    event = {"ref": "refs/heads/feature", "before": "0" * 40, "after": head, "created": True,
             "repository": {"default_branch": "main"}}  # fmt: skip
    runner = Runner(tmp_path, "push", event)
    code, log = runner.run(repo.root)
    assert code == 0, log
    document = runner.document()
    assert _totals(document) == (2, 0, 0) and document["base_commit"] == merge_base
    first = Runner(tmp_path / "first", "push", {**event, "ref": "refs/heads/main"})
    assert first.run(repo.root)[0] == 0  # the default branch's first push: all of it new
    assert first.document()["base"] == "EMPTY" and _totals(first.document()) == (4, 0, 0)
    deleted = Runner(tmp_path / "gone", "push", {**event, "after": "0" * 40, "deleted": True})
    code, _ = deleted.run(repo.root)
    assert code == 2 and "the push deleted a branch: nothing to measure" in (
        deleted.summary.read_text()
    )


def _shallow_clone(origin: GitRepo, tmp_path: Path) -> Path:
    clone = tmp_path / "clone"
    subprocess.run(
        ["git", "clone", "-q", "--depth", "1", "-b", "feature", f"file://{origin.root}",
         str(clone)], check=True, capture_output=True,
    )  # fmt: skip
    return clone


def test_a_shallow_clone_is_deepened_to_the_merge_base_or_refused_with_the_fix(
    repo: GitRepo, tmp_path: Path
) -> None:
    main_tip, merge_base = _behind(repo)
    repo.git("checkout", "-q", "feature")
    repo.commit("feature again", files={"d.py": "w = 1\n"})  # the clone's boundary: 1 commit
    refused = Runner(tmp_path / "refused", "pull_request", _pull_request(main_tip))
    clone = _shallow_clone(repo, tmp_path / "refused")
    code, log = refused.run(clone, deepen="false")
    assert code == 2
    summary = refused.summary.read_text()
    assert summary.startswith("### archmetrics could not measure\n\n")
    assert "not both in this shallow clone with their merge base" in summary
    assert "fetch-depth: 0" in summary and "fetch-depth: 0" in log
    assert set(refused.outputs()) == {"status", "error"}  # no path of a file not written
    runner = Runner(tmp_path, "pull_request", _pull_request(main_tip))
    clone = _shallow_clone(repo, tmp_path)
    code, log = runner.run(clone)
    assert code == 0, log
    document = runner.document()
    assert _totals(document) == (3, 0, 0) and document["base_commit"] == merge_base


def test_quoted_arguments_reach_the_diff_as_words(repo: GitRepo, tmp_path: Path) -> None:
    repo.commit("base", files={"src/app.py": A_MAIN})
    repo.commit("new code", files={"src/new/store.py": B_MAIN, "lib/x.py": "y = 2\n"})
    runner = Runner(tmp_path, "workflow_dispatch", {})
    args = "--new \"src/new/**\" --framework 'lib/**'\n--exclude 'docs/**'"
    code, log = runner.run(repo.root, args=args, format="table")
    assert code == 0, log
    document = runner.document()
    assert document["base"] == "HEAD~1"
    assert document["locations"]["new"]["loc_post"] == 4  # the glob without its quotes
    assert document["locations"]["framework"]["loc_post"] == 1
    summary = runner.summary.read_text()
    assert summary.startswith("```\n") and summary.rstrip().endswith("```")
    # a glob that matches nothing is named, in the log and the summary
    warning = "the glob 'docs/**' matched no file archmetrics measures, before or after"
    assert f"archmetrics: warning: {warning}" in log and warning in summary
    assert "'src/new/**' matched no file" not in log
    unclosed = Runner(tmp_path / "unclosed", "workflow_dispatch", {})
    code, _ = unclosed.run(repo.root, args='--new "src/new/**')
    assert code == 2 and "the args input cannot be split" in unclosed.summary.read_text()


def test_a_failed_gate_and_a_failed_run_say_so_in_the_summary(
    repo: GitRepo, tmp_path: Path
) -> None:
    main_tip, _ = _behind(repo)
    runner = Runner(tmp_path, "pull_request", _pull_request(main_tip))
    code, log = runner.run(repo.root, **{"fail-on": "  added > 1\n\nloc_post(total) < 0\n"})
    assert code == 1 and runner.outputs()["status"] == "1"
    assert "gate failed: added > 1 (added(total) = 2)" in runner.summary.read_text()
    assert log.count("gate failed: added > 1") == 1 and "loc_post(total) < 0 (" not in log
    broken = Runner(tmp_path / "broken", "pull_request", _pull_request(main_tip))
    code, log = broken.run(repo.root, base="no-such-revision")
    assert code == 2 and broken.outputs()["status"] == "2"
    summary = broken.summary.read_text()
    assert summary == (
        "### archmetrics could not measure\n\nerror: unknown revision 'no-such-revision'\n"
    )
    assert set(broken.outputs()) == {"status", "error"}
    sarif = Runner(tmp_path / "sarif", "pull_request", _pull_request(main_tip))
    code, _ = sarif.run(repo.root, format="sarif")
    assert code == 2 and "format must be markdown or table" in sarif.summary.read_text()


def test_the_steps_set_up_python_cache_and_install_the_action_itself(tmp_path: Path) -> None:
    steps = {s["name"]: s for s in ACTION["runs"]["steps"]}
    setup = steps["set up Python"]
    assert setup["uses"].startswith("actions/setup-python@")
    assert setup["with"]["python-version"] == "${{ inputs.python-version }}"
    assert ACTION["inputs"]["python-version"]["default"] == "3.11"
    pip, facts = steps["cache pip's downloads"], steps["cache the facts"]
    assert pip["uses"].startswith("actions/cache@") and facts["uses"].startswith("actions/cache@")
    assert pip["with"]["key"] == "${{ steps.prepare.outputs.pip-key }}"
    assert facts["with"]["restore-keys"] == "${{ steps.prepare.outputs.facts-prefix }}"
    install = steps["install archmetrics"]
    assert install["env"]["ARCHMETRICS_SOURCE"] == "${{ github.action_path }}"
    assert '"$ARCHMETRICS_SOURCE"' in install["run"] and "pip install" in install["run"]
    assert ACTION["runs"]["using"] == "composite"
    runner = Runner(tmp_path, "push", {})
    repo = GitRepo(tmp_path / "empty")
    assert runner.run(repo.root)[0] == 2  # an event with no commits: prepared, not measured
    outputs = runner.outputs("name the caches")
    version = f"py{sys.version_info[0]}.{sys.version_info[1]}"
    assert outputs["pip-key"].startswith(f"archmetrics-pip-Linux-{version}-")
    assert outputs["facts-key"] == outputs["facts-prefix"] + "7"  # this run's: saved anew
    old = tmp_path / "old"  # a Python older than 3.11: the check says so before anything
    old.mkdir()
    (old / "python3").write_text("#!/bin/sh\n[ \"$1\" = --version ] && echo 'Python 3.10.12'\n"
                                 "exit 1\n")  # fmt: skip
    (old / "python3").chmod(0o755)
    runner.variables["PATH"] = f"{old}{os.pathsep}{runner.variables['PATH']}"
    code, log = runner.run(repo.root)
    assert code == 2 and "archmetrics needs Python 3.11 or later, found: Python 3.10.12" in log


@pytest.mark.parametrize("name", ["base", "head", "fail-on", "format", "args", "deepen"])
def test_every_input_is_documented(name: str) -> None:
    assert ACTION["inputs"][name]["description"].strip()
