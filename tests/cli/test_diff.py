"""`archmetrics diff` end to end on real repositories, against hand-computed values.

The repository in ``integration`` is the worked example of docs/metrics.md: a client (base)
starts calling a new store module (new).
"""

from __future__ import annotations

import json
import sqlite3
import zlib
from pathlib import Path
from typing import Any

import pytest

from archmetrics.cli import main
from tests.gitrepo import GitRepo

CLIENT_V1 = "import os\n\n\ndef main(argv):\n    if argv:\n        return os.sep\n    return 0\n"
CLIENT_V2 = (
    "import os\nfrom wdb import store\n\n\ndef main(argv):\n    if argv:\n"
    "        return store.query(argv[0])\n    return 0\n"
)
STORE = 'def query(name):\n    if name and name != "*":\n        return [name]\n    return []\n'
SUMMARY_KEYS = {
    "delta_s_a",
    "delta_s_e",
    "delta_d_a",
    "delta_d_e",
    "loc_pre",
    "loc_post",
    "loc_scale",
    "added",
    "removed",
    "modified",
    "changes",
    "scaled_changes",
    "vg_pre",
    "vg_post",
    "vg_scale",
    "delta_vg",
    "scaled_delta_vg",
    "cost",
    "notes",
    "unparsed",
}


@pytest.fixture
def integration(repo: GitRepo) -> GitRepo:
    repo.commit("baseline", tag="v1", files={"app/client.py": CLIENT_V1})
    repo.commit("first", tag="v2", files={"app/client.py": CLIENT_V2, "wdb/store.py": STORE})
    return repo


def diff(repo: GitRepo, capsys: pytest.CaptureFixture[str], *argv: str, status: int = 0) -> Any:
    code = main(["diff", "-C", str(repo.root), "--format", "json", *argv])
    out, err = capsys.readouterr()
    assert code == status, err
    return json.loads(out)


def close(value: float | None, expected: float) -> bool:
    return value is not None and abs(value - expected) < 1e-9


