"""Edges a CI job meets on its first day: a change with nothing to measure, a syntax error in
a changed file, an output file whose ending names no format."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from archmetrics.cli import main
from tests.gitrepo import GitRepo


def test_a_tree_of_docs_only_is_measured_as_empty(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    repo.commit("docs", files={"README.md": "# hello\n", "docs/guide.rst": "text\n"})
    assert main(["scan", str(repo.root), "-q", "--no-cache"]) == 0
    out, err = capsys.readouterr()
    note = "no source files to measure in the tree (WORKTREE): nothing measured"
    assert note in out and err == ""  # shown once, in the table on stdout
    assert main(["scan", str(repo.root), "-q", "--no-cache", "--format", "json"]) == 0
    out, err = capsys.readouterr()
    document: Any = json.loads(out)
    assert document["totals"]["files"] == 0 and document["notes"][0].startswith(note)
    assert note in err
    # a threshold still reads the (empty) total, and a path missing at a revision is an error
    assert main(["scan", str(repo.root), "-q", "--no-cache", "--fail-on", "files(total) < 1"]) == 1
    capsys.readouterr()
    assert main(["scan", str(repo.root / "src"), "--rev", "HEAD", "-q", "--no-cache"]) == 2
    assert "src: no such path at revision HEAD" in capsys.readouterr().err


def test_a_syntax_error_in_a_changed_file_is_reported_and_gateable(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    repo.commit("v1", tag="v1", files={"app.py": "x = 1\n", "new/mod.py": "y = 1\n"})
    repo.commit("v2", tag="v2", files={"new/mod.py": "def broken(:\n    pass\n"})
    diff = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2", "-q", "--no-cache",
            "--new", "new/**"]  # fmt: skip
    assert main([*diff, "--format", "json"]) == 0  # measured: no gate says otherwise
    document: Any = json.loads(capsys.readouterr().out)
    assert document["locations"]["new"]["unparsed"] == 1
    assert document["locations"]["total"]["unparsed"] == 1
    assert document["locations"]["base"]["unparsed"] == 0
    assert {"path": "new/mod.py", "reason": "not_parsed"} in document["excluded"]
    assert any(w["path"] == "new/mod.py" for w in document["warnings"])
    assert main([*diff, "--fail-on", "unparsed(new) > 0", "--format", "markdown"]) == 1
    out = capsys.readouterr().out
    assert "gate failed: unparsed(new) > 0 (unparsed(new) = 1)" in out
    assert "1 changed file(s) could not be parsed" in out
    # a file broken before and untouched by the change is not the change's
    repo.commit("v3", tag="v3", files={"app.py": "x = 2\n"})
    again = ["diff", "-C", str(repo.root), "--base", "v2", "--head", "v3", "-q", "--no-cache"]
    assert main([*again, "--fail-on", "unparsed > 0"]) == 0


@pytest.mark.parametrize(
    ("argv", "said"),
    [
        (["scan", "-o", "report.html"], "report.html: .html names no format of this command"),
        (["scan", "-o", "graph.dot"], "graph.dot: .dot names no format of this command"),
        (["diff", "-o", "r.pdf"], "r.pdf: .pdf names no format of this command"),
    ],
)
def test_an_output_ending_that_names_no_format_is_refused(
    argv: list[str], said: str, repo: GitRepo, capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:  # fmt: skip
    repo.commit("one", files={"a.py": "x = 1\n"})
    monkeypatch.chdir(repo.root)
    assert main([*argv, "-q", "--no-cache"]) == 2
    assert said in capsys.readouterr().err
    assert not list(Path(repo.root).glob(Path(argv[-1]).name))  # nothing written


def test_an_output_file_picks_its_format_by_ending_or_by_flag(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    repo.commit("one", files={"a.py": "x = 1\n"})
    monkeypatch.chdir(repo.root)
    assert main(["scan", "-q", "--no-cache", "-o", "r.json"]) == 0
    assert json.loads((repo.root / "r.json").read_text())["schema"] == "archmetrics.scan/1"
    assert main(["scan", "-q", "--no-cache", "-o", "r.html", "--format", "markdown"]) == 0
    assert (repo.root / "r.html").read_text().startswith("## archmetrics scan")
    assert main(["scan", "-q", "--no-cache", "-o", "report"]) == 0  # no ending: the default
    assert "archmetrics scan: WORKTREE" in (repo.root / "report").read_text()
