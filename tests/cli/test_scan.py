"""`archmetrics scan` end to end: real trees, real git repositories, the real parsers."""

from __future__ import annotations

import json
import sqlite3
import subprocess
import sys
import venv
from pathlib import Path

import pytest

from archmetrics.cli import main
from tests.gitrepo import GitRepo

PY_V1 = "import os\n\n\ndef f(a):\n    if a:\n        return 1\n    return 2\n"
PY_V2 = PY_V1 + "\n\ndef g(b):\n    return [x for x in b if x]\n"
C_SRC = '#include "m.h"\nint m(int a) {\n    return a > 0 && a < 9;\n}\n'


def _json(capsys: pytest.CaptureFixture[str], *argv: str) -> dict[str, object]:
    assert main(list(argv)) == 0
    out, err = capsys.readouterr()
    assert err == ""
    document: dict[str, object] = json.loads(out)
    return document


def _files(document: dict[str, object]) -> dict[str, dict[str, object]]:
    return {f["path"]: f for f in document["files"]}  # type: ignore[attr-defined, index]


def test_sample_is_measured(capsys: pytest.CaptureFixture[str]) -> None:
    document = _json(capsys, "scan", "--sample", "--format", "json")
    assert document["schema"] == "archmetrics.scan/1"
    files = _files(document)
    assert {"python/odometry.py", "c/motor.c", "c/motor.h"} <= set(files)
    totals = document["totals"]
    assert isinstance(totals, dict) and totals["loc"] > 0 and totals["vg"] > 0


def test_revision_and_worktree(repo: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    repo.commit("v1", tag="v1", files={"p.py": PY_V1, "m.c": C_SRC})
    repo.write({"p.py": PY_V2})
    old = _files(_json(capsys, "scan", str(repo.root), "--rev", "v1", "--format", "json"))
    new = _files(_json(capsys, "scan", str(repo.root), "--format", "json"))
    assert old["p.py"]["vg"] == 2 and new["p.py"]["vg"] == 2 + 3
    assert [f["name"] for f in new["p.py"]["functions"]] == ["f", "g"]  # type: ignore[union-attr]
    assert old["m.c"] == new["m.c"] and old["m.c"]["vg"] == 2


def test_paths_restrict_the_scan(repo: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    repo.commit("v1", files={"a/p.py": PY_V1, "b/q.py": PY_V1})
    files = _files(_json(capsys, "scan", str(repo.root / "a"), "--format", "json"))
    assert list(files) == ["a/p.py"]


@pytest.mark.parametrize(
    ("fmt", "needle"),
    [("table", "p.py"), ("markdown", "| `p.py` |"), ("csv", "path,language,loc,sloc,vg")],
)
def test_other_formats(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], fmt: str, needle: str
) -> None:
    (tmp_path / "p.py").write_text(PY_V1)
    assert main(["scan", str(tmp_path), "--format", fmt]) == 0
    assert needle in capsys.readouterr().out


def test_by_function_and_output_file(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "p.py").write_text(PY_V2)
    out = tmp_path / "report.csv"
    assert (
        main(["scan", str(tmp_path / "src"), "--by", "function", "--format", "csv", "-o", str(out)])
        == 0
    )
    assert capsys.readouterr().out == ""
    lines = out.read_text().splitlines()
    assert lines[0] == "path,language,function,line,loc,vg"
    assert lines[1:] == ["p.py,python,f,4,4,2", "p.py,python,g,10,2,3"]


@pytest.mark.parametrize(
    ("name", "explicit", "starts"),
    [
        ("out.json", [], "{"),
        ("OUT.JSON", [], "{"),
        ("out.md", [], "## archmetrics scan"),
        ("out.csv", [], "path,language,"),
        ("out.json", ["--format", "csv"], "path,language,"),  # --format wins
        ("out", [], "archmetrics scan: WORKTREE"),  # no ending: the default, a table
    ],
)
def test_the_output_suffix_picks_the_format_unless_format_is_given(
    tmp_path: Path, name: str, explicit: list[str], starts: str
) -> None:
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "p.py").write_text(PY_V2)
    out = tmp_path / name
    assert main(["scan", str(tmp_path / "src"), "-q", "-o", str(out), *explicit]) == 0
    text = out.read_text()
    assert text.lstrip().startswith(starts)
    if starts == "{":
        assert json.loads(text)["schema"] == "archmetrics.scan/1"


