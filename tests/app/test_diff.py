"""A diff keeps what each commit's tree adds up to (its state: the files' rows and the
coupling index) in the facts cache, keyed by all that decides it, and serves it back byte
for byte; a bad entry is recomputed."""

from __future__ import annotations

import json
import sqlite3
import zlib
from pathlib import Path

import pytest

from archmetrics.app.diff import run_diff
from archmetrics.app.diff_options import DiffRequest
from archmetrics.app.scan import ScanRequest, run_scan
from archmetrics.cli import main
from archmetrics.config import load_settings
from tests.gitrepo import GitRepo

CLIENT = 'import zmq\nimport shared\n\nsock = zmq.Context().socket(zmq.REQ)\nsock.connect("tcp://localhost:5555")\n'
SERVER = 'import zmq\n\nsock = zmq.Context().socket(zmq.REP)\nsock.bind("tcp://*:5555")\n'
SHARED = "def helper(a):\n    return a if a else None\n"


@pytest.fixture
def history(repo: GitRepo) -> GitRepo:
    repo.commit("one", tag="v1", files={"src/client.py": CLIENT, "src/shared.py": SHARED})
    repo.commit(
        "two",
        tag="v2",
        files={"src/server.py": SERVER, "src/shared.py": SHARED + "\nLIMIT = 3\n"},
    )
    return repo


def _diff(repo: GitRepo, tmp_path: Path, *extra: str) -> bytes:
    out = tmp_path / "out.json"
    command = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2", "-q"]
    assert main([*command, "--format", "json", *extra, "-o", str(out)]) == 0
    return out.read_bytes()


def _totals(cache: Path) -> list[tuple[str, bytes]]:
    """The trees' states kept in the cache (file pairs' changes are kept beside them)."""
    with sqlite3.connect(cache) as db:
        return db.execute(
            "select key, data from totals where key not like 'file-change/%'"
            " and key not like 'generated-head/%' and key not like 'link-sites/%' order by key"
        ).fetchall()


def _changes(cache: Path) -> list[tuple[str, bytes]]:
    """The file pairs' changes kept in the cache."""
    with sqlite3.connect(cache) as db:
        return db.execute(
            "select key, data from totals where key like 'file-change/%' order by key"
        ).fetchall()


def test_each_trees_coupling_is_kept_and_served_byte_for_byte(
    history: GitRepo, tmp_path: Path
) -> None:
    cache = tmp_path / "cache.sqlite3"
    plain = _diff(history, tmp_path, "--no-cache")
    elements = {e["element"]: e for e in json.loads(plain)["elements"]}
    assert elements["src/client.py"]["post"]["s_e"] == 2  # it imports zmq and shared
    assert elements["src/server.py"]["post"]["d_a"] == 1  # the client's link to the new server
    assert _diff(history, tmp_path, "--cache-path", str(cache)) == plain  # computed, kept
    kept = _totals(cache)
    assert len(kept) == 2  # one per tree
    assert _diff(history, tmp_path, "--cache-path", str(cache)) == plain  # served
    assert _totals(cache) == kept


def test_a_setting_that_changes_coupling_is_another_key(history: GitRepo, tmp_path: Path) -> None:
    cache = ["--cache-path", str(tmp_path / "cache.sqlite3")]
    before = _diff(history, tmp_path, *cache)
    config = history.root / "archmetrics.toml"  # not committed: the runner's file
    config.write_text('[tool.archmetrics.coupling]\nignore-imports = ["__future__", "shared"]\n')
    plain = _diff(history, tmp_path, "--no-cache", "--config-from", str(config))
    assert plain != before  # the import of shared no longer counts
    assert _diff(history, tmp_path, *cache, "--config-from", str(config)) == plain
    assert len(_totals(tmp_path / "cache.sqlite3")) == 4


