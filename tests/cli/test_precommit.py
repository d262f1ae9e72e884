"""archmetrics as a hook of the real pre-commit framework, in a temporary repository.

pre-commit installs archmetrics from this checkout's HEAD commit into its own environment
(as it would from a tag on a host), so this test measures what is committed.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.gitrepo import GitRepo

ROOT = Path(__file__).resolve().parents[2]
PRE_COMMIT = Path(sys.executable).parent / "pre-commit"
IDENTITY = {
    "GIT_AUTHOR_NAME": "T",
    "GIT_AUTHOR_EMAIL": "t@example.invalid",
    "GIT_COMMITTER_NAME": "T",
    "GIT_COMMITTER_EMAIL": "t@example.invalid",
}


def _head() -> str:
    done = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "HEAD"], capture_output=True, text=True
    )
    if done.returncode != 0:
        pytest.skip("not running from a git checkout of archmetrics")
    return done.stdout.strip()


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_hook_gates_the_staged_change(repo: GitRepo, tmp_path: Path) -> None:
    repo.write(
        {
            ".pre-commit-config.yaml": f"repos:\n- repo: {ROOT}\n  rev: {_head()}\n"
            "  hooks:\n  - id: archmetrics\n",
            "archmetrics.toml": 'gates = ["added > 3"]\n',
            "a.py": "x = 1\n",
        }
    )
    env = {
        **os.environ,
        **IDENTITY,
        "PRE_COMMIT_HOME": str(ROOT / ".cache" / "pre-commit"),
        "ARCHMETRICS_CACHE": str(tmp_path / "facts.sqlite3"),
    }

    def run(*argv: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            argv, cwd=repo.root, env=env, capture_output=True, text=True, timeout=900
        )

    assert run(str(PRE_COMMIT), "install").returncode == 0
    repo.git("add", "-A")
    first = run("git", "commit", "-m", "first: 1 statement, under the gate")
    assert first.returncode == 0, first.stdout + first.stderr
    assert "archmetrics" in first.stdout + first.stderr  # the hook ran

    repo.write({"b.py": "".join(f"v{i} = {i}\n" for i in range(5))})
    repo.git("add", "b.py")
    staged = repo.git("diff", "--cached", "--stat")
    second = run("git", "commit", "-m", "second: 5 statements")
    assert second.returncode != 0
    assert "gate failed: added > 3 (added(total) = 5)" in second.stdout + second.stderr
    assert repo.git("diff", "--cached", "--stat") == staged  # the hook changed nothing
    assert repo.git("rev-list", "--count", "HEAD").strip() == "1"


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_hook_gates_the_range_pre_commit_is_given(repo: GitRepo, tmp_path: Path) -> None:
    """In CI, `pre-commit run --from-ref A --to-ref B` checks the commits A..B: the hook
    measures that range, not the (empty) staged change."""
    repo.write(
        {
            ".pre-commit-config.yaml": f"repos:\n- repo: {ROOT}\n  rev: {_head()}\n"
            "  hooks:\n  - id: archmetrics\n",
            "archmetrics.toml": 'gates = ["added > 3"]\n',
            "a.py": "x = 1\n",
        }
    )
    base = repo.commit("first: 1 statement")
    repo.write({"b.py": "".join(f"v{i} = {i}\n" for i in range(5))})
    head = repo.commit("second: 5 statements, committed without the hook")
    env = {
        **os.environ,
        **IDENTITY,
        "PRE_COMMIT_HOME": str(ROOT / ".cache" / "pre-commit"),
        "ARCHMETRICS_CACHE": str(tmp_path / "facts.sqlite3"),
    }

    def run(*argv: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run(
            [str(PRE_COMMIT), "run", "archmetrics", *argv],
            cwd=repo.root,
            env=env,
            capture_output=True,
            text=True,
            timeout=900,
        )

    ranged = run("--from-ref", base, "--to-ref", head)
    assert ranged.returncode == 1, ranged.stdout + ranged.stderr
    assert "gate failed: added > 3 (added(total) = 5)" in ranged.stdout + ranged.stderr


def _hooked(repo: GitRepo, tmp_path: Path, gates: str) -> dict[str, str]:
    """The repository configured to run this checkout's hook, and pre-commit's environment."""
    repo.write(
        {
            ".pre-commit-config.yaml": f"repos:\n- repo: {ROOT}\n  rev: {_head()}\n"
            "  hooks:\n  - id: archmetrics\n",
            "archmetrics.toml": f"gates = [{gates}]\n",
        }
    )
    return {
        **os.environ,
        **IDENTITY,
        "PRE_COMMIT_HOME": str(ROOT / ".cache" / "pre-commit"),
        "ARCHMETRICS_CACHE": str(tmp_path / "facts.sqlite3"),
    }


def _run(repo: GitRepo, env: dict[str, str], *argv: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        argv, cwd=repo.root, env=env, capture_output=True, text=True, timeout=900
    )


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_hook_runs_on_deletions_and_configuration_changes(repo: GitRepo, tmp_path: Path) -> None:
    """A commit that only deletes files, or only edits archmetrics.toml, is measured too (the
    hook's file filter used to match nothing staged, and pre-commit skipped it); a gate a
    commit adds holds from the next commit on."""
    env = _hooked(repo, tmp_path, '"removed > 3"')
    repo.write({"a.py": "".join(f"v{i} = {i}\n" for i in range(5)), "b.py": "x = 1\n"})
    assert _run(repo, env, str(PRE_COMMIT), "install").returncode == 0
    repo.git("add", "-A")
    first = _run(repo, env, "git", "commit", "-m", "first")
    assert first.returncode == 0, first.stdout + first.stderr
    repo.git("rm", "-q", "a.py")  # 5 statements removed, nothing else staged
    deleted = _run(repo, env, "git", "commit", "-m", "delete a.py")
    assert deleted.returncode != 0
    assert "gate failed: removed > 3 (removed(total) = 5)" in deleted.stdout + deleted.stderr
    repo.git("reset", "-q", "--hard")
    repo.write({"archmetrics.toml": 'gates = ["removed > 3", "loc_post < 100"]\n'})
    repo.git("add", "archmetrics.toml")
    configured = _run(repo, env, "git", "commit", "-m", "a stricter gate, nothing else")
    said = configured.stdout + configured.stderr
    # the hook ran on a configuration-only commit (pre-commit says Skipped when it does not),
    # under the gates of the commit's base: a commit cannot change the gates it is judged by
    assert configured.returncode == 0 and "Passed" in said and "Skipped" not in said, said
    repo.write({"b.py": "x = 2\n"})
    repo.git("add", "b.py")
    after = _run(repo, env, "git", "commit", "-m", "the next change")  # the new gate holds
    assert after.returncode != 0
    assert "gate failed: loc_post < 100" in after.stdout + after.stderr


@pytest.mark.slow
@pytest.mark.timeout(900)
def test_all_files_fails_with_the_fix_and_a_range_counts_from_the_merge_base(
    repo: GitRepo, tmp_path: Path
) -> None:
    """`pre-commit run --all-files` names no change: the hook says so instead of passing.
    With --from-ref/--to-ref on a branch behind main, only the branch's changes count,
    as pre-commit's own A...B file selection has it."""
    env = _hooked(repo, tmp_path, '"removed > 0"')
    repo.write({"a.py": "def f(a):\n    return a\n"})
    repo.commit("base")
    repo.git("checkout", "-q", "-b", "feature")
    repo.commit("feature", files={"a.py": "def f(a):\n    if a:\n        return 1\n    return a\n"})
    repo.git("checkout", "-q", "main")
    repo.commit("main moves on", files={"b.py": "def g(b):\n    return b\n"})
    repo.git("checkout", "-q", "feature")
    every = _run(repo, env, str(PRE_COMMIT), "run", "archmetrics", "--all-files")
    assert every.returncode == 1
    assert "pre-commit ran the hook on files, not on a change" in every.stdout
    assert "SKIP=archmetrics" in every.stdout
    ranged = _run(
        repo, env, str(PRE_COMMIT), "run", "archmetrics", "--from-ref", "main", "--to-ref", "HEAD"
    )
    assert ranged.returncode == 0, ranged.stdout + ranged.stderr  # main's b.py: not removed
    assert "removed > 0" not in ranged.stdout
