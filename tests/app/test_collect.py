"""Parsing a snapshot: the process pool gives exactly what one process gives, and the cache
serves what it has seen by content, whatever the path."""

from __future__ import annotations

import json
import sqlite3
from pathlib import Path

import pytest

from archmetrics.app.collect import parse_all, select
from archmetrics.app.workers import FORK_BELOW as PARALLEL_THRESHOLD
from archmetrics.cli import main
from archmetrics.parsers import LanguageTable
from archmetrics.sources import WORKTREE, codec, open_snapshot
from archmetrics.sources.cache import FactsCache
from archmetrics.sources.snapshot import DirectorySnapshot, SourceFile, blob_hash
from tests.gitrepo import GitRepo
from tests.harness import facts_of

PY = "def f{i}(a):\n    if a > {i}:\n        return [x for x in a if x]\n    return None\n"
CLIENT = (
    'import zmq\n\nsock = zmq.Context().socket(zmq.REQ)\nsock.connect("tcp://localhost:5555")\n'
)
SERVER = 'import zmq\n\nsock = zmq.Context().socket(zmq.REP)\nsock.bind("tcp://*:5555")\n'
C = "int g{i}(int a) {{\n    switch (a) {{ case {i}: return 1; default: return a && {i}; }}\n}}\n"


def _tree(root: Path, count: int) -> DirectorySnapshot:
    for i in range(count):
        (root / f"p{i}.py").write_text(PY.format(i=i))
        (root / f"c{i}.c").write_text(C.format(i=i))
    return DirectorySnapshot(root)


def test_the_pool_gives_what_one_process_gives(tmp_path: Path) -> None:
    snapshot = _tree(tmp_path, PARALLEL_THRESHOLD)
    selected = select(snapshot, LanguageTable.default())
    assert len(selected) == 2 * PARALLEL_THRESHOLD
    serial = parse_all(snapshot, selected, jobs=1)
    pooled = parse_all(snapshot, selected, jobs=2)
    assert pooled == serial
    assert [f.path for f in pooled] == [s.file.path for s in selected]


def test_the_pool_stores_every_file_it_parses(tmp_path: Path) -> None:
    tree = tmp_path / "tree"
    tree.mkdir()
    snapshot = _tree(tree, PARALLEL_THRESHOLD)
    selected = select(snapshot, LanguageTable.default())
    with FactsCache(tmp_path / "cache.sqlite3") as cache:
        pooled = parse_all(snapshot, selected, jobs=2, cache=cache)
        assert (cache.hits, cache.misses) == (0, len(selected))
    with FactsCache(tmp_path / "cache.sqlite3") as cache:
        again = parse_all(snapshot, selected, jobs=2, cache=cache)
        assert (cache.hits, cache.misses) == (len(selected), 0)
    assert again == pooled


def test_the_cache_serves_by_content(tmp_path: Path) -> None:
    tree = tmp_path / "tree"
    tree.mkdir()
    snapshot = _tree(tree, 3)
    selected = select(snapshot, LanguageTable.default())
    with FactsCache(tmp_path / "cache.sqlite3") as cache:
        first = parse_all(snapshot, selected, jobs=1, cache=cache)
        assert (cache.hits, cache.misses) == (0, 6)
        again = parse_all(snapshot, selected, jobs=1, cache=cache)
        assert again == first and cache.hits == 6
    (tree / "moved.py").write_text(PY.format(i=0))  # same content as p0.py, another path
    with FactsCache(tmp_path / "cache.sqlite3") as cache:
        moved = [
            s
            for s in select(DirectorySnapshot(tree), LanguageTable.default())
            if s.file.path == "moved.py"
        ]
        [facts] = parse_all(DirectorySnapshot(tree), moved, jobs=1, cache=cache)
        assert cache.hits == 1 and facts.path == "moved.py"
        assert facts.functions == first[[s.file.path for s in selected].index("p0.py")].functions


def test_a_diff_is_the_same_without_cache_cold_and_warm(repo: GitRepo, tmp_path: Path) -> None:
    """The pool sends facts in the cache's encoding: no path may change a number."""

    def tree(change: str = "") -> dict[str, str | bytes]:
        files: dict[str, str | bytes] = {
            f"src/m{i}.py": PY.format(i=i) + change for i in range(PARALLEL_THRESHOLD)
        }
        files |= {
            f"native/c{i}.c": C.format(i=i) + change.replace("#", "//")
            for i in range(PARALLEL_THRESHOLD)
        }
        files["src/broken.py"] = "def broken(:\n    pass\n"
        # a run-time link: dynamic coupling reads these call sites, decoded or parsed
        files["src/client.py"] = CLIENT + change
        files["src/server.py"] = SERVER
        return files

    repo.commit("one", tag="v1", files=tree())
    repo.commit("two", tag="v2", files=tree("# changed\nx = 1\n"))
    diff = [
        "diff",
        "-C",
        str(repo.root),
        "--base",
        "v1",
        "--head",
        "v2",
        "-j",
        "2",
        "--format",
        "json",
        "-q",
    ]
    cache = ["--cache-path", str(tmp_path / "cache.sqlite3")]

    def run(*extra: str) -> object:
        out = tmp_path / "out.json"
        assert main([*diff, *extra, "-o", str(out)]) == 0
        return json.loads(out.read_text())

    plain = run("--no-cache")
    client = next(e for e in plain["elements"] if e["element"] == "src/client.py")  # type: ignore[index]
    assert client["post"]["d_e"] == 1  # the link is there to be found
    assert run(*cache) == plain  # cold
    assert run(*cache) == plain  # warm