def _tampered(data: bytes, how: str) -> bytes:
    """A kept tree state changed as a stranger with the cache file could change it."""
    if how == "not-compressed":
        return b"not a state"
    if how == "not-json":
        return zlib.compress(b"{not json")
    document = json.loads(zlib.decompress(data))
    if how == "other-numbers":
        document["values"] = [9] * len(document["values"])
    elif how == "a-bool":
        document["numbers"][0] = True
    elif how == "a-file-twice":
        document["files"][-1] = document["files"][0]
    elif how == "a-dependency-outside":
        document["deps"][2][0] = len(document["files"])
    elif how == "an-element-too-many":  # the first file in a second element
        names, members, sizes, _, kind_sizes = document["elements"]
        names.append("ghost")
        members.append(0)
        sizes.append(1)
        kind_sizes.append(0)
        document["values"] += [0, 0, 0, 0]
    return zlib.compress(json.dumps(document).encode())


@pytest.mark.parametrize(
    "how",
    ["other-numbers", "not-compressed", "not-json", "a-bool", "a-file-twice",
     "a-dependency-outside", "an-element-too-many"],
)  # fmt: skip
def test_a_kept_state_that_is_not_what_was_computed_is_recomputed(
    history: GitRepo, tmp_path: Path, how: str
) -> None:
    """The cache file is not trusted. Numbers that parse are believed (they carry no
    checksum; the key is the digest of their inputs), so the first case only shows that a
    rewritten entry changes what is served; the others must be recomputed."""
    cache = tmp_path / "cache.sqlite3"
    plain = _diff(history, tmp_path, "--no-cache")
    _diff(history, tmp_path, "--cache-path", str(cache))
    with sqlite3.connect(cache) as db:
        for key, data in db.execute("select key, data from totals where key like 'tree-state/%'"):
            db.execute("update totals set data = ? where key = ?", (_tampered(data, how), key))
    served = _diff(history, tmp_path, "--cache-path", str(cache))
    if how == "other-numbers":
        assert served != plain
    else:
        assert served == plain


def test_a_cache_made_before_the_totals_table_keeps_its_facts(
    history: GitRepo, tmp_path: Path
) -> None:
    cache = tmp_path / "cache.sqlite3"
    plain = _diff(history, tmp_path, "--cache-path", str(cache))
    with sqlite3.connect(cache) as db:
        db.execute("drop table totals")
        facts = db.execute("select count(*) from facts").fetchone()[0]
    assert facts > 0
    assert _diff(history, tmp_path, "--cache-path", str(cache)) == plain
    with sqlite3.connect(cache) as db:
        assert db.execute("select count(*) from facts").fetchone()[0] == facts
    assert len(_totals(cache)) == 2


def test_each_file_pairs_change_is_kept_and_served_byte_for_byte(
    history: GitRepo, tmp_path: Path
) -> None:
    cache = tmp_path / "cache.sqlite3"
    plain = _diff(history, tmp_path, "--no-cache")
    assert _diff(history, tmp_path, "--cache-path", str(cache)) == plain
    kept = _changes(cache)
    assert len(kept) == 2  # shared.py changed, server.py added; client.py is the same blob
    assert _diff(history, tmp_path, "--cache-path", str(cache)) == plain
    assert _changes(cache) == kept
    # what is served is the kept record: rewritten (still well formed), the report follows it
    with sqlite3.connect(cache) as db:
        for key, data in kept:
            record = json.loads(data)
            if record[0]:  # the added file's record: one statement more, counted
                record[0] += 1
                record[4].append(["added", None, ["assignment", 1, 1, "x = 1", None], False])
                db.execute(
                    "update totals set data = ? where key = ?", (json.dumps(record).encode(), key)
                )
    served = json.loads(_diff(history, tmp_path, "--cache-path", str(cache)))
    before = json.loads(plain)["locations"]["base"]
    assert served["locations"]["base"]["added"] == before["added"] + 2  # two records