def test_contract_shape(integration: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    doc = diff(integration, capsys, "--base", "v1", "--head", "v2", "--new", "wdb/**")
    assert doc["schema"] == "archmetrics.diff/1"
    assert (doc["base"], doc["head"]) == ("v1", "v2")
    assert set(doc["locations"]) == {"base", "new", "framework", "total"}
    for summary in doc["locations"].values():
        assert set(summary) == SUMMARY_KEYS
    element = doc["elements"][0]
    assert {
        "element",
        "location",
        "files",
        "status",
        "pre",
        "post",
        "added",
        "removed",
        "modified",
    } <= set(element)
    assert set(element["pre"]) == {"loc", "sloc", "vg", "s_a", "s_e", "d_a", "d_e"}


def test_hand_computed_values(integration: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    doc = diff(integration, capsys, "--base", "v1", "--head", "v2", "--new", "wdb/**")
    base, new, framework, total = (
        doc["locations"][k] for k in ("base", "new", "framework", "total")
    )
    # base: λ 5 -> 6; one import added, one return edited in place; v_g 2 -> 2.
    assert (
        base["loc_pre"],
        base["loc_post"],
        base["added"],
        base["removed"],
        base["modified"],
    ) == (5, 6, 1, 0, 1)
    assert close(base["loc_scale"], 1.2) and close(base["scaled_changes"], 2.4)
    assert (base["vg_pre"], base["vg_post"], base["delta_vg"]) == (2, 2, 0)
    assert close(base["vg_scale"], 1.0) and base["scaled_delta_vg"] == 0 and base["cost"] == 0
    assert any(n.startswith("cost_zero_no_complexity_change") for n in base["notes"])
    assert (base["delta_s_e"], base["delta_s_a"]) == (1, 0)  # now imports wdb.store too
    # new: nothing before, so both scales are undefined and flagged; E = 4 / 3.
    assert (new["loc_pre"], new["loc_post"], new["added"], new["changes"]) == (0, 4, 4, 4)
    assert new["loc_scale"] is None and new["vg_scale"] is None
    assert (new["vg_pre"], new["vg_post"], new["delta_vg"]) == (0, 3, 3)
    assert close(new["scaled_changes"], 4) and close(new["scaled_delta_vg"], 3)
    assert close(new["cost"], 4 / 3)
    assert new["delta_s_a"] == 1 and new["delta_s_e"] == 0
    assert {n.split(":")[0] for n in new["notes"]} >= {
        "loc_scale_undefined_pre_zero",
        "vg_scale_undefined_pre_zero",
    }
    # framework: nothing at all.
    assert framework["changes"] == 0 and framework["cost"] == 0
    # total: λ̂ = 10/5, Γ' = 2 * 6; v̂g = 5/2, ΔVg' = 2.5 * 3; E = 12 / 7.5.
    assert (total["loc_pre"], total["loc_post"], total["changes"]) == (5, 10, 6)
    assert close(total["loc_scale"], 2.0) and close(total["scaled_changes"], 12.0)
    assert close(total["vg_scale"], 2.5) and close(total["scaled_delta_vg"], 7.5)
    assert close(total["cost"], 1.6)
    assert (total["delta_s_a"], total["delta_s_e"], total["delta_d_a"], total["delta_d_e"]) == (
        1,
        1,
        0,
        0,
    )
    statuses = {e["element"]: (e["location"], e["status"]) for e in doc["elements"]}
    assert sorted(statuses.values()) == [("base", "modified"), ("new", "added")]


def test_empty_base_is_everything_added(
    integration: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    doc = diff(integration, capsys, "--base", "EMPTY", "--head", "v1")
    total = doc["locations"]["total"]
    assert (total["loc_pre"], total["loc_post"], total["added"], total["changes"]) == (0, 5, 5, 5)
    assert total["loc_scale"] is None and close(total["cost"], 5 / 2)


def test_reformatting_and_comments_cost_nothing(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    repo.commit("v1", tag="v1", files={"m.py": CLIENT_V1})
    repo.commit(
        "v2",
        tag="v2",
        files={
            "m.py": "import os  # os\n\ndef main( argv ):\n"
            "    # why\n    if argv:\n        return os.\\\n"
            "                sep\n    return 0\n"
        },
    )
    total = diff(repo, capsys, "--base", "v1", "--head", "v2")["locations"]["total"]
    assert (total["added"], total["removed"], total["modified"]) == (0, 0, 0)


def test_rename_is_followed(repo: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    body = CLIENT_V1 + "".join(f"\n\ndef f{i}(x):\n    return x + {i}\n" for i in range(8))
    repo.commit("v1", tag="v1", files={"old/m.py": body})
    (repo.root / "new").mkdir()
    repo.git("mv", "old/m.py", "new/m.py")
    repo.commit("v2", tag="v2", files={"new/m.py": body + "\n\ndef g():\n    return 1\n"})
    doc = diff(repo, capsys, "--base", "v1", "--head", "v2")
    total = doc["locations"]["total"]
    assert (total["added"], total["removed"], total["modified"]) == (2, 0, 0)


def test_deleted_file(repo: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    repo.commit("v1", tag="v1", files={"a.py": CLIENT_V1, "b.py": STORE})
    repo.remove("b.py")
    repo.commit("v2", tag="v2")
    doc = diff(repo, capsys, "--base", "v1", "--head", "v2")
    total = doc["locations"]["total"]
    assert (total["added"], total["removed"], total["loc_pre"], total["loc_post"]) == (0, 4, 9, 5)
    assert (total["vg_pre"], total["vg_post"], total["delta_vg"]) == (5, 2, -3)
    removed = [e for e in doc["elements"] if e["status"] == "removed"]
    assert len(removed) == 1 and removed[0]["post"] is None


def test_binary_and_syntax_error_files_are_listed_not_measured(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    repo.commit("v1", tag="v1", files={"a.py": CLIENT_V1})
    repo.commit("v2", tag="v2", files={"blob.py": b"\x00\x01binary", "bad.py": "def f(:\n"})
    doc = diff(repo, capsys, "--base", "v1", "--head", "v2")
    assert {x["path"]: x["reason"] for x in doc["excluded"]} == {
        "bad.py": "not_parsed",
        "blob.py": "not_parsed",
    }
    assert {w["path"] for w in doc["warnings"]} == {"bad.py", "blob.py"}
    assert doc["locations"]["total"]["changes"] == 0


def test_index_and_worktree(repo: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    repo.commit("v1", tag="v1", files={"a.py": CLIENT_V1})
    repo.write({"b.py": STORE})
    repo.git("add", "b.py")
    repo.write({"c.py": "x = 1\n"})
    before = repo.status()
    staged = diff(repo, capsys, "--base", "HEAD", "--head", "INDEX")["locations"]["total"]
    assert staged["added"] == 4
    working = diff(repo, capsys, "--base", "HEAD", "--head", "WORKTREE")["locations"]["total"]
    assert working["added"] == 5
    # WORKTREE and INDEX work as a base too: the same change, read backwards
    back = diff(repo, capsys, "--base", "WORKTREE", "--head", "HEAD")["locations"]["total"]
    assert (back["added"], back["removed"]) == (0, 5)
    unstaged = diff(repo, capsys, "--base", "INDEX", "--head", "WORKTREE")["locations"]["total"]
    assert unstaged["added"] == 1  # c.py only
    assert repo.status() == before  # it only reads


def test_gates(integration: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    args = ["--base", "v1", "--head", "v2", "--new", "wdb/**"]
    code = main(
        [
            "diff",
            "-C",
            str(integration.root),
            *args,
            "--format",
            "json",
            "--fail-on",
            "cost(new) > 1",
            "--fail-on",
            "delta_s_e(base) > 5",
        ]
    )
    out, err = capsys.readouterr()
    assert code == 1
    assert "gate failed: cost(new) > 1" in err and "delta_s_e" not in err
    gates = [{"gate": g["gate"], "failed": g["failed"]} for g in json.loads(out)["gates"]]
    assert gates == [  # (each entry's `values`: tests/cli/test_merge_base.py)
        {"gate": "cost(new) > 1", "failed": True},
        {"gate": "delta_s_e(base) > 5", "failed": False},
        {"gate": "unmeasured(head) > 0", "failed": False},  # every gated diff's own
    ]
    assert main(["diff", "-C", str(integration.root), *args, "--fail-on", "cost(new) > 2"]) == 0


def test_gates_combine_conditions_with_and_and_or(
    integration: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    # `and` binds tighter than `or`; a failure names the values of the group that failed
    command = ["diff", "-C", str(integration.root), "--base", "v1", "--head", "v2"]
    command += ["--new", "wdb/**", "--format", "json"]
    document = diff(integration, capsys, *command[3:])
    cost = document["locations"]["new"]["cost"]
    changes = document["locations"]["total"]["changes"]
    assert cost > 1 and changes > 3
    both = "cost(new) > 1 and changes > 3"
    assert main([*command, "--fail-on", both]) == 1
    err = capsys.readouterr().err
    assert err.strip() == (
        f"archmetrics: gate failed: {both} (cost(new) = {cost:g}, changes(total) = {changes:g})"
    )
    assert main([*command, "--fail-on", "cost(new) > 1 and changes > 1000"]) == 0
    capsys.readouterr()
    either = "changes > 1000 or delta_s_e(base) > 50 or cost(new) > 1 and added > 0"
    assert main([*command, "--fail-on", either]) == 1
    assert "gate failed" in capsys.readouterr().err
    assert main([*command, "--fail-on", "cost(new) > 1 and"]) == 2
    assert "expected FIELD(LOCATION) OP NUMBER" in capsys.readouterr().err


def test_gates_from_config(integration: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    integration.write(
        {"archmetrics.toml": 'gates = ["changes > 3"]\n[locations]\nnew = ["wdb/**"]\n'}
    )
    # an uncommitted configuration: neither v1's nor v2's, so named as the runner's file
    config = ["--config-from", str(integration.root / "archmetrics.toml")]
    assert main(["diff", "-C", str(integration.root), "--base", "v1", "--head", "v2"]) == 0
    assert main(["diff", "-C", str(integration.root), "--base", "v1", "--head", "v2", *config]) == 1
    out, err = capsys.readouterr()
    # the table on stdout names the failed gate; stderr does not repeat it
    assert out.count("gate failed: changes > 3") == 1 and "gate failed" not in err


@pytest.mark.parametrize(
    ("extra", "on_stdout"),
    [([], True), (["--format", "markdown"], True), (["--format", "json"], False)],
)
def test_a_failed_gate_is_printed_once(
    integration: GitRepo,
    capsys: pytest.CaptureFixture[str],
    tmp_path: Path,
    extra: list[str],
    on_stdout: bool,
) -> None:
    command = ["diff", "-C", str(integration.root), "--base", "v1", "--head", "v2"]
    gate = ["--new", "wdb/**", "--fail-on", "changes > 3", *extra]
    assert main([*command, *gate]) == 1
    out, err = capsys.readouterr()
    assert (out + err).count("gate failed: changes > 3") == 1
    assert ("gate failed" in out) is on_stdout
    assert main([*command, *gate, "-o", str(tmp_path / "report.txt")]) == 1
    out, err = capsys.readouterr()
    assert out == "" and err.count("gate failed: changes > 3") == 1  # the report is a file


@pytest.mark.parametrize(
    ("argv", "message"),
    [
        (["--base", "nope"], "unknown revision 'nope'"),
        (["--fail-on", "cost(moon) > 1"], "unknown location 'moon'"),
        (["--fail-on", "bogus"], "expected FIELD(LOCATION) OP NUMBER"),
    ],
)
def test_cannot_measure_is_exit_2(
    integration: GitRepo, capsys: pytest.CaptureFixture[str], argv: list[str], message: str
) -> None:
    assert main(["diff", "-C", str(integration.root), *argv]) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    ("fmt", "needle"),
    [("table", "Γ'"), ("markdown", "| E | 6.37 |"), ("csv", "row,name,location,status,delta_s_a")],
)
def test_formats(
    integration: GitRepo, capsys: pytest.CaptureFixture[str], fmt: str, needle: str
) -> None:
    assert (
        main(["diff", "-C", str(integration.root), "--base", "v1", "--head", "v2", "--format", fmt])
        == 0
    )
    assert needle in capsys.readouterr().out


def test_damaged_statements_in_the_cache_are_a_one_line_error(
    integration: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    cache = tmp_path / "facts.sqlite3"
    first = diff(integration, capsys, "--base", "v1", "--head", "v2", "--cache-path", str(cache))
    db = sqlite3.connect(cache)
    rows = db.execute(
        "select f.rowid, b.rowid, f.data, b.data from facts f join bodies b"
        " on b.blob=f.blob and b.language=f.language and b.parser=f.parser"
    ).fetchall()
    for head_row, body_row, head, body in rows:
        calls, statements, bindings = body.split(b"\n")
        bad = statements.replace(b'"import"', b"1")  # well-formed JSON, not statements
        document = json.loads(head)
        document[2][1] = zlib.crc32(bad)  # a checksum that matches: found only when read
        db.execute("update facts set data=? where rowid=?", (_json(document), head_row))
        damaged = b"\n".join((calls, bad, bindings))
        db.execute("update bodies set data=? where rowid=?", (damaged, body_row))
    db.execute("delete from totals")  # the kept file changes: the statements must be read
    db.commit()
    db.close()
    code = main(["diff", "-C", str(integration.root), "--base", "v1", "--head", "v2",
                 "--cache-path", str(cache)])  # fmt: skip
    err = capsys.readouterr().err
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert "bad statements in the cached facts of app/client.py" in err
    assert "archmetrics cache clear" in err
    main(["cache", "clear", "--cache-path", str(cache)])
    capsys.readouterr()
    again = diff(integration, capsys, "--base", "v1", "--head", "v2", "--cache-path", str(cache))
    assert again == first


def _json(document: Any) -> bytes:
    return json.dumps(document, separators=(",", ":")).encode()


def test_the_hook_takes_the_range_pre_commit_was_given(
    integration: GitRepo, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    hook = ["diff", "-C", str(integration.root), "--base", "HEAD", "--head", "INDEX"]
    hook += ["--from-pre-commit", "--format", "json"]
    assert main(hook) == 0  # a commit: pre-commit sets no range, the staged change is measured
    staged = json.loads(capsys.readouterr().out)
    assert (staged["base"], staged["head"]) == ("HEAD", "INDEX")
    assert staged["locations"]["total"]["changes"] == 0
    monkeypatch.setenv("PRE_COMMIT_FROM_REF", "v1")
    monkeypatch.setenv("PRE_COMMIT_TO_REF", "v2")
    assert main(hook) == 0
    ranged = json.loads(capsys.readouterr().out)
    assert (ranged["base"], ranged["head"]) == ("v1...v2", "v2")  # as pre-commit selects: A...B
    assert ranged["locations"]["total"]["changes"] > 0
    assert main([*hook[:-3], "--format", "json"]) == 0  # without the flag: as written
    assert json.loads(capsys.readouterr().out)["base"] == "HEAD"
    monkeypatch.delenv("PRE_COMMIT_TO_REF")
    assert main(hook) == 2
    assert "only one of PRE_COMMIT_FROM_REF" in capsys.readouterr().err


def test_a_chart_is_drawn_in_the_format_its_name_ends_with(
    integration: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    command = ["diff", "-C", str(integration.root), "--base", "v1", "--head", "v2", "-q"]
    for name, starts in (("c.png", b"\x89PNG"), ("c.SVG", b"<?xml")):
        assert main([*command, "--no-cache", "--chart", str(tmp_path / name)]) == 0
        assert (tmp_path / name).read_bytes().startswith(starts)


@pytest.mark.parametrize(
    ("chart", "message"),
    [("c.jpg", "--chart needs a .png or .svg file"), ("no/such/c.png", "--chart: no folder")],
)
def test_a_chart_that_cannot_be_written_is_refused_before_any_work(
    integration: GitRepo,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    chart: str,
    message: str,
) -> None:
    cache = tmp_path / "cache.sqlite3"
    command = ["diff", "-C", str(integration.root), "--base", "v1", "--head", "v2", "-q"]
    assert main([*command, "--cache-path", str(cache), "--chart", str(tmp_path / chart)]) == 2
    assert message in capsys.readouterr().err
    assert not cache.exists()  # nothing was parsed


@pytest.fixture
def many_changes(repo: GitRepo) -> GitRepo:
    """300 elements with long names, element k gaining k % 7 + 1 statements."""
    folder = "pkg/" + "a_rather_long_folder_name_" * 6
    names = [f"{folder}/module_number_{k:03d}_with_a_long_name.py" for k in range(300)]
    repo.commit("v1", tag="v1", files={name: "x = 0\n" for name in names})
    changed = {
        name: "x = 0\n" + "".join(f"y{j} = {j}\n" for j in range(k % 7 + 1))
        for k, name in enumerate(names)
    }
    repo.commit("v2", tag="v2", files=changed)
    return repo


def _markdown(repo: GitRepo, capsys: pytest.CaptureFixture[str], *extra: str) -> str:
    argv = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2", "-q"]
    assert main([*argv, "--format", "markdown", "--no-cache", *extra]) == 0
    return capsys.readouterr().out


def _rows(markdown: str) -> list[str]:
    return [line for line in markdown.splitlines() if line.startswith("| `pkg/")]


def test_markdown_fits_a_pull_request_comment_and_says_what_it_left_out(
    many_changes: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    everything = _markdown(many_changes, capsys, "--max-rows", "0")
    assert len(_rows(everything)) == 300 and len(everything) > 65_536  # too long for GitHub
    fitted = _markdown(many_changes, capsys)
    rows = _rows(fitted)
    assert len(fitted) <= 65_536 and 0 < len(rows) < 300
    assert f"{300 - len(rows)} more changed elements not shown" in fitted
    added = [int(row.split("|")[8]) for row in rows]  # the "added" column
    assert added == sorted(added, reverse=True) and added[0] == 7  # the most changed first
    five = _markdown(many_changes, capsys, "--max-rows", "5")
    assert len(_rows(five)) == 5 and "295 more changed elements not shown" in five
    assert main(["diff", "-C", str(many_changes.root), "--max-rows", "-1"]) == 2
