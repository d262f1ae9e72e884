"""Shared fixtures."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

from tests.gitrepo import GitRepo

# No test asserts a time: hypothesis's per-example deadline and its "too slow" health check
# are clocks, which a loaded machine (CI's two cores, other jobs) trips without a defect.
settings.register_profile(
    "archmetrics", deadline=None, suppress_health_check=[HealthCheck.too_slow]
)
settings.load_profile("archmetrics")


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
