"""Reading a repository never writes to it, never fetches, and explains what it cannot read.

The CLI runs in this process (tests/untrusted.py ``run_main``): what is under test is the
files under the work tree and ``.git``, which the git processes archmetrics starts would
change the same way either way."""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path

import pytest

from tests.gitrepo import _ENV, GitRepo
from tests.untrusted import checksums, run_main

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


@pytest.fixture(scope="module")
def made_history(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """:func:`_history` made once per module (a dozen git commands)."""
    repo = GitRepo(tmp_path_factory.mktemp("readonly") / "repo")
    _history(repo)
    return repo.root


@pytest.fixture
def history(made_history: Path, tmp_path: Path) -> Path:
    """A copy of :func:`_history` of the test's own, the stale stat data included (a copied
    file keeps its modification time; its inode and change time differ from the index's)."""
    root = tmp_path / "repo"
    shutil.copytree(made_history, root, symlinks=True)
    return root


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
    history: Path, argv: list[str]
) -> None:
    before = checksums(history)
    run = run_main([*argv, "--no-cache"] if argv[0] != "graph" else argv, history)
    assert run.code == 0, run.err
    assert checksums(history) == before


@pytest.mark.parametrize("head", ["WORKTREE", "INDEX", "v2"])
def test_a_diff_patching_a_kept_state_changes_no_file(
    history: Path, tmp_path: Path, head: str
) -> None:
    """The incremental path (a cache, a base commit's kept state, git asked what differs)
    writes nothing under the work tree or .git either, stale index stat data included."""
    cache = ["--cache-path", str(tmp_path / "cache.sqlite3")]
    before = checksums(history)
    for _ in range(2):  # the base's state kept, then patched
        run = run_main(["diff", "--base", "v1", "--head", head, *cache], history)
        assert run.code == 0, run.err
    assert checksums(history) == before


def test_a_diff_works_while_another_git_holds_the_index_lock(history: Path) -> None:
    lock = history / ".git" / "index.lock"
    lock.write_bytes(b"held by a concurrent git commit")
    before = checksums(history)
    run = run_main(["diff", "--format", "json"], history)
    assert run.code == 0, run.err
    assert checksums(history) == before


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
    run = run_main(["diff", "--base", "v1", "--head", "v2", "--no-cache"], clone)
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
    run = run_main(["diff", "--base", "HEAD~1", "--head", "HEAD"], clone)
    assert run.code == 2
    assert "git fetch --unshallow" in run.one_line_error()
    assert checksums(clone) == before
    assert run_main(["diff", "--base", "HEAD", "--head", "HEAD"], clone).code == 0


def test_reflog_and_previous_branch_syntax(repo: GitRepo) -> None:
    repo.commit("one", files={"a.py": V1})
    repo.git("checkout", "-q", "-b", "topic")
    repo.commit("two", files={"a.py": V2})
    repo.git("checkout", "-q", "main")
    run = run_main(["diff", "--base", "HEAD", "--head", "@{-1}", "--format", "json"], repo.root)
    assert run.code == 0, run.err
    assert '"added"' in run.out
    assert run_main(["diff", "--base", "topic@{1}", "--head", "topic"], repo.root).code == 0
    for bad in ("@{-9}", "HEAD@{99}", "--output=x", "HEAD:a.py", "nope^{tree}"):
        run = run_main(["diff", f"--base={bad}"], repo.root)
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
        run = run_main(argv, repo.root, {"HOME": str(home), "GIT_CONFIG_NOSYSTEM": "1"})
        assert run.code == 2
        assert "safe.directory" in run.one_line_error()
