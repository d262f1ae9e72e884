"""docs/estimate.md's worked example, run: the bundled WDB subjects in one repository (a
branch per approach, a tag per stage), the plan docs/examples/wdb-first.toml estimated, then
each approach's plan against its measured first stage. The figures the page quotes must be
the ones archmetrics prints."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from archmetrics.cli import main
from tests.gitrepo import GitRepo

ROOT = Path(__file__).resolve().parents[2]
STUDY = ROOT / "fixtures" / "study" / "wdb"
PLAN = ROOT / "docs" / "examples" / "wdb-first.toml"
PAGE = (ROOT / "docs" / "estimate.md").read_text(encoding="utf-8")
LOCATIONS = [
    *("--new", "wdb/**"),
    *(a for glob in ("proxy", "service", "server", "interface", "driver")
      for a in ("--framework", f"{glob}/**")),
    *("--exclude", "generated/**", "--exclude", "interface/*.def"),
]  # fmt: skip
APPROACHES = ("soa", "player", "p2p")


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> GitRepo:
    repo = GitRepo(tmp_path_factory.mktemp("wdb") / "wdb")
    repo.commit("root")
    for approach in APPROACHES:
        repo.git("checkout", "-q", "-b", approach, "main")
        for stage in ("baseline", "first", "second"):
            for child in repo.root.iterdir():
                if child.name != ".git":
                    shutil.rmtree(child) if child.is_dir() else child.unlink()
            shutil.copytree(STUDY / approach / stage, repo.root, dirs_exist_ok=True)
            repo.commit(f"{approach} {stage}", tag=f"{approach}-{stage}")
    return repo


def markdown(study: GitRepo, capsys: pytest.CaptureFixture[str], *argv: str) -> str:
    code = main(["estimate", str(PLAN), "-C", str(study.root), *LOCATIONS, "-q", *argv])
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def test_the_page_quotes_the_estimate_and_its_ranking(
    study: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    out = markdown(study, capsys, "--format", "markdown")
    quoted = [line for line in PAGE.splitlines() if line.startswith("| `estimate` |")]
    assert len(quoted) == 3 and all(line in out.splitlines() for line in quoted)
    rows = [
        line for line in PAGE.splitlines() if line.startswith(("| Γ' | 6.25 |", "| E | 6.37 |"))
    ]
    assert len(rows) == 2 and all(row in out.splitlines() for row in rows)


@pytest.mark.parametrize("approach", APPROACHES)
def test_the_page_quotes_each_plans_errors_against_the_measured_stage(
    study: GitRepo, capsys: pytest.CaptureFixture[str], approach: str
) -> None:
    argv = ["--actual", "--architecture", approach, "--base", f"{approach}-baseline"]
    out = markdown(study, capsys, *argv, "--head", f"{approach}-first", "--format", "markdown")
    printed = {
        line.replace(f"| `{approach}` | total |", f"| `{approach}` |") for line in out.splitlines()
    }
    quoted = [line for line in PAGE.splitlines() if line.startswith(f"| `{approach}` | ")]
    assert quoted and all(line in printed for line in quoted)