@pytest.mark.parametrize(
    "stored",
    [
        b"not json",
        b"[]",
        b'{"a": 1}',
        b"[1, 0, 0, false, []]",  # a count its changes do not make
        b'[1, 0, 0, false, [["added", null, ["k", 2, 1, "t", null], false]]]',  # a bad span
        b'[1, 0, 0, false, [["added", ["k", 1, 1, "t", null], null, false]]]',  # sides swapped
        b'[1, 0, 0, false, [["grown", null, ["k", 1, 1, "t", null], false]]]',
        b'[1.0, 0, 0, false, [["added", null, ["k", 1, 1, "t", null], false]]]',
        b'[1, 0, 0, 0, [["added", null, ["k", 1, 1, "t", null], false]]]',
        b'[1, 0, 0, false, [["added", null, ["k", 1, 1, 5, null], false]]]',
    ],
)
def test_a_kept_change_that_is_not_what_was_computed_is_recomputed(
    history: GitRepo, tmp_path: Path, stored: bytes
) -> None:
    cache = tmp_path / "cache.sqlite3"
    plain = _diff(history, tmp_path, "--no-cache")
    _diff(history, tmp_path, "--cache-path", str(cache))
    with sqlite3.connect(cache) as db:
        db.execute("update totals set data = ? where key like 'file-change/%'", (stored,))
    assert _diff(history, tmp_path, "--cache-path", str(cache)) == plain


def test_diffs_along_a_history_served_from_kept_changes_equal_full_recomputation(
    repo: GitRepo, tmp_path: Path
) -> None:
    # a file rewritten over three commits, another renamed, one removed: every pair of
    # revisions, diffed warm after a cold pass, gives the JSON a diff without a cache gives
    body = "def f(a):\n    if a:\n        return 1\n    return 2\n"
    repo.commit("r1", tag="r1", files={"m.py": body, "old.py": SHARED, "gone.py": SERVER})
    repo.remove("gone.py")
    repo.commit("r2", tag="r2", files={"m.py": body.replace("1", "10")})
    repo.git("mv", "old.py", "new.py")
    repo.commit("r3", tag="r3", files={"m.py": body + "\ndef g():\n    return f(1)\n"})
    cache = ["--cache-path", str(tmp_path / "cache.sqlite3")]
    pairs = [("r1", "r2"), ("r2", "r3"), ("r1", "r3"), ("r3", "r1")]
    for warm in (False, True):
        for base, head in pairs:
            out = tmp_path / "out.json"
            command = ["diff", "-C", str(repo.root), "--base", base, "--head", head, "-q"]
            assert main([*command, "--format", "json", *cache, "-o", str(out)]) == 0
            cached = out.read_bytes()
            assert main([*command, "--format", "json", "--no-cache", "-o", str(out)]) == 0
            assert cached == out.read_bytes(), (base, head, warm)
    assert len(_changes(tmp_path / "cache.sqlite3")) >= 4


def test_a_change_of_non_ascii_text_is_kept_and_served(repo: GitRepo, tmp_path: Path) -> None:
    # records are ASCII (JSON escapes): a text may hold any character, a lone surrogate too
    # (which no UTF-8 can); here a Latin-1 byte of a C string literal, read as U+00E9
    repo.commit("one", tag="v1", files={"m.c": b'const char *s = "cafe";\n'})
    repo.commit("two", tag="v2", files={"m.c": b'const char *s = "caf\xe9";\nint n = 1;\n'})
    cache = tmp_path / "cache.sqlite3"
    plain = _diff(repo, tmp_path, "--no-cache")
    assert _diff(repo, tmp_path, "--cache-path", str(cache)) == plain
    ((_, data),) = _changes(cache)
    assert b"caf\\u00e9" in data
    assert _diff(repo, tmp_path, "--cache-path", str(cache)) == plain


GENERATED = "/* Generated by Cython 3.0.11 */\nint ok(void) { return 1; }\nint broken( { @ }\n"


