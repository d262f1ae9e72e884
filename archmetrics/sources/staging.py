"""Stage folders into a git repository: one commit and one tag per stage (for the study).

This is the only place archmetrics writes a repository, and it writes only a new one, in a
folder it is given: the study subjects ship as plain folders and become history here.
"""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Sequence
from pathlib import Path

from archmetrics.sources.snapshot import SourceError

_IDENTITY = {
    "GIT_AUTHOR_NAME": "archmetrics",
    "GIT_AUTHOR_EMAIL": "archmetrics@localhost",
    "GIT_COMMITTER_NAME": "archmetrics",
    "GIT_COMMITTER_EMAIL": "archmetrics@localhost",
    "GIT_CONFIG_NOSYSTEM": "1",
    "GIT_CONFIG_GLOBAL": os.devnull,
}
_IGNORE = shutil.ignore_patterns("__pycache__", "*.pyc", "*.o", "*.so", ".pytest_cache")


def _git(dest: Path, *args: str, date: str | None = None) -> None:
    env = {**os.environ, **_IDENTITY}
    if date:
        env["GIT_AUTHOR_DATE"] = env["GIT_COMMITTER_DATE"] = date
    done = subprocess.run(
        ["git", "-c", "commit.gpgsign=false", "-c", "core.autocrlf=false", *args],
        cwd=dest,
        env=env,
        capture_output=True,
        text=True,
    )
    if done.returncode != 0:
        raise SourceError(f"git {args[0]} in {dest} failed: {done.stderr.strip()}")


def build_stage_repository(dest: Path, stages: Sequence[tuple[str, Path]]) -> Path:
    """A new repository at ``dest`` (which must not exist or be empty) with a commit and a tag
    per stage, each commit holding exactly that stage's folder. Commit dates are fixed, so the
    same stages always give the same commit ids."""
    if dest.exists() and any(dest.iterdir()):
        raise SourceError(f"{dest}: exists and is not empty")
    dest.mkdir(parents=True, exist_ok=True)
    _git(dest, "init", "-q", "-b", "main")
    for number, (tag, folder) in enumerate(stages):
        for child in dest.iterdir():
            if child.name != ".git":
                shutil.rmtree(child) if child.is_dir() else child.unlink()
        shutil.copytree(folder, dest, dirs_exist_ok=True, ignore=_IGNORE)
        _git(dest, "add", "-A")
        stamp = f"2011-01-{number + 1:02d}T12:00:00+0000"
        _git(dest, "commit", "-q", "--allow-empty", "-m", f"stage {tag}", date=stamp)
        _git(dest, "tag", tag)
    return dest
