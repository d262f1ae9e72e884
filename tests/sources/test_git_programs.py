"""Threat: a repository whose ``.git/config`` names programs (a tarball or CI artifact that
carries its ``.git``). No git command archmetrics runs may start one of them: not
``core.fsmonitor``, not a filter's ``clean`` / ``smudge`` / ``process``, not a diff
driver's ``textconv``, hooks, a pager, an askpass or ssh program, a credential helper
(docs/security.md, threat table).

Every such program here writes a marker file. The repository holds a racily clean file (its
index entry is as new as the index), so that git must hash the work-tree file to compare
it, which is when a filter runs; the test first shows that plain git does run them."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from archmetrics.sources.gitenv import config_environment, driver_overrides
from tests.gitrepo import _ENV, GitRepo
from tests.untrusted import run_main

pytestmark = pytest.mark.security

SOURCE = "def f(a):\n    if a:\n        return 1\n    return 2\n"
PLAN = '[architecture.a]\n[[architecture.a.element]]\nname = "a.py"\nstatements_added = 3\n'
HOOKS = ("post-index-change", "reference-transaction", "post-checkout", "pre-commit")


def _program(markers: Path, name: str) -> str:
    return f"touch {markers / name}; cat"


def _hostile_config(root: Path, markers: Path) -> str:
    """A ``.git/config`` whose every program leaves a marker named after its setting."""
    hooks = root / ".git" / "evil-hooks"
    hooks.mkdir()
    for hook in HOOKS:
        script = hooks / hook
        script.write_text(f"#!/bin/sh\ntouch {markers / ('hook-' + hook)}\n")
        script.chmod(0o755)
    programs = {
        "core": ["fsmonitor", "pager", "askPass", "sshCommand", "editor"],
        'filter "evil"': ["clean", "smudge", "process"],
        'diff "evil"': ["textconv", "command"],
        "diff": ["external"],
        "credential": ["helper"],
        "gpg": ["program"],
    }
    lines = []
    for section, keys in programs.items():
        lines.append(f"[{section}]")
        name = section.replace('"', "").replace(" ", ".")
        lines += [f'\t{key} = "{_program(markers, f"{name}.{key}")}"' for key in keys]
    lines += ["[core]", f"\thooksPath = {hooks}", '[filter "evil"]', "\trequired = true"]
    lines += ["[pager]", f'\tls-files = "{_program(markers, "pager.ls-files")}"']
    return "\n".join(lines) + "\n"


@pytest.fixture(scope="module")
def hostile(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """A repository with tags v1, v2, a staged and an unstaged change, a racily clean file
    and the hostile configuration; and the folder its markers go to."""
    top = tmp_path_factory.mktemp("git-programs")
    markers = top / "markers"
    markers.mkdir()
    repo = GitRepo(top / "repo")
    attributes = "* filter=evil diff=evil\n"
    files = {".gitattributes": attributes, "a.py": SOURCE, "c.py": SOURCE, "plan.toml": PLAN}
    repo.commit("one", tag="v1", files=files)
    repo.commit("two", tag="v2", files={"a.py": SOURCE + "x = 1\n"})
    repo.write({"b.py": SOURCE})
    repo.git("add", "b.py")
    repo.write({"a.py": SOURCE + "x = 2\n"})
    with (repo.root / ".git" / "config").open("a") as config:
        config.write(_hostile_config(repo.root, markers))
    index = repo.root / ".git" / "index"
    stamp = (repo.root / "c.py").stat().st_mtime
    os.utime(index, (stamp, stamp))  # c.py is racily clean: git compares its content
    return repo.root, markers


def _markers(markers: Path) -> list[str]:
    found = sorted(p.name for p in markers.iterdir())
    for path in markers.iterdir():
        path.unlink()
    return found


def test_plain_git_runs_the_repositorys_programs(hostile: tuple[Path, Path]) -> None:
    """The setup is hostile: git without archmetrics's environment runs fsmonitor and the
    filter (so the test below would see them), and with it runs neither."""
    root, markers = hostile
    env = {**os.environ, **_ENV, "GIT_OPTIONAL_LOCKS": "0"}
    for _ in range(2):  # the second time, env also holds archmetrics's overrides
        subprocess.run(["git", "diff-files"], cwd=root, env=env, capture_output=True)
        found = _markers(markers)
        if "GIT_CONFIG_COUNT" not in env:
            assert "core.fsmonitor" in found and "filter.evil.process" in found, found
            names = subprocess.run(
                ["git", "config", "--list", "--name-only"], cwd=root, env=env,
                capture_output=True, text=True, check=True,
            ).stdout.split()  # fmt: skip
            pairs = [("core.fsmonitor", "false"), *driver_overrides(names)]
            env.update(config_environment(pairs, env))
        else:
            assert found == []


COMMANDS = [
    ["scan", "."],
    ["scan", ".", "--rev", "v1"],
    ["scan", "a.py"],
    ["graph", "."],
    ["graph", ".", "--rev", "v2"],
    ["rules"],
    ["diff"],
    ["diff", "--base", "v1", "--head", "v2"],
    ["diff", "--base", "v1", "--head", "WORKTREE"],
    ["diff", "--base", "HEAD", "--head", "INDEX"],
    ["diff", "--base", "INDEX", "--head", "WORKTREE"],
    ["diff", "--base", "WORKTREE", "--head", "v1"],
    ["diff", "--base", "INDEX", "--head", "v2"],
    ["diff", "--base", "EMPTY", "--head", "WORKTREE"],
    ["series", "v1", "v2", "INDEX", "WORKTREE"],
    ["compare", "r=.", "--revisions", "v1,v2"],
    ["estimate", "plan.toml", "--base", "v2"],
    ["estimate", "plan.toml", "--base", "v1", "--actual", "--head", "WORKTREE"],
]


def test_no_command_runs_a_program_of_the_repository(hostile: tuple[Path, Path]) -> None:
    """Every command, on every kind of revision."""
    root, markers = hostile
    _markers(markers)
    for argv in COMMANDS:
        run = run_main([*argv] if argv[0] == "rules" else [*argv, "--no-cache"], root)
        assert run.code == 0, (argv, run.err)
        assert _markers(markers) == [], argv


@pytest.mark.parametrize("head", ["WORKTREE", "INDEX", "v2"])
def test_a_diff_patching_a_kept_state_runs_no_program(
    hostile: tuple[Path, Path], tmp_path: Path, head: str
) -> None:
    """With a facts cache, a diff keeps the base's state and asks git what changed since
    (gitdelta.py: git's processes started at once): the second run takes that path."""
    root, markers = hostile
    cache = ["--cache-path", str(tmp_path / "cache.sqlite3")]
    _markers(markers)
    for _ in range(2):
        run = run_main(["diff", "--base", "v1", "--head", head, *cache], root)
        assert run.code == 0, run.err
        assert _markers(markers) == []


def test_a_copied_repository_keeps_its_programs_disabled(
    hostile: tuple[Path, Path], tmp_path: Path
) -> None:
    """A copy of the repository (an artifact unpacked elsewhere, the path named from
    outside it) is read with the same overrides."""
    root, markers = hostile
    copy = tmp_path / "copy"
    shutil.copytree(root, copy, symlinks=True)
    _markers(markers)
    for argv in (["scan", str(copy)], ["diff", "-C", str(copy), "--base", "v1"]):
        run = run_main([*argv, "--no-cache"], tmp_path)
        assert run.code == 0, (argv, run.err)
        assert _markers(markers) == [], argv