def test_a_generated_file_is_read_no_further_than_its_first_lines(
    repo: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    # a diff excludes generated files: past the line that says so they are not read (a
    # Cython module of 8.7 MB cost 38 s and 680 MB), and what is not read is not cached
    repo.commit("one", tag="v1", files={"m.c": "int f(void) { return 1; }\n"})
    repo.commit("two", tag="v2", files={"m.c": "int f(void) { return 2; }\n", "gen.c": GENERATED})
    cache = ["--cache-path", str(tmp_path / "cache.sqlite3")]
    for _ in range(2):  # cold, then with the cache
        report = json.loads(_diff(repo, tmp_path, *cache))
        assert {"path": "gen.c", "reason": "generated"} in report["excluded"]
        assert not [w for w in report["warnings"] if "gen.c" in json.dumps(w)]
    # the cache remembers that the blob is generated: no worker is asked again
    command = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2", "-q", "-v"]
    assert main([*command, *cache, "-o", str(tmp_path / "again.json")]) == 0
    assert " 0 parsed;" in capsys.readouterr().err
    # asked to count generated files, the diff reads it whole: its function and the
    # region it could not parse
    config = repo.root / "archmetrics.toml"  # not committed: the runner's file
    config.write_text("[tool.archmetrics]\ninclude-generated = true\n")
    counted = json.loads(_diff(repo, tmp_path, *cache, "--config-from", str(config)))
    assert "gen.c" not in [x["path"] for x in counted["excluded"]]
    assert [w for w in counted["warnings"] if "gen.c" in json.dumps(w)]
    gen = next(e for e in counted["elements"] if e["element"] == "gen")
    assert gen["post"]["vg"] >= 1


def test_an_edited_worktree_finds_the_link_sites_of_the_edited_files_only(
    history: GitRepo, tmp_path: Path
) -> None:
    # each file's link sites are kept by content (coupling/sitememo.py): after an edit, the
    # worktree's coupling reads back every file whose reach did not change, and the JSON is
    # the JSON of a diff without a cache
    history.git("checkout", "-q", "v2")
    cache = tmp_path / "cache.sqlite3"
    out = tmp_path / "out.json"
    command = ["diff", "-C", str(history.root), "--base", "HEAD", "--head", "WORKTREE", "-q"]
    command += ["--format", "json", "-o", str(out)]
    assert main([*command, "--cache-path", str(cache)]) == 0

    def sites() -> set[str]:
        with sqlite3.connect(cache) as db:
            rows = db.execute("select key from totals where key like 'link-sites/%'")
            return {key for (key,) in rows}

    before = sites()
    assert len(before) == 2  # client and server, the same in both trees (shared calls
    # nothing a rule names: it has no sites to keep)
    server = history.root / "src/server.py"
    server.write_text(SERVER.replace("5555", "6666"))
    assert main([*command, "--cache-path", str(cache)]) == 0
    cached = out.read_bytes()
    assert main([*command, "--no-cache"]) == 0
    assert cached == out.read_bytes()
    post = {e["element"]: e["post"] for e in json.loads(cached)["elements"]}
    assert post["src/server.py"]["d_a"] == 0  # the client still connects to 5555
    assert len(sites() - before) == 1  # the edited server's; the others were read back


class _Steps:
    """A progress port that records the steps it is told of."""

    def __init__(self) -> None:
        self.steps: list[str] = []

    def phase(self, description: str) -> None:
        self.steps.append(description)

    def start(self, description: str, total: int) -> None:
        self.steps.append(f"{description} {total}")

    def advance(self, count: int = 1) -> None:
        pass

    def stop(self) -> None:
        self.steps.append("stop")


def test_every_long_step_of_a_diff_and_a_scan_is_named(history: GitRepo) -> None:
    # not only parsing: reading each side, coupling each tree and comparing are named, so
    # a long run never sits silent after the parsing bar ends
    steps = _Steps()
    request = DiffRequest(history.root, "v1", "v2", load_settings(history.root), jobs=1)
    run_diff(request, steps, None)
    assert steps.steps == [
        "reading v1 and v2",
        "parsing 2",
        "stop",
        "coupling v1",
        "reading v2",
        "parsing 3",
        "stop",
        "coupling v2",
        "comparing the changed files",
        "stop",
    ]
    steps = _Steps()
    run_scan(ScanRequest((history.root,), None, load_settings(history.root), jobs=1), steps)
    assert steps.steps == ["listing the files", "parsing 3", "stop", "coupling", "stop"]
