"""Pull-request semantics: ``--base A...B`` and ``--merge-base`` compare B with the merge base
of A and B, as ``git diff A...B`` does, so commits the base branch gained after the branch
point are not counted as the pull request's (reversed) changes.

The repository: main holds ``a.py`` (def f + return: 2 statements, v_g 1); the branch
``feature`` adds an ``if`` and a ``return`` to f (2 statements added, v_g 2); after the branch
point main gains ``b.py`` (def, for, print call, return: 4 statements).
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import pytest

from archmetrics import __version__
from archmetrics.cli import main
from tests.gitrepo import GitRepo

A_MAIN = "def f(a):\n    return a\n"
A_FEATURE = "def f(a):\n    if a:\n        return 1\n    return a\n"
B_MAIN = "def g(b):\n    for i in b:\n        print(i)\n    return b\n"


@pytest.fixture
def behind(repo: GitRepo) -> GitRepo:
    """A pull request's branch ``feature``, checked out, behind ``main``."""
    repo.commit("base", files={"a.py": A_MAIN})
    repo.git("checkout", "-q", "-b", "feature")
    repo.commit("feature", files={"a.py": A_FEATURE})
    repo.git("checkout", "-q", "main")
    repo.commit("main moves on", files={"b.py": B_MAIN})
    repo.git("checkout", "-q", "feature")
    return repo


def _json(repo: GitRepo, capsys: pytest.CaptureFixture[str], *argv: str, status: int = 0) -> Any:
    code = main(["diff", "-C", str(repo.root), "--format", "json", "-q", *argv])
    out, err = capsys.readouterr()
    assert code == status, err
    return json.loads(out) if out else err


def _counts(document: Any) -> tuple[int, int, int, int]:
    total = document["locations"]["total"]
    return total["added"], total["removed"], total["modified"], total["delta_vg"]


def test_three_dots_count_only_the_branch_s_changes(
    behind: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    merge_base = behind.git("merge-base", "main", "feature").strip()
    head = behind.git("rev-parse", "HEAD").strip()
    three = _json(behind, capsys, "--base", "main...HEAD", "--fail-on", "added > 1", status=1)
    assert _counts(three) == (2, 0, 0, 1)  # the if and its return; f's v_g 1 -> 2
    assert (three["base"], three["head"]) == ("main...HEAD", "HEAD")
    assert (three["base_commit"], three["head_commit"]) == (merge_base, head)
    assert three["tool"] == {"name": "archmetrics", "version": __version__}
    assert three["gates"] == [
        {"gate": "added > 1", "failed": True, "values": {"added(total)": 2}},
        {"gate": "unmeasured(head) > 0", "failed": False, "values": {"unmeasured(head)": 0}},
    ]  # a gated diff also checks that the head measures what the base's configuration does
    two = _json(behind, capsys, "--base", "main", "--head", "HEAD")
    assert _counts(two) == (2, 4, 0, -1)  # main's b.py counted as removed by the branch
    flag = _json(behind, capsys, "--base", "main", "--head", "HEAD", "--merge-base")
    assert _counts(flag) == _counts(three) and flag["base_commit"] == merge_base
    open_end = _json(behind, capsys, "--base", "main...")  # an empty end is HEAD, as in git
    assert _counts(open_end) == _counts(three)
    dots = _json(behind, capsys, "--base", "main..feature")
    assert _counts(dots) == _counts(two) and dots["base"] == "main"


def test_a_gate_entry_carries_what_it_measured(
    behind: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    document = _json(
        behind, capsys, "--base", "main...HEAD", "--fail-on", "added > 1 and cost(new) > 5",
        "--fail-on", "loc_scale(new) > 0",
    )  # fmt: skip
    assert document["gates"] == [
        {
            "gate": "added > 1 and cost(new) > 5",
            "failed": False,
            "values": {"added(total)": 2.0, "cost(new)": 0.0},
        },
        {"gate": "loc_scale(new) > 0", "failed": False, "values": {"loc_scale(new)": None}},
        {"gate": "unmeasured(head) > 0", "failed": False, "values": {"unmeasured(head)": 0}},
    ]  # nothing new: E(N) = 0 and λ̂(N) undefined (null), so neither gate fails


def test_the_worktree_is_compared_from_head_s_merge_base(
    behind: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    behind.write({"a.py": A_FEATURE + "x = 1\n"})
    document = _json(behind, capsys, "--base", "main", "--merge-base")  # head: WORKTREE
    assert _counts(document) == (3, 0, 0, 1)
    assert document["head_commit"] is None and document["head"] == "WORKTREE"


def test_what_cannot_be_a_merge_base_is_refused_with_the_reason(
    behind: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    err = _json(behind, capsys, "--base", "main...feature", "--head", "HEAD~1", status=2)
    assert "--base main...feature names the head (feature); --head HEAD~1 disagrees" in err
    behind.git("checkout", "-q", "--orphan", "lonely")
    behind.commit("unrelated", files={"c.py": "y = 1\n"})
    err = _json(behind, capsys, "--base", "main...HEAD", status=2)
    assert "main and HEAD share no history: no merge base" in err
    clone = tmp_path / "shallow"
    subprocess.run(
        ["git", "clone", "-q", "--depth", "1", "--no-single-branch", "-b", "feature",
         f"file://{behind.root}", str(clone)],
        check=True, capture_output=True,
    )  # fmt: skip
    code = main(["diff", "-C", str(clone), "--base", "origin/main...HEAD", "-q"])
    err = capsys.readouterr().err
    assert code == 2
    assert (
        "origin/main and HEAD: no merge base in this shallow clone; fetch the history first"
        " (git fetch --deepen=200, or --unshallow; fetch-depth: 0 in CI)"
    ) in err


def test_a_location_glob_that_matches_no_file_is_named(
    behind: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    argv = ["diff", "-C", str(behind.root), "--base", "main...HEAD", "-q", "--format", "markdown"]
    assert main([*argv, "--new", '"a.py"', "--framework", "a.py"]) == 0
    out, err = capsys.readouterr()
    said = "the glob '\"a.py\"' matched no file archmetrics measures, before or after"
    assert f"archmetrics: warning: {said}" in err and said in out
    assert "'a.py' matched" not in err  # the same glob without its quotes matches
