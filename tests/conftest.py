"""Shared fixtures."""

from __future__ import annotations

from pathlib import Path

import pytest

from tests.gitrepo import GitRepo


@pytest.fixture
def repo(tmp_path: Path) -> GitRepo:
    """An empty real git repository in a temporary folder."""
    return GitRepo(tmp_path / "repo")


@pytest.fixture(autouse=True)
def _private_cache(
    tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Tests never touch the user's facts cache."""
    path = tmp_path_factory.getbasetemp() / "facts-cache.sqlite3"
    monkeypatch.setenv("ARCHMETRICS_CACHE", str(path))
