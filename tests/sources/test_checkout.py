"""sources/checkout.py: a repository (or folder) opened once, asked for snapshots, renames
and tags, on real repositories."""

from __future__ import annotations

from pathlib import Path

import pytest

from archmetrics.cli import main
from archmetrics.sources import EMPTY, INDEX, WORKTREE, SourceError, git
from archmetrics.sources.checkout import Checkout, open_checkout
from tests.gitrepo import GitRepo


def _paths(checkout: Checkout, spec: str | None) -> list[str]:
    return sorted(f.path for f in checkout.snapshot(spec).files())


def test_a_repository_opened_from_a_subfolder_answers_every_snapshot(tmp_path: Path) -> None:
    repo = GitRepo(tmp_path / "r")
    repo.commit("one", tag="v1", files={"src/a.py": "x = 1\n"})
    repo.git("mv", "src/a.py", "src/b.py")
    repo.commit("two", tag="v2", files={"src/c.py": "y = 2\n"})
    repo.write({"src/d.py": "z = 3\n"})
    checkout = open_checkout(repo.root / "src")
    assert checkout.root == repo.root and checkout.repo is not None
    assert _paths(checkout, "v1") == ["src/a.py"]
    assert _paths(checkout, "v2") == _paths(checkout, INDEX) == ["src/b.py", "src/c.py"]
    assert (
        _paths(checkout, WORKTREE)
        == _paths(checkout, None)
        == [
            "src/b.py",
            "src/c.py",
            "src/d.py",
        ]
    )
    assert _paths(checkout, EMPTY) == []
    assert checkout.renames("v1", "v2") == {"src/a.py": "src/b.py"}
    assert checkout.tags() == ("v1", "v2")


def test_a_folder_outside_git_is_its_own_root(tmp_path: Path) -> None:
    (tmp_path / "plain").mkdir()
    (tmp_path / "plain" / "a.c").write_text("int f(void) { return 0; }\n")
    checkout = open_checkout(tmp_path / "plain")
    assert checkout == checkout and checkout.repo is None and checkout.root == tmp_path / "plain"
    assert _paths(checkout, None) == ["a.c"]
    assert checkout.renames("HEAD", WORKTREE) == {}
    with pytest.raises(SourceError, match="not inside a git repository"):
        checkout.snapshot("HEAD")
    with pytest.raises(SourceError, match="not inside a git repository"):
        checkout.tags()


def test_a_repository_without_tags_says_to_give_revisions(tmp_path: Path) -> None:
    repo = GitRepo(tmp_path / "r")
    repo.commit("one", files={"a.py": "x = 1\n"})
    with pytest.raises(SourceError, match="no tags to take stages from; give --revisions"):
        open_checkout(repo.root).tags()


@pytest.mark.parametrize(
    "command",
    [
        ["diff", "--base", "v1", "--head", "WORKTREE"],
        ["series", "v1", "v2"],
        ["compare", "one={root}"],
    ],
)
def test_a_diff_or_a_series_opens_its_repository_once(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, command: list[str]
) -> None:
    """The settings, the rule packs, every snapshot and the renames come from one opening
    (each opening runs git's own checks in a subprocess)."""
    repo = GitRepo(tmp_path / "r")
    repo.commit("one", tag="v1", files={"a.py": "import b\n", "b.py": "x = 1\n"})
    repo.commit("two", tag="v2", files={"b.py": "x = 2\nif x:\n    x = 3\n"})
    opened: list[Path] = []
    real = git.find_repository

    def counted(path: Path) -> object:
        opened.append(path)
        return real(path)

    monkeypatch.setattr(git, "find_repository", counted)
    arguments = [part.format(root=repo.root) for part in command]
    arguments += [] if command[0] == "compare" else ["-C", str(repo.root)]
    arguments += ["--no-cache", "-q", "--format", "json"]
    assert main(arguments) == 0
    assert len(opened) == 1
