"""Directory snapshots: what a folder outside git lists, all of it or only the paths asked for."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from archmetrics.sources.snapshot import DirectorySnapshot


def _tree(root: Path) -> None:
    for path in (
        "z.c",
        "a/x.c",
        "a/b/y.c",
        "a/m.c",
        "a/.venv/lib.py",
        "c/deep/er/w.c",
        "c/v.c",
        "other/huge.c",
    ):
        (root / path).parent.mkdir(parents=True, exist_ok=True)
        (root / path).write_text("int x;\n")


def test_a_snapshot_within_paths_lists_only_them_in_the_order_of_the_whole_walk(
    tmp_path: Path,
) -> None:
    _tree(tmp_path)
    whole = [f.path for f in DirectorySnapshot(tmp_path).files()]
    assert whole == ["z.c", "a/m.c", "a/x.c", "a/b/y.c", "c/v.c", "c/deep/er/w.c", "other/huge.c"]
    within = DirectorySnapshot(tmp_path, within=["c", "a/b/y.c", "z.c", "a/m.c", "c/v.c"])
    listed = [f.path for f in within.files()]
    assert listed == [p for p in whole if p != "a/x.c" and not p.startswith("other/")]
    assert [f.path for f in DirectorySnapshot(tmp_path, within=["", "a"]).files()] == whole


def test_a_folder_is_skipped_for_what_it_is_not_for_its_name(tmp_path: Path) -> None:
    for path in (
        "venv/__init__.py",  # a package named venv (the standard library has one): code
        "env/pyvenv.cfg",  # a virtual environment, whatever its name
        "env/lib/site.py",
        "src/__pycache__/m.cpython-311.pyc",
        "src/m.py",
        "pkg.egg-info/PKG-INFO",
        "node_modules/x/index.js",
        "conda/conda-meta/history",  # a conda environment
        "conda/lib/x.py",
    ):
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text("x = 1\n")
    snapshot = DirectorySnapshot(tmp_path)
    assert [f.path for f in snapshot.files()] == ["src/m.py", "venv/__init__.py"]
    assert snapshot.skipped == {
        "conda/": "conda environment (conda-meta)",
        "env/": "virtual environment (pyvenv.cfg)",
        "node_modules/": "npm packages",
        "pkg.egg-info/": "package metadata",
        "src/__pycache__/": "bytecode cache",
    }


GITIGNORED = {
    ".gitignore": "build/\n*.log\n!keep.log\n/top.py\ndocs/**/draft*\n",
    "sub/.gitignore": "local.py\n!/top.py\n*.py\n!wanted.py\n",
    "a.py": "", "top.py": "", "keep.log": "", "x.log": "", "sub/top.py": "", "sub/local.py": "",
    "sub/wanted.py": "", "sub/deep/more.py": "", "sub/deep/note.txt": "", "build/gen.py": "",
    "src/build/gen.c": "", "docs/a/draft1.md": "", "docs/a/final.md": "", "src/m.c": "",
    "weird name [x].py": "", "src/#literal.c": "", "src/x.tmp": "", "src/[z-a].c": "",
    "src/.gitignore": "\\#literal.c\n[z-a].c\n*.tmp\n",  # git skips the bad range alone
}  # fmt: skip


def test_a_plain_folder_ignores_what_git_would_ignore(tmp_path: Path) -> None:
    # outside git, the folder's .gitignore files are read as git reads them (the deeper file
    # wins, the last match wins, ! re-includes, a leading / anchors to its folder): the
    # files a folder snapshot lists are the files git would list as untracked
    for name, text in GITIGNORED.items():
        (tmp_path / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / name).write_text(text)
    snapshot = DirectorySnapshot(tmp_path)
    ours = {f.path for f in snapshot.files()}
    subprocess.run(["git", "init", "-q", str(tmp_path)], check=True)
    listed = subprocess.run(
        ["git", "-C", str(tmp_path), "ls-files", "--others", "--exclude-standard", "-z"],
        capture_output=True, text=True, check=True,
    ).stdout  # fmt: skip
    assert ours == set(filter(None, listed.split("\0")))
    assert snapshot.skipped["build/"] == "ignored by .gitignore"
    assert snapshot.skipped["sub/local.py"] == "ignored by .gitignore"
    assert "sub/wanted.py" in ours and "keep.log" in ours and "sub/top.py" not in ours


@pytest.mark.security
def test_a_hostile_gitignore_cannot_backtrack(tmp_path: Path) -> None:
    """Under Python's re, pathspec's regex of this pattern against a 250-character name
    backtracks for hours (five stars on 200 characters took 7 s, six 148 s); RE2 cannot."""
    (tmp_path / ".gitignore").write_text("*a" * 12 + "*b\n" + "a/" + "**/a/" * 40 + "c\n")
    (tmp_path / ("a" * 250)).write_text("")
    (tmp_path / ("a" * 249 + "b")).write_text("")
    assert {f.path for f in DirectorySnapshot(tmp_path).files()} == {".gitignore", "a" * 250}


@pytest.mark.security
def test_a_gitignore_too_large_or_unreadable_counts_as_absent(tmp_path: Path) -> None:
    (tmp_path / "a.py").write_text("")
    (tmp_path / ".gitignore").write_bytes(b"*.py\n" + b"#" * (1 << 20))
    assert {f.path for f in DirectorySnapshot(tmp_path).files()} == {"a.py", ".gitignore"}
