"""Odd and hostile input gives a report or one line with exit 2: never a traceback, never
exit 1 (which means only "a gate failed"), never output that is not valid UTF-8."""

from __future__ import annotations

import json
import os
from pathlib import Path

import pytest

from tests.gitrepo import GitRepo
from tests.untrusted import run_cli, run_main

SOURCE = "def f(a):\n    if a:\n        return 1\n    return 2\n"


@pytest.mark.parametrize(
    ("config", "problem"),
    [
        ('tool = "x"\n', "tool: expected a table"),
        ("[tool]\narchmetrics = 3\n", "expected a table"),
        ("[tool.archmetrics]\nx = " + "[" * 5000 + "]" * 5000 + "\n", "nested too deeply"),
        ("[tool.archmetrics]\njobs = -1\n", "non-negative integer"),
        ("[tool.archmetrics]\nexclude = ['[z-a]']\n", "unusable glob '[z-a]'"),
        ("[tool.archmetrics.locations]\nnew = ['src/[b-a].c']\n", "unusable glob"),
        ("[tool.archmetrics]\nexclude = ['#vendor']\n", "exclude: unusable glob '#vendor'"),
        ("[tool.archmetrics.locations]\nbase = ['" + "*" * 1025 + "']\n", "longer than 1024"),
        ('[tool.archmetrics]\nlanguages = { ".py" = "cobol" }\n', "no parser for language"),
        ("[tool.archmetrics]\ncache-path = '/'\n", "outside archmetrics's cache directory"),
        (b"\xff\xfe[tool]", "not valid TOML"),
        ("[tool.archmetrics.limits]\nfile-mb = 1e-9\n", "limits.file-mb: expected at least 0.001"),
        ('[tool.archmetrics]\ncache-path = "\\u0000"\n', "cache-path: expected a path (without"),
    ],
)
@pytest.mark.security
def test_a_bad_configuration_is_one_line(
    repo: GitRepo, config: str | bytes, problem: str, tmp_path: Path
) -> None:
    repo.commit("v1", files={"pyproject.toml": config, "a.py": SOURCE})
    repo.write({"a.py": SOURCE + "x = 1\n"})
    env = {"ARCHMETRICS_CACHE": "", "XDG_CACHE_HOME": str(tmp_path / "xdg")}
    for argv in (["scan", "."], ["diff"]):
        run = run_main(argv, repo.root, env)
        assert run.code == 2, (argv, run.err)
        assert problem in run.one_line_error()


@pytest.mark.security
def test_a_symbolic_link_loop_as_an_argument(tmp_path: Path) -> None:
    (tmp_path / "one").symlink_to(tmp_path / "two")
    (tmp_path / "two").symlink_to(tmp_path / "one")
    for argv in (["scan", "one"], ["diff", "-C", "one"], ["graph", "one"]):
        run = run_main(argv, tmp_path)
        assert run.code == 2
        assert "one" in run.one_line_error()


@pytest.mark.security
def test_an_unforeseen_error_is_one_line_and_v_shows_the_traceback(
    repo: GitRepo, tmp_path: Path
) -> None:
    """A broken language plugin (its entry point is not a LanguageSpec) is nothing the CLI
    knows how to explain: still exit 2 and one line, and -v prints the traceback.

    Processes of their own: PYTHONPATH, which brings the plugin in, is read when the
    interpreter starts."""
    site = tmp_path / "site"
    (site / "broken-1.0.dist-info").mkdir(parents=True)
    (site / "broken_lang.py").write_text("SPEC = 42\n")
    (site / "broken-1.0.dist-info" / "METADATA").write_text("Name: broken\nVersion: 1.0\n")
    (site / "broken-1.0.dist-info" / "entry_points.txt").write_text(
        "[archmetrics.languages]\nbroken = broken_lang:SPEC\n"
    )
    repo.commit("v1", files={"a.py": SOURCE})
    env = {"PYTHONPATH": os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")])}
    run = run_cli(["scan", "."], repo.root, env)
    assert run.code == 2
    line = run.one_line_error()
    assert "unexpected TypeError" in line and "rerun with -v" in line
    for argv in (["-v", "scan", "."], ["scan", ".", "-v"]):
        verbose = run_cli(argv, repo.root, env)
        assert verbose.code == 2
        assert "Traceback" in verbose.err and "must be a LanguageSpec" in verbose.err


NAMES = {
    "latin1": b"caf\xe9.py",
    "newline": b"two\nlines.py",
    "escape": b"red\x1b[31m.py",
    "backslash": b"back\\slash.py",
    "c1": "c1\u0085.py".encode(),
}


@pytest.mark.security
@pytest.mark.parametrize("committed", [True, False], ids=["revision", "worktree"])
def test_file_names_that_are_not_plain_text_are_escaped_everywhere(
    repo: GitRepo, committed: bool
) -> None:
    for name in NAMES.values():
        (repo.root / os.fsdecode(name)).write_bytes(SOURCE.encode())
    if committed:
        repo.commit("v1")
    for fmt in ("json", "table", "markdown", "csv"):
        run = run_main(["scan", ".", "--format", fmt, "--no-cache"], repo.root)
        assert run.code == 0, run.err
        assert "\ufffd" not in run.out and "\x1b" not in run.out and "\x85" not in run.out
    document = json.loads(run_main(["scan", ".", "--format", "json"], repo.root).out)
    paths = {f["path"] for f in document["files"]}
    assert paths == {
        "caf\\351.py",
        "two\\nlines.py",
        "red\\033[31m.py",
        "back\\\\slash.py",
        "c1\\302\\205.py",
    }
    assert all(f["vg"] == 2 for f in document["files"])


@pytest.mark.security
def test_json_bytes_are_valid_utf8_and_diff_pairs_escaped_names(repo: GitRepo) -> None:
    name = os.fsdecode(NAMES["latin1"])
    repo.commit("v1", files={name: SOURCE})
    repo.write({name: SOURCE + "\n\ndef g(b):\n    return b or 1\n"})
    run = run_main(["diff", "--format", "json", "--no-cache"], repo.root)
    assert run.code == 0, run.err
    document = json.loads(run.out.encode("utf-8"))
    total = document["locations"]["total"]
    assert (total["added"], total["removed"], total["delta_vg"]) == (2, 0, 2)  # paired, not A+R
    assert [e["files"] for e in document["elements"]] == [["caf\\351.py"]]


@pytest.mark.parametrize(  # the narrowest in the security suite, every one in the whole
    "encoding", [pytest.param("ascii", marks=pytest.mark.security), "cp1252", "latin-1"]
)
@pytest.mark.parametrize("fmt", ["table", "markdown", "csv", "json"])
def test_every_format_prints_on_a_narrow_encoding(repo: GitRepo, encoding: str, fmt: str) -> None:
    repo.commit("v1", tag="v1", files={"a.py": SOURCE})
    repo.commit("v2", files={"a.py": SOURCE + "x = 1\n"})
    env = {"PYTHONIOENCODING": encoding}  # run_main's stdout is then in that encoding
    for argv in (["diff", "--base", "v1", "--head", "HEAD"], ["scan", "."]):
        run = run_main([*argv, "--format", fmt], repo.root, env)
        assert run.code == 0, run.err
        assert run.out.strip()