def test_bad_files_never_stop_the_run(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "ok.py").write_text(PY_V1)
    (tmp_path / "broken.py").write_text("def f(:\n    pass\n")
    (tmp_path / "latin.c").write_bytes(b"/* caf\xe9 */\nint x;\n")
    (tmp_path / "blob.h").write_bytes(b"\x00\x01\x02binary")
    files = _files(_json(capsys, "scan", str(tmp_path), "--format", "json"))
    assert files["ok.py"]["parsed"] is True and files["ok.py"]["warnings"] == []
    assert files["broken.py"]["parsed"] is False and files["broken.py"]["loc"] == 0
    [warning] = files["broken.py"]["warnings"]  # type: ignore[misc]
    assert warning["path"] == "broken.py" and warning["line"] == 1
    assert files["latin.c"]["loc"] == 1 and files["latin.c"]["warnings"][0]["line"] == 1  # type: ignore[index]
    assert files["blob.h"]["parsed"] is False


def test_second_run_is_served_from_the_cache(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "p.py").write_text(PY_V1)
    cache = tmp_path / "c.sqlite3"
    first = _json(
        capsys, "scan", str(tmp_path / "src"), "--format", "json", "--cache-path", str(cache)
    )
    second = _json(
        capsys, "scan", str(tmp_path / "src"), "--format", "json", "--cache-path", str(cache)
    )
    assert first == second
    assert main(["cache", "info", "--cache-path", str(cache)]) == 0
    assert "entries:     1" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["scan", "--rev", "no-such-rev"], "unknown revision 'no-such-rev'"),
        (["scan", "/no/such/path"], "no such file or directory"),
        (["scan", "--format", "yaml"], "invalid choice"),
        (["scan", "--jobs", "-2"], "--jobs must be 0 or more"),
    ],
)
def test_bad_usage_is_exit_2_with_one_line(repo: GitRepo, argv: list[str], message: str) -> None:
    repo.commit("v1", files={"p.py": PY_V1})
    done = subprocess.run(
        [sys.executable, "-m", "archmetrics", *argv],
        cwd=repo.root,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2
    assert message in done.stderr
    assert len(done.stderr.strip().splitlines()) == 1 and "Traceback" not in done.stderr


def test_an_ignored_folder_is_read_as_a_plain_folder(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    repo.commit("v1", files={".gitignore": "vendor/\n", "p.py": PY_V1})
    repo.write({"vendor/lib/q.py": PY_V2})
    files = _files(_json(capsys, "scan", str(repo.root / "vendor"), "--format", "json"))
    assert list(files) == ["lib/q.py"]


def test_nothing_to_measure_is_exit_0_with_a_note(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A changed-files job that runs on a docs-only change must pass: an empty tree measured
    (exit 0), and a note that says nothing was measured (tests/cli/test_edges.py has more)."""
    (tmp_path / "notes.txt").write_text("no source here\n")
    assert main(["scan", str(tmp_path), "--format", "json"]) == 0
    out, err = capsys.readouterr()
    assert "no source files to measure" in err and json.loads(out)["files"] == []


@pytest.mark.parametrize(("name", "starts"), [("g.mmd", "flowchart"), ("g.gv", "digraph")])
def test_the_graph_output_suffix_picks_its_format(tmp_path: Path, name: str, starts: str) -> None:
    (tmp_path / "one.c").write_text("int f(void) { return 0; }\n")
    out = tmp_path / name
    assert main(["graph", str(tmp_path), "--no-cache", "-o", str(out)]) == 0
    assert out.read_text().startswith(starts)


def _excluding(repo: GitRepo, **more: str) -> None:
    """A commit whose configuration excludes vendor/**, holding src/p.py, vendor/v.py (which
    would warn if it were read) and ``more`` (path -> text)."""
    files = {
        "pyproject.toml": '[tool.archmetrics]\nexclude = ["vendor/**"]\n',
        "src/p.py": PY_V2,
        "vendor/v.py": "def broken(:\n",
    }
    repo.commit("v1", files={**files, **more})


def test_the_configured_exclude_leaves_files_out_and_lists_them(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    _excluding(repo)
    document = _json(capsys, "scan", str(repo.root), "--format", "json", "-q")
    assert list(_files(document)) == ["src/p.py"]
    assert document["excluded"] == [{"path": "vendor/v.py", "reason": "exclude:vendor/**"}]
    assert document["totals"]["warnings"] == 0  # type: ignore[index]
    assert main(["scan", str(repo.root), "-q"]) == 0
    assert "excluded vendor/v.py: exclude:vendor/**" in capsys.readouterr().out
    # every report lists it: Markdown, and the CSV as a row of its own, its reason last
    assert main(["scan", str(repo.root), "-q", "--format", "markdown"]) == 0
    assert "- excluded `vendor/v.py`: `exclude:vendor/**`" in capsys.readouterr().out
    assert main(["scan", str(repo.root), "-q", "--format", "csv"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].endswith(",excluded") and lines[-1] == "vendor/v.py,,,,,,,exclude:vendor/**"
    repo.commit("v2", files={"vendor/v.py": "x = 2\n", "src/p.py": PY_V2 + "z = 1\n"})
    for fmt, listed in (("markdown", "- excluded `vendor/v.py`: `exclude:vendor/**`"),
                        ("table", "excluded vendor/v.py: exclude:vendor/**"),
                        ("csv", "excluded,vendor/v.py,")):  # fmt: skip
        argv = ["diff", "-C", str(repo.root), "--base", "HEAD~1", "--head", "HEAD", "-q"]
        assert main([*argv, "--format", fmt]) == 0
        out = capsys.readouterr().out
        assert listed in out, fmt
        # its old side does not parse, but it is excluded: listed for that, no warning shown
        assert "not_parsed" not in out and "syntax error" not in out, fmt


def test_exclude_on_the_command_line_adds_to_the_configured_globs(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    _excluding(repo, **{"src/gen/t.py": "x = 1\n"})
    base = ["scan", str(repo.root), "--format", "json", "-q", "--no-cache"]
    document = _json(capsys, *base, "--exclude", "src/gen/**", "--exclude", "*.toml")
    assert list(_files(document)) == ["src/p.py"]
    assert document["excluded"] == [
        {"path": "src/gen/t.py", "reason": "exclude:src/gen/**"},
        {"path": "vendor/v.py", "reason": "exclude:vendor/**"},
    ]
    assert main([*base, "--exclude", "!vendor/**"]) == 2
    assert "--exclude: unusable glob '!vendor/**'" in capsys.readouterr().err
    # the same flag on a diff: the excluded file counts nowhere and is listed
    repo.commit("v2", files={"src/gen/t.py": "x = 1\ny = 2\n", "src/p.py": PY_V2 + "z = 1\n"})
    assert main(["diff", "-C", str(repo.root), "--base", "HEAD~1", "--head", "HEAD", "-q",
                 "--format", "json", "--exclude", "src/gen/**"]) == 0  # fmt: skip
    diffed = json.loads(capsys.readouterr().out)
    assert [e["element"] for e in diffed["elements"] if e["status"] != "unchanged"] == ["src/p.py"]
    assert {"path": "src/gen/t.py", "reason": "exclude:src/gen/**"} in diffed["excluded"]


def test_a_plain_folder_scan_lists_the_folders_it_skipped(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "venv").mkdir()
    (tmp_path / "venv" / "__init__.py").write_text(PY_V2)  # a package named venv
    # a real virtual environment, as python -m venv makes it (its site-packages get a module)
    venv.EnvBuilder(with_pip=False, symlinks=True).create(tmp_path / "env")
    [site] = (tmp_path / "env").glob("lib/python*/site-packages")
    (site / "installed.py").write_text(PY_V2)
    document = _json(capsys, "scan", str(tmp_path), "--format", "json", "-q", "--no-cache")
    assert list(_files(document)) == ["venv/__init__.py"]
    assert document["excluded"] == [{"path": "env/", "reason": "virtual environment (pyvenv.cfg)"}]
    assert main(["scan", str(tmp_path), "-q", "--no-cache"]) == 0
    assert "excluded env/: virtual environment (pyvenv.cfg)" in capsys.readouterr().out


def test_verbose_adds_cache_and_time_detail_and_quiet_stays_quiet(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    (tmp_path / "src").mkdir()
    (tmp_path / "src" / "p.py").write_text(PY_V2)
    cache = ["--cache-path", str(tmp_path / "cache.sqlite3")]
    scan = ["scan", str(tmp_path / "src"), "-q", "--format", "json", *cache]
    assert main([*scan, "-v"]) == 0
    first = capsys.readouterr().err
    assert "0 files' facts served, 1 parsed; measured in" in first
    assert main(["-v", *scan]) == 0
    assert "1 files' facts served, 0 parsed" in capsys.readouterr().err
    assert main(scan) == 0
    assert capsys.readouterr().err == ""


def test_scan_thresholds_fail_the_run_and_name_every_failing_unit(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    repo.commit("one", files={"m.py": PY_V2, "src/m.c": C_SRC, "src/m.h": "int m(int a);\n"})
    scan = ["scan", str(repo.root), "-q", "--no-cache"]
    # the table shows each failure once, on stdout; exit 1
    assert main([*scan, "--fail-on", "vg(function) >= 2"]) == 1
    out, err = capsys.readouterr()
    assert err == ""
    assert out.count("gate failed") == 3
    assert "gate failed: vg(function) >= 2: m.py:4 f (vg = 2)" in out
    assert "gate failed: vg(function) >= 2: m.py:10 g (vg = 3)" in out  # the comprehension's if
    assert "gate failed: vg(function) >= 2: src/m.c:2 m (vg = 2)" in out
    # JSON: every threshold and its failing units; the failures on stderr, once each
    assert main([*scan, "--format", "json", "--fail-on", "vg(total) > 100",
                 "--fail-on", "loc(file) > 1 and functions(file) >= 2"]) == 1  # fmt: skip
    out, err = capsys.readouterr()
    gates = json.loads(out)["gates"]
    assert gates[0] == {"gate": "vg(total) > 100", "failed": False, "failures": [],
                        "suppressed": [], "baselined": []}  # fmt: skip
    assert gates[1]["failures"] == [
        {"name": "m.py", "path": "m.py", "line": None, "values": {"loc": 7, "functions": 2}}
    ]
    assert err.splitlines() == [
        "archmetrics: gate failed: loc(file) > 1 and functions(file) >= 2: m.py"
        " (loc = 7, functions = 2)"
    ]
    # Markdown names the thresholds and the verdict; a threshold that holds is exit 0
    assert main([*scan, "--format", "markdown", "--fail-on", "vg(element) > 50"]) == 0
    assert "**Gates** (`vg(element) > 50`): all hold" in capsys.readouterr().out


def test_a_threshold_failed_by_many_units_lists_the_first_fifty(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    body = "".join(f"def f{i}(a):\n    return a\n\n\n" for i in range(60))
    repo.commit("one", files={"many.py": body})
    scan = ["scan", str(repo.root), "-q", "--no-cache", "--fail-on", "vg(function) > 0"]
    assert main(scan) == 1
    out = capsys.readouterr().out
    assert out.count("gate failed:") == 50
    assert "... and 10 more failing units (--format json lists them all)" in out
    assert main([*scan, "--format", "json"]) == 1
    out, err = capsys.readouterr()
    assert len(json.loads(out)["gates"][0]["failures"]) == 60
    assert err.count("gate failed:") == 50 and "... and 10 more failures" in err


def test_a_bad_threshold_is_exit_2_before_any_work(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    repo.commit("one", files={"m.py": PY_V1})
    cache = tmp_path / "cache.sqlite3"
    argv = ["scan", str(repo.root), "-q", "--cache-path", str(cache), "--fail-on", "vg > 3"]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.splitlines()) == 1 and "is not FIELD(UNIT) OP NUMBER" in err
    with sqlite3.connect(cache) as db:  # nothing was parsed
        assert db.execute("select count(*) from facts").fetchone()[0] == 0
