"""What git says differs from a commit to another snapshot (sources/gitdelta.py), on real
repositories: the files it names are the files whose snapshot entries differ, with the blob
git knows (none for a work tree file it saw change), renames as ``git diff -M`` pairs them;
where the work tree holds entries git would take from the index (assume-unchanged,
skip-worktree, unmerged), no delta: the caller lists the tree."""

from __future__ import annotations

import contextlib
import os
import subprocess
from pathlib import Path

from hypothesis import given
from hypothesis import strategies as st

from archmetrics.sources import INDEX, WORKTREE, open_snapshot
from archmetrics.sources.gitdelta import Delta, _flagged
from archmetrics.sources.snapshot import blob_hash
from tests.gitrepo import GitRepo

FILES = {
    "a.py": "x = 1\n",
    "b.py": "y = 1\n",
    "sub/c.c": "int c(void) { return 1; }\n",
    "gone.py": "z = 1\n",
    "moved.py": "def long_function(a, b):\n    return a + b\n" * 5,
}


def _delta(repo: GitRepo, head: str, base: str = "HEAD") -> Delta | None:
    commit = repo.git("rev-parse", base).strip()
    snapshot = open_snapshot(repo.root, head)
    return snapshot.delta_from(commit)()  # type: ignore[attr-defined,no-any-return]


def _listing(repo: GitRepo, spec: str) -> dict[str, bytes]:
    snapshot = open_snapshot(repo.root, spec)
    return {f.path: snapshot.read(f) for f in snapshot.files()}


def _applied(
    base: dict[str, bytes], delta: Delta, snapshot_spec: str, repo: GitRepo
) -> dict[str, bytes]:
    """``base``'s files with ``delta`` applied, each read as the delta says."""
    snapshot = open_snapshot(repo.root, snapshot_spec)
    if hasattr(snapshot, "delta_from"):  # the work tree learns the names on disk
        snapshot.delta_from(repo.git("rev-parse", "HEAD").strip())()
    files = {p: data for p, data in base.items() if p not in delta.removed}
    for file in delta.changed:
        data = snapshot.read(file)
        if file.blob:
            assert blob_hash(data) == file.blob
        files[file.path] = data
    return files


def _history(repo: GitRepo) -> None:
    repo.commit("one", tag="v1", files=FILES)


def test_a_work_tree_delta_applied_to_its_base_is_the_work_tree(repo: GitRepo) -> None:
    _history(repo)
    repo.write({"a.py": "x = 2\n", "new.py": "n = 1\n", "sub/new.c": "int n;\n"})
    repo.write({"b.py": "y = 2\n"})
    repo.git("add", "b.py")  # staged, then edited again
    repo.write({"b.py": "y = 3\n"})
    repo.git("mv", "moved.py", "sub/moved_here.py")
    (repo.root / "gone.py").unlink()
    os.symlink("a.py", repo.root / "link.py")  # an untracked link: not a file of the tree
    (repo.root / ".gitignore").write_text("ignored.py\n")
    (repo.root / "ignored.py").write_text("i = 1\n")
    delta = _delta(repo, WORKTREE)
    assert delta is not None
    assert delta.renames == {"moved.py": "sub/moved_here.py"}
    assert {f.path: f.blob for f in delta.changed}["a.py"] == ""  # seen changed: read it
    base = _listing(repo, "HEAD")
    assert _applied(base, delta, WORKTREE, repo) == _listing(repo, WORKTREE)


def test_an_index_delta_and_a_commit_delta(repo: GitRepo) -> None:
    _history(repo)
    repo.write({"a.py": "x = 2\n", "new.py": "n = 1\n"})
    repo.git("add", "a.py", "new.py")
    repo.write({"a.py": "x = 3\n"})  # not staged: not the index's
    delta = _delta(repo, INDEX)
    assert delta is not None
    assert all(f.blob for f in delta.changed)
    assert _applied(_listing(repo, "HEAD"), delta, INDEX, repo) == _listing(repo, INDEX)
    repo.git("rm", "-q", "gone.py")
    repo.commit("two", tag="v2")
    delta = _delta(repo, "v2", base="v1")
    assert delta is not None and delta.removed == {"gone.py"}
    assert _applied(_listing(repo, "v1"), delta, "v2", repo) == _listing(repo, "v2")


def test_a_file_made_a_link_is_removed_and_a_link_made_a_file_added(repo: GitRepo) -> None:
    repo.commit("one", files={"a.py": "x = 1\n", "b.py": "y = 1\n"})
    os.symlink("a.py", repo.root / "c.py")
    repo.commit("two")
    (repo.root / "b.py").unlink()
    os.symlink("a.py", repo.root / "b.py")
    (repo.root / "c.py").unlink()
    (repo.root / "c.py").write_text("z = 1\n")
    delta = _delta(repo, WORKTREE)
    assert delta is not None
    assert "b.py" in delta.removed
    assert [f.path for f in delta.changed] == ["c.py"]
    assert _applied(_listing(repo, "HEAD"), delta, WORKTREE, repo) == _listing(repo, WORKTREE)


def test_entries_git_takes_from_the_index_give_no_delta(repo: GitRepo) -> None:
    _history(repo)
    repo.git("update-index", "--assume-unchanged", "a.py")
    assert _delta(repo, WORKTREE) is None
    repo.git("update-index", "--no-assume-unchanged", "a.py")
    assert _delta(repo, WORKTREE) is not None
    repo.git("update-index", "--skip-worktree", "b.py")
    assert _delta(repo, WORKTREE) is None


def test_an_unmerged_path_gives_no_delta(repo: GitRepo) -> None:
    _history(repo)
    repo.git("checkout", "-q", "-b", "other")
    repo.commit("theirs", files={"a.py": "x = 'theirs'\n"})
    repo.git("checkout", "-q", "main")
    repo.commit("ours", files={"a.py": "x = 'ours'\n"})
    with contextlib.suppress(subprocess.CalledProcessError):  # the conflict is the point
        repo.git("merge", "-q", "other")
    assert "a.py" in repo.git("diff", "--name-only", "--diff-filter=U")
    assert _delta(repo, WORKTREE) is None


def test_a_pending_delta_cancelled_leaves_no_process(repo: GitRepo, tmp_path: Path) -> None:
    _history(repo)
    commit = repo.git("rev-parse", "HEAD").strip()
    pending = open_snapshot(repo.root, WORKTREE).delta_from(commit)  # type: ignore[attr-defined]
    pending.cancel()
    assert all(p.returncode is not None for p in pending.processes)


@given(st.lists(st.tuples(st.sampled_from(["H", "h", "S", "M", "C", "K", "?"]),
                          st.text(alphabet="aH \n/é", min_size=1, max_size=6))))  # fmt: skip
def test_an_entry_tagged_other_than_h_is_found_in_any_listing(
    entries: list[tuple[str, str]],
) -> None:
    """``ls-files -z -v`` listings, paths with spaces, newlines and ``H`` in them."""
    listing = b"".join(f"{tag} {path}\0".encode() for tag, path in entries)
    assert _flagged(listing) == any(tag != "H" for tag, _ in entries)
