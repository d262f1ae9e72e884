"""Directory snapshots: what a folder outside git lists, all of it or only the paths asked for."""

from __future__ import annotations

from pathlib import Path

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
