"""A repository's own configuration cannot make the facts cache touch anything but itself."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.gitrepo import GitRepo
from tests.untrusted import checksums, run_main

pytestmark = pytest.mark.security

SOURCE = "def f(a):\n    if a:\n        return 1\n    return 2\n"


@pytest.fixture
def env(tmp_path: Path) -> dict[str, str]:
    """No ARCHMETRICS_CACHE: the repository's cache-path is what decides."""
    return {"XDG_CACHE_HOME": str(tmp_path / "xdg"), "ARCHMETRICS_CACHE": ""}


def _configured(repo: GitRepo, cache_path: str) -> None:
    repo.commit(
        "v1",
        files={
            "pyproject.toml": f"[tool.archmetrics]\ncache-path = {cache_path!r}\n",
            "tracked.py": SOURCE,
        },
    )


@pytest.mark.parametrize(
    "target",
    [".git", "pyproject.toml", "tracked.py", ".git/index", ".git/HEAD", ""],
    ids=["git-dir", "the-config", "tracked-file", "git-index", "git-head", "repo-root"],
)
def test_a_cache_path_into_the_repository_is_refused(
    repo: GitRepo, env: dict[str, str], target: str
) -> None:
    _configured(repo, str(repo.root / target))
    before = checksums(repo.root)
    run = run_main(["scan", "."], repo.root, env)
    assert run.code == 2
    assert "outside archmetrics's cache directory" in run.one_line_error()
    assert checksums(repo.root) == before
    assert not (Path(env["XDG_CACHE_HOME"]) / "archmetrics").exists()


@pytest.mark.parametrize("target", ["/", "/dev/null", "~/.bashrc", "../../x.sqlite3"])
def test_a_cache_path_out_of_the_cache_directory_is_refused(
    repo: GitRepo, env: dict[str, str], target: str, tmp_path: Path
) -> None:
    _configured(repo, target)
    before = checksums(tmp_path)
    run = run_main(["scan", "."], repo.root, {**env, "HOME": str(tmp_path / "home")})
    assert run.code == 2
    assert "outside archmetrics's cache directory" in run.one_line_error()
    assert checksums(tmp_path) == before


def test_a_relative_cache_path_is_a_file_in_the_cache_directory(
    repo: GitRepo, env: dict[str, str]
) -> None:
    _configured(repo, ".git")
    before = checksums(repo.root)
    run = run_main(["scan", "."], repo.root, env)
    assert run.code == 0, run.err
    assert checksums(repo.root) == before
    assert (Path(env["XDG_CACHE_HOME"]) / "archmetrics" / ".git").is_file()


def test_the_runners_environment_outranks_the_repositorys_config(
    repo: GitRepo, env: dict[str, str], tmp_path: Path
) -> None:
    _configured(repo, str(repo.root / ".git"))
    mine = tmp_path / "mine.sqlite3"
    run = run_main(["scan", "."], repo.root, {**env, "ARCHMETRICS_CACHE": str(mine)})
    assert run.code == 0, run.err
    assert mine.is_file()


@pytest.mark.parametrize("target", ["tracked.py", ".git", "pyproject.toml"])
def test_the_cache_path_flag_never_overwrites_what_is_not_a_cache(
    repo: GitRepo, env: dict[str, str], target: str
) -> None:
    repo.commit("v1", files={"pyproject.toml": "[tool.archmetrics]\n", "tracked.py": SOURCE})
    before = checksums(repo.root)
    for argv in (["scan", "."], ["cache", "clear"], ["cache", "info"]):
        run = run_main([*argv, "--cache-path", target], repo.root, env)
        assert run.code == 2
        assert "facts cache" in run.one_line_error()
    assert checksums(repo.root) == before


def test_the_cache_path_flag_expands_the_home_directory(
    repo: GitRepo, env: dict[str, str], tmp_path: Path
) -> None:
    repo.commit("v1", files={"tracked.py": SOURCE})
    home = tmp_path / "home"
    run = run_main(["scan", ".", "--cache-path=~/c.sqlite3"], repo.root, {**env, "HOME": str(home)})
    assert run.code == 0, run.err
    assert (home / "c.sqlite3").is_file()
