"""Snapshots of real repositories: revisions, the index, the working tree, renames."""

from __future__ import annotations

from pathlib import Path

import pytest

from archmetrics.sources import INDEX, WORKTREE, SourceError, open_snapshot
from archmetrics.sources.git import open_repository, renames
from archmetrics.sources.snapshot import DirectorySnapshot, blob_hash
from tests.gitrepo import GitRepo


def _contents(snapshot: object) -> dict[str, bytes]:
    files = snapshot.files()  # type: ignore[attr-defined]
    return {f.path: snapshot.read(f) for f in files}  # type: ignore[attr-defined]


def test_revision_index_and_worktree_differ_as_git_says(repo: GitRepo) -> None:
    repo.commit("one", tag="v1", files={"a.py": "x = 1\n", "sub/b.c": "int b;\n"})
    repo.write({"a.py": "x = 2\n"})
    repo.git("add", "a.py")
    repo.write({"a.py": "x = 3\n", "new.py": "y = 1\n"})

    assert _contents(open_snapshot(repo.root, "v1")) == {"a.py": b"x = 1\n", "sub/b.c": b"int b;\n"}
    assert _contents(open_snapshot(repo.root, INDEX))["a.py"] == b"x = 2\n"
    worktree = _contents(open_snapshot(repo.root, WORKTREE))
    assert worktree["a.py"] == b"x = 3\n" and worktree["new.py"] == b"y = 1\n"


def test_revision_blobs_are_git_blob_ids(repo: GitRepo) -> None:
    repo.commit("one", files={"a.py": "x = 1\n"})
    [file] = open_snapshot(repo.root, "HEAD").files()
    assert file.blob == repo.git("rev-parse", "HEAD:a.py").strip() == blob_hash(b"x = 1\n")


def test_worktree_files_unchanged_since_staged_carry_the_index_blob(repo: GitRepo) -> None:
    # a tracked file git finds as staged is neither read nor hashed: its blob is the index's;
    # a modified, an untracked and an assume-unchanged file (whose change git would not see)
    # carry none and are hashed from their bytes; a skip-worktree file not on disk is absent
    files = {"same.py": "x = 1\n", "edited.py": "y = 1\n", "hidden.py": "z = 1\n"}
    repo.commit("one", files={**files, "sparse.py": "w = 1\n"})
    repo.git("update-index", "--assume-unchanged", "hidden.py")
    repo.git("update-index", "--skip-worktree", "sparse.py")
    (repo.root / "sparse.py").unlink()
    repo.write({"edited.py": "y = 2\n", "hidden.py": "z = 2\n", "new.py": "v = 1\n"})
    blobs = {f.path: f.blob for f in open_snapshot(repo.root, WORKTREE).files()}
    assert blobs == {
        "same.py": blob_hash(b"x = 1\n"),
        "edited.py": "",
        "hidden.py": "",
        "new.py": "",
    }


def test_unknown_revision_is_a_one_line_error(repo: GitRepo) -> None:
    repo.commit("one", files={"a.py": "x = 1\n"})
    with pytest.raises(SourceError, match="unknown revision 'nope'"):
        open_snapshot(repo.root, "nope")


def test_worktree_skips_ignored_files(repo: GitRepo) -> None:
    repo.commit("one", files={".gitignore": "build/\n", "a.py": "x = 1\n"})
    repo.write({"build/gen.py": "z = 1\n"})
    paths = {f.path for f in open_snapshot(repo.root, WORKTREE).files()}
    assert "build/gen.py" not in paths and "a.py" in paths


def test_renames_follow_git(repo: GitRepo) -> None:
    body = "".join(f"value_{i} = {i}\n" for i in range(30))
    repo.commit("one", tag="v1", files={"old/name.py": body})
    (repo.root / "new").mkdir()
    repo.git("mv", "old/name.py", "new/name.py")
    repo.commit("two", tag="v2", files={"new/name.py": body + "extra = 1\n"})
    git_repo = open_repository(repo.root)
    assert renames(git_repo, "v1", "v2") == {"old/name.py": "new/name.py"}
    assert renames(git_repo, "v1", WORKTREE) == {"old/name.py": "new/name.py"}


def test_reading_changes_nothing(repo: GitRepo) -> None:
    repo.commit("one", files={"a.py": "x = 1\n"})
    repo.write({"a.py": "x = 2\n", "b.py": "y = 1\n"})
    before = repo.status()
    for spec in ("HEAD", INDEX, WORKTREE):
        _contents(open_snapshot(repo.root, spec))
    assert repo.status() == before


def test_directory_snapshot_outside_git(tmp_path: Path) -> None:
    (tmp_path / "pkg").mkdir()
    (tmp_path / "pkg" / "m.py").write_text("x = 1\n")
    (tmp_path / ".venv").mkdir()
    (tmp_path / ".venv" / "skip.py").write_text("y = 1\n")
    snapshot = open_snapshot(tmp_path, None)
    assert isinstance(snapshot, DirectorySnapshot)
    assert [f.path for f in snapshot.files()] == ["pkg/m.py"]


def test_head_of_a_repository_without_commits_is_the_empty_tree(repo: GitRepo) -> None:
    repo.write({"a.py": "x = 1\n"})
    repo.git("add", "a.py")
    assert open_snapshot(repo.root, "HEAD").files() == ()
    assert [f.path for f in open_snapshot(repo.root, INDEX).files()] == ["a.py"]
    assert renames(open_repository(repo.root), "HEAD", INDEX) == {}