def test_facts_parsed_in_a_run_read_their_statements_back_from_the_cache(
    tmp_path: Path,
) -> None:
    # a cold run keeps no statement bytes either: what the workers sent is in the cache
    repo_file = tmp_path / "src" / "m.py"
    repo_file.parent.mkdir()
    repo_file.write_text("def f(a):\n    if a:\n        return 1\n    return 2\n")
    path = tmp_path / "cache.sqlite3"
    snapshot = DirectorySnapshot(tmp_path / "src")
    with FactsCache(path) as cache:
        (facts,) = parse_all(snapshot, select(snapshot, LanguageTable.default()), cache=cache)
    head, body = codec.split(codec.encode(facts_of("x = 1\n", "python")))
    with sqlite3.connect(path) as db:  # rewritten once the run has closed the cache
        db.execute("update facts set data = ?", (head,))
        db.execute("update bodies set data = ?", (body,))
    with pytest.raises(codec.CodecError, match="no longer in the facts cache"):
        facts.statements.items()
    assert facts.functions[0].complexity == 2  # what was decoded stays


def test_a_worktree_file_whose_bytes_differ_from_its_blob_is_kept_under_its_bytes(
    repo: GitRepo, tmp_path: Path
) -> None:
    # with core.autocrlf the checkout holds CRLF where the blob holds LF, and git finds the
    # file unchanged: the index's blob is taken for the look-up, but facts parsed from the
    # bytes on disk are kept under those bytes' blob, never under another's
    repo.git("config", "core.autocrlf", "true")
    repo.commit("one", files={"m.py": "x = 1\n"})
    (repo.root / "m.py").unlink()
    repo.git("checkout", "--", "m.py")
    on_disk = (repo.root / "m.py").read_bytes()
    assert on_disk == b"x = 1\r\n"
    snapshot = open_snapshot(repo.root, WORKTREE)
    [file] = snapshot.files()
    assert file.blob == blob_hash(b"x = 1\n")  # git's view: unchanged
    blobs: dict[str, str] = {}
    with FactsCache(tmp_path / "cache.sqlite3") as cache:
        selected = select(snapshot, LanguageTable.default())
        (facts,) = parse_all(snapshot, selected, cache=cache, blobs=blobs)
        assert facts.parsed and facts.sloc == 1
        assert blobs == {"m.py": blob_hash(on_disk)}
        assert cache.get(blob_hash(on_disk), "python", "m.py") is not None
        assert cache.get(blob_hash(b"x = 1\n"), "python", "m.py") is None


class _Recording(DirectorySnapshot):
    """Files on disk whose blobs are known (as a work tree's staged files are), so that each
    is read only when its batch goes to a worker: the reads are the order of parsing."""

    def __init__(self, root: Path, paths: list[str]) -> None:
        super().__init__(root, paths)
        self._hashes = {path: blob_hash((root / path).read_bytes()) for path in paths}
        self.reads: list[str] = []

    def read(self, file: SourceFile) -> bytes:
        self.reads.append(file.path)
        return super().read(file)


class _Unsized:
    """The same files where no size can be known without reading (a revision's blobs)."""

    def __init__(self, inner: _Recording) -> None:
        self.inner, self.label = inner, inner.label

    def files(self) -> tuple[SourceFile, ...]:
        return self.inner.files()

    def read(self, file: SourceFile) -> bytes:
        return self.inner.read(file)


def test_the_largest_files_are_parsed_first_where_sizes_are_known(tmp_path: Path) -> None:
    """The last batches hold the smallest files, so no worker is left with a large one when
    the others are done; files of unknown size keep their order."""
    functions = {"a.c": 1, "b.c": 40, "c.c": 8, "d.c": 20}
    for name, count in functions.items():
        (tmp_path / name).write_text("".join(C.format(i=i) for i in range(count)))
    snapshot = _Recording(tmp_path, list(functions))
    selected = select(snapshot, LanguageTable.default())
    facts = parse_all(snapshot, selected, jobs=1)
    assert snapshot.reads == ["b.c", "d.c", "c.c", "a.c"]
    assert [f.path for f in facts] == ["a.c", "b.c", "c.c", "d.c"]  # reported as listed
    unsized = _Unsized(_Recording(tmp_path, list(functions)))
    parse_all(unsized, select(unsized, LanguageTable.default()), jobs=1)
    assert unsized.inner.reads == ["a.c", "b.c", "c.c", "d.c"]
