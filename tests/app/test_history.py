"""`archmetrics history` on real git histories: every commit's figures are the ones `diff
--base C^ --head C` gives, byte for byte; a second or interrupted run measures only what it
lacks; the range options pick the commits git log picks."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from archmetrics.app.collect import open_cache
from archmetrics.app.diff_options import DiffRequest
from archmetrics.app.history import HistoryRequest, run_history
from archmetrics.cli import main
from archmetrics.config import load_settings
from archmetrics.sources.githistory import Range
from archmetrics.sources.snapshot import SourceError
from tests.gitrepo import GitRepo

HEADER = "#ifndef BUS_H\n#define BUS_H\nint bus_send(int port, const char *text);\n#endif\n"
BUS = (
    '#include "bus.h"\n#include <string.h>\n\nint bus_send(int port, const char *text) {\n'
    "    if (port < 0) {\n        return -1;\n    }\n    return (int)strlen(text) + port;\n}\n"
)
BUS_2 = BUS.replace(
    "    return (int)strlen", "    if (!text) {\n        return 0;\n    }\n    return (int)strlen"
)
CLIENT = (
    '#include "bus.h"\n\nint main(int argc, char **argv) {\n    if (argc > 1) {\n'
    "        return bus_send(5555, argv[1]);\n    }\n    return 0;\n}\n"
)
TOOL = (
    "import os\n\n\ndef run(args):\n    for a in args:\n        if a:\n            print(a)\n"
    "    return os.sep\n"
)
TOOL_2 = TOOL.replace(
    "            print(a)\n", "            print(a)\n        elif a is None:\n            break\n"
)


def _history(repo: GitRepo) -> list[str]:
    """A history with every kind of change a diff pairs: files added, modified, renamed and
    removed, a header and its component, a commit that changes nothing measured, a file
    with spaces and non-ASCII characters in its name, a merged branch."""
    commits = [
        repo.commit("root", files={"src/bus.h": HEADER, "src/bus.c": BUS, "tools/tool.py": TOOL})
    ]
    commits.append(repo.commit("client", files={"app/client.c": CLIENT}))
    commits.append(repo.commit("guard the text", files={"src/bus.c": BUS_2}))
    commits.append(repo.commit("docs only", files={"README.md": "# bus\n"}))
    repo.git("mv", "tools/tool.py", "tools/runner.py")
    commits.append(repo.commit("rename the tool"))
    commits.append(repo.commit("unicode name", files={"tools/naïve tool.py": TOOL_2}))
    repo.git("checkout", "-q", "-b", "topic")
    repo.commit("topic: more in the tool", files={"tools/runner.py": TOOL_2})
    repo.remove("app/client.c")
    repo.commit("topic: client gone")
    repo.git("checkout", "-q", "main")
    repo.commit("main moves on", files={"src/bus.h": HEADER + "int bus_close(void);\n"})
    repo.git("merge", "-q", "--no-ff", "-m", "merge topic", "topic")
    return commits


@pytest.fixture
def history_repo(repo: GitRepo) -> GitRepo:
    _history(repo)
    return repo


@pytest.fixture(autouse=True)
def _own_cache(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """Each test its own facts cache: what a run parses is part of what is checked."""
    monkeypatch.setenv("ARCHMETRICS_CACHE", str(tmp_path / "facts.sqlite3"))


def _json(capsys: pytest.CaptureFixture[str], *argv: str, status: int = 0) -> Any:
    code = main([*argv, "--format", "json", "-q"])
    out, err = capsys.readouterr()
    assert code == status, err
    return json.loads(out)


def _changed(document: dict[str, Any]) -> list[Any]:
    return [e for e in document["elements"] if e["status"] != "unchanged" or e["pre"] != e["post"]]


def test_every_commit_gives_what_its_diff_gives(
    history_repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    root = str(history_repo.root)
    history = _json(capsys, "history", "-C", root)
    listed = history_repo.git("log", "--first-parent", "--reverse", "--format=%H").split()
    assert [c["commit"] for c in history["commits"]] == listed
    assert history["measured"] == len(listed)
    for commit in history["commits"]:
        base = commit["parent"] or "EMPTY"
        diff = _json(capsys, "diff", "-C", root, "--base", base, "--head", commit["commit"])
        assert json.dumps(commit["locations"]) == json.dumps(diff["locations"]), commit["subject"]
        assert json.dumps(commit["elements"]) == json.dumps(_changed(diff)), commit["subject"]
    merge = history["commits"][-1]
    assert merge["merge"] and merge["subject"] == "merge topic"
    # the merge brings the topic's two commits in at once: the tool's decision and the
    # client's removal, against main's first parent
    assert merge["locations"]["total"]["removed"] > 0
    assert merge["locations"]["total"]["delta_vg"] == 1 - 2  # +1 elif; the client: 1 + one if


def test_the_same_figures_without_a_cache(
    history_repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    root = str(history_repo.root)
    cached = _json(capsys, "history", "-C", root)
    uncached = _json(capsys, "history", "-C", root, "--no-cache")
    assert uncached["commits"] == cached["commits"]


def test_a_second_run_measures_nothing_again(
    history_repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    root = str(history_repo.root)
    first = _json(capsys, "history", "-C", root)
    second = _json(capsys, "history", "-C", root)
    assert (second["measured"], second["parsed"]) == (0, 0)
    assert first["parsed"] > 0
    assert {**first, "measured": 0, "parsed": 0} == second


class _StopAfter:
    """A progress port that interrupts the run after ``count`` commits, as Ctrl-C would."""

    def __init__(self, count: int) -> None:
        self.count = count

    def phase(self, description: str) -> None:
        pass

    def start(self, description: str, total: int) -> None:
        self.measuring = description == "measuring commits"

    def advance(self, count: int = 1) -> None:
        if self.measuring and count == 1:
            self.count -= 1
            if self.count == 0:
                raise KeyboardInterrupt

    def stop(self) -> None:
        pass


def test_an_interrupted_run_resumes_where_it_stopped(
    history_repo: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    root = history_repo.root
    settings = load_settings(root)
    request = HistoryRequest(DiffRequest(root, "", "", settings, jobs=1), Range())
    path = tmp_path / "cache.sqlite3"
    with open_cache(path, settings) as cache, pytest.raises(KeyboardInterrupt):
        run_history(request, _StopAfter(4), cache)
    with open_cache(path, settings) as cache:
        resumed = run_history(request, None, cache)
    total = len(resumed.entries)
    assert resumed.measured == total - 4
    whole = _json(capsys, "history", "-C", str(root), "--no-cache")
    assert [e.commit for e in resumed.entries] == [c["commit"] for c in whole["commits"]]
    for entry, commit in zip(resumed.entries, whole["commits"], strict=True):
        mine = {k: s.to_dict() for k, s in entry.step.summaries.items()}
        assert json.dumps(mine) == json.dumps(commit["locations"])


def _ids(document: dict[str, Any]) -> list[str]:
    return [c["commit"] for c in document["commits"]]


def test_the_range_options_pick_what_git_log_picks(
    history_repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    root = str(history_repo.root)

    def log(*options: str) -> list[str]:
        return history_repo.git("log", "--reverse", "--format=%H", *options).split()

    assert _ids(_json(capsys, "history", "-C", root, "--merges")) == log(
        "--first-parent", "--merges"
    )
    assert _ids(_json(capsys, "history", "-C", root, "-n", "3")) == log("--first-parent", "-n3")
    every = _json(capsys, "history", "-C", root, "--no-first-parent")
    assert _ids(every) == log()
    topic = _json(capsys, "history", "-C", root, "main~1..topic")
    assert [c["subject"] for c in topic["commits"]] == [
        "topic: more in the tool",
        "topic: client gone",
    ]
    # each commit against its own first parent, whatever was measured before it
    by_id = {c["commit"]: c for c in every["commits"]}
    for commit in topic["commits"]:
        assert commit["locations"] == by_id[commit["commit"]]["locations"]


def test_gates_fail_on_the_commits_that_break_them(
    history_repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    root = str(history_repo.root)
    document = _json(capsys, "history", "-C", root, "--fail-on", "vg_post(total) > 6", status=1)
    failed = [c["subject"] for c in document["commits"] if c["gates"][0]["failed"]]
    expected = [
        c["subject"] for c in document["commits"] if c["locations"]["total"]["vg_post"] > 6
    ]
    assert failed == expected and failed


def test_every_format_names_every_commit(
    history_repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    root = str(history_repo.root)
    ids = [c[:12] for c in history_repo.git("log", "--first-parent", "--format=%H").split()]
    for fmt in ("table", "markdown", "csv"):
        assert main(["history", "-C", root, "--format", fmt, "-q"]) == 0
        out = capsys.readouterr().out
        assert all(i in out for i in ids), fmt
    assert main(["history", "-C", root, "--format", "csv", "-q"]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert len(lines) == 1 + 4 * len(ids)  # a header, then a row per commit and location


def test_an_element_trend_and_hotspots(
    history_repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    root = str(history_repo.root)
    document = _json(capsys, "history", "-C", root, "--element", "src/bus")
    spots = {h["element"]: h for h in document["hotspots"]}
    # src/bus changed in the root commit, when guarded, and when main moved on (the header)
    touched = [
        c for c in document["commits"]
        if any(e["element"] == "src/bus" and e["status"] != "unchanged" for e in c["elements"])
    ]  # fmt: skip
    assert spots["src/bus"]["commits"] == len(touched) == 3
    assert main(["history", "-C", root, "--element", "src/bus", "-q"]) == 0
    assert "src/bus: its own trend" in capsys.readouterr().out


def test_a_bad_range_is_one_line(history_repo: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["history", "-C", str(history_repo.root), "no-such-rev", "-q"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "no-such-rev" in err[0]
    # a range that git would read as an option is refused before git sees it
    root = history_repo.root
    request = HistoryRequest(
        DiffRequest(root, "", "", load_settings(root)), Range("--output=/tmp/x")
    )
    with pytest.raises(SourceError, match="not an option"):
        run_history(request)
