"""Reading a repository never writes to it, never fetches, and explains what it cannot read."""

from __future__ import annotations

import os
import subprocess
import time
from pathlib import Path

import pytest

from tests.gitrepo import _ENV, GitRepo
from tests.untrusted import checksums, run_cli

pytestmark = pytest.mark.security

V1 = "def f(a):\n    if a:\n        return 1\n    return 2\n"
V2 = V1 + "\n\ndef g(b):\n    return [x for x in b if x]\n"


def _history(repo: GitRepo) -> None:
    repo.commit(
        "one", tag="v1", files={"a.py": V1, "b.py": V1, "c/m.c": "int m(void){return 0;}\n"}
    )
    repo.commit("two", tag="v2", files={"a.py": V2})
    repo.git("mv", "b.py", "renamed.py")
    repo.write({"staged.py": V1})
    repo.git("add", "staged.py")
    repo.write({"a.py": V2 + "\nx = 1\n", "untracked.py": V2})
    past = time.time() + 5  # every tracked file's stat no longer matches the index
    for path in repo.root.rglob("*.py"):
        os.utime(path, (past, past))


@pytest.mark.parametrize(
    "argv",
    [
        ["diff"],
        ["diff", "--base", "v1", "--head", "WORKTREE"],
        ["diff", "--base", "INDEX", "--head", "WORKTREE"],
        ["diff", "--base", "HEAD", "--head", "INDEX"],
        ["diff", "--base", "WORKTREE", "--head", "v1"],
        ["diff", "--base", "INDEX", "--head", "v2"],
        ["diff", "--base", "v1", "--head", "v2"],
        ["series", "v1", "v2", "INDEX", "WORKTREE"],
        ["scan", "."],
        ["scan", ".", "--rev", "v1"],
        ["graph", "."],
    ],
    ids=lambda argv: "-".join(argv),
)
def test_measuring_changes_no_file_under_the_work_tree_or_git(
    repo: GitRepo, argv: list[str]
) -> None:
    _history(repo)
    before = checksums(repo.root)
    run = run_cli([*argv, "--no-cache"] if argv[0] != "graph" else argv, repo.root)
    assert run.code == 0, run.err
    assert checksums(repo.root) == before


@pytest.mark.parametrize("head", ["WORKTREE", "INDEX", "v2"])
def test_a_diff_patching_a_kept_state_changes_no_file(
    repo: GitRepo, tmp_path: Path, head: str
) -> None:
    """The incremental path (a cache, a base commit's kept state, git asked what differs)
    writes nothing under the work tree or .git either, stale index stat data included."""
    _history(repo)
    cache = ["--cache-path", str(tmp_path / "cache.sqlite3")]
    before = checksums(repo.root)
    for _ in range(2):  # the base's state kept, then patched
        run = run_cli(["diff", "--base", "v1", "--head", head, *cache], repo.root)
        assert run.code == 0, run.err
    assert checksums(repo.root) == before


def test_a_diff_works_while_another_git_holds_the_index_lock(repo: GitRepo) -> None:
    _history(repo)
    lock = repo.root / ".git" / "index.lock"
    lock.write_bytes(b"held by a concurrent git commit")
    before = checksums(repo.root)
    run = run_cli(["diff", "--format", "json"], repo.root)
    assert run.code == 0, run.err
    assert checksums(repo.root) == before


def _clone(source: GitRepo, dest: Path, *options: str) -> Path:
    source.git("config", "uploadpack.allowFilter", "true")
    subprocess.run(
        ["git", "clone", "-q", *options, source.root.resolve().as_uri(), str(dest)],
        check=True,
        env={**os.environ, **_ENV},
        capture_output=True,
    )
    return dest


def test_a_partial_clone_is_not_fetched_into(repo: GitRepo, tmp_path: Path) -> None:
    repo.commit("one", tag="v1", files={"a.py": V1})
    repo.commit("two", tag="v2", files={"a.py": V2})
    clone = _clone(repo, tmp_path / "partial", "--filter=blob:none", "--no-checkout")
    before = checksums(clone)
    run = run_cli(["diff", "--base", "v1", "--head", "v2", "--no-cache"], clone)
    assert run.code == 2
    assert "partial clone" in run.one_line_error()
    assert checksums(clone) == before


def test_a_revision_beyond_a_shallow_clone_says_how_to_fetch_it(
    repo: GitRepo, tmp_path: Path
) -> None:
    repo.commit("one", files={"a.py": V1})
    repo.commit("two", files={"a.py": V2})
    clone = _clone(repo, tmp_path / "shallow", "--depth", "1")
    before = checksums(clone)
    run = run_cli(["diff", "--base", "HEAD~1", "--head", "HEAD"], clone)
    assert run.code == 2
    assert "git fetch --unshallow" in run.one_line_error()
    assert checksums(clone) == before
    assert run_cli(["diff", "--base", "HEAD", "--head", "HEAD"], clone).code == 0


def test_reflog_and_previous_branch_syntax(repo: GitRepo) -> None:
    repo.commit("one", files={"a.py": V1})
    repo.git("checkout", "-q", "-b", "topic")
    repo.commit("two", files={"a.py": V2})
    repo.git("checkout", "-q", "main")
    run = run_cli(["diff", "--base", "HEAD", "--head", "@{-1}", "--format", "json"], repo.root)
    assert run.code == 0, run.err
    assert '"added"' in run.out
    assert run_cli(["diff", "--base", "topic@{1}", "--head", "topic"], repo.root).code == 0
    for bad in ("@{-9}", "HEAD@{99}", "--output=x", "HEAD:a.py", "nope^{tree}"):
        run = run_cli(["diff", f"--base={bad}"], repo.root)
        assert run.code == 2
        assert f"unknown revision {bad!r}" in run.one_line_error()
    assert not (repo.root / "x").exists()


@pytest.mark.skipif(os.geteuid() != 0, reason="needs root to give the repository away")
def test_a_repository_owned_by_another_user(repo: GitRepo, tmp_path: Path) -> None:
    repo.commit("one", files={"a.py": V1})
    subprocess.run(["chown", "-R", "nobody", str(repo.root)], check=True)
    home = tmp_path / "home"
    home.mkdir()
    for argv in (["diff"], ["scan", "."], ["diff", "--base", "HEAD", "--head", "HEAD"]):
        run = run_cli(argv, repo.root, {"HOME": str(home), "GIT_CONFIG_NOSYSTEM": "1"})
        assert run.code == 2
        assert "safe.directory" in run.one_line_error()
