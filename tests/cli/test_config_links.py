"""Configuration links end to end: a router's rules file in real folders and repositories,
through scan (its link view), diff (per element and location), the caches and hostile input."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from archmetrics.cli import main
from tests.gitrepo import GitRepo
from tests.untrusted import checksums, run_main

ONE_ROUTE = """[[rules]]
operation = "drive"
[[rules.to]]
kind = "send"
service = "muri.backend"
operation = "translate"
"""
TWO_ROUTES = (
    ONE_ROUTE + '\n[[rules]]\noperation = "turn"\n[[rules.to]]\nkind = "send"\n'
    'service = "muri.backend"\noperation = "rotate"\n'
)
BACKEND = 'import robosoa\n\n\ndef serve(bus, handler):\n    bus.provide("muri.backend", handler)\n'


def _run(capsys: pytest.CaptureFixture[str], *argv: str) -> Any:
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out) if "json" in argv else out


def test_a_folder_holding_only_router_rules_has_one_messaging_link(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """The reproducer in docs/study.md, "Router rules": one route, one messaging link."""
    monkeypatch.setenv("COLUMNS", "300")  # every cell whole, however long the temp path
    (tmp_path / "rules.toml").write_text(ONE_ROUTE)
    table = _run(capsys, "scan", "--by", "link", str(tmp_path), "--no-cache")
    row = next(line for line in table.splitlines() if "rules.toml:3" in line)
    for cell in ("dynamic", "robosoa/route-service", "messaging", "initiate",
                 "service:muri.backend", "external"):  # fmt: skip
        assert cell in row
    [element] = _run(capsys, "scan", str(tmp_path), "--format", "json", "--by", "element")[
        "elements"
    ]
    assert (element["element"], element["d_e"], element["loc"], element["vg"]) == (
        "rules.toml", 1, 0, 0,
    )  # fmt: skip
    [site] = element["link_sites"]
    assert (site["path"], site["line"], site["rule"], site["callee"]) == (
        "rules.toml", 3, "robosoa/route-service", "rules.to",
    )  # fmt: skip


@pytest.fixture
def router(repo: GitRepo) -> GitRepo:
    files = {"backend_app.py": BACKEND, "pragmatics/rules.toml": ONE_ROUTE}
    repo.commit("baseline", tag="v1", files=files)
    repo.commit("first", tag="v2", files={"pragmatics/rules.toml": TWO_ROUTES})
    return repo


def _diff(repo: GitRepo, capsys: pytest.CaptureFixture[str], *more: str) -> Any:
    argv = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2", "--format", "json"]
    return _run(capsys, *argv, "--framework", "pragmatics/**", *more)


def test_a_new_route_is_a_change_of_its_element_and_location(
    router: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    doc = _diff(router, capsys, "--no-cache")
    elements = {e["element"]: e for e in doc["elements"]}
    rules, backend = elements["pragmatics/rules.toml"], elements["backend_app.py"]
    assert (rules["location"], rules["status"]) == ("framework", "modified")
    assert (rules["pre"]["d_e"], rules["post"]["d_e"]) == (1, 2)
    assert (backend["pre"]["d_a"], backend["post"]["d_a"]) == (1, 2)  # the routes resolve
    framework, base = doc["locations"]["framework"], doc["locations"]["base"]
    assert (framework["delta_d_e"], framework["changes"], framework["delta_vg"]) == (1, 0, 0)
    assert base["delta_d_a"] == 1


def test_the_caches_serve_the_same_links_and_know_the_rule_packs(
    router: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    cache = str(tmp_path / "c.sqlite3")
    cold = _diff(router, capsys, "--cache-path", cache)
    warm = _diff(router, capsys, "--cache-path", cache)
    assert warm == cold
    # a configured pack that also reads each rule's operation: what was kept under the
    # built-in packs alone must not be served
    router.write({
        "pack.toml": '[pack]\nname = "mine"\n[[configuration]]\nid = "operation"\n'
        'files = ["rules.toml"]\nformat = "toml"\ntable = "rules"\nkind = "config"\n'
        'role = "use"\nendpoint = { type = "operation", key = "operation" }\n',
        "pyproject.toml": '[tool.archmetrics.coupling]\nrule-packs = ["pack.toml"]\n',
    })  # fmt: skip
    config = ["--config-from", str(router.root / "pyproject.toml")]  # not committed
    mine = _diff(router, capsys, "--cache-path", cache, *config)
    assert mine["locations"]["framework"]["delta_d_e"] == 2  # the route and the operation
    assert main(["cache", "info", "--cache-path", cache]) == 0
    capsys.readouterr()


@pytest.mark.security
def test_a_linked_rules_file_is_not_followed_and_a_broken_one_is_reported(
    tmp_path: Path,
) -> None:
    outside = tmp_path / "outside.toml"
    outside.write_text(ONE_ROUTE)
    repo = GitRepo(tmp_path / "repo")
    (repo.root / "linked").mkdir()
    (repo.root / "linked" / "rules.toml").symlink_to(outside)
    repo.commit("v1", files={"broken/rules.toml": "[[rules]\nto = [\n", "a.py": "x = 1\n"})
    before = checksums(tmp_path)
    done = run_main(["scan", "--by", "link", "--no-cache", "--format", "json", "."], repo.root)
    assert done.code == 0, done.err
    files = {f["path"]: f for f in json.loads(done.out)["files"]}
    assert set(files) == {"a.py", "broken/rules.toml"}  # the link is skipped, like any link
    assert files["broken/rules.toml"]["parsed"] is False
    assert files["broken/rules.toml"]["warnings"][0]["message"].startswith("not valid TOML")
    assert checksums(tmp_path) == before


@pytest.mark.security
def test_a_huge_rules_file_is_over_the_file_limit_not_read(tmp_path: Path) -> None:
    (tmp_path / "pyproject.toml").write_text("[tool.archmetrics.limits]\nfile-mb = 0.01\n")
    (tmp_path / "rules.toml").write_text(ONE_ROUTE + '\n[[rules]]\nx = "y"\n' * 2_000)
    done = run_main(["scan", "--no-cache", "--format", "json", "."], tmp_path)
    assert done.code == 0, done.err
    [facts] = json.loads(done.out)["files"]
    assert facts["parsed"] is False and "limit" in facts["warnings"][0]["message"]


def test_a_configured_pack_with_a_bad_glob_is_one_line_naming_the_key(tmp_path: Path) -> None:
    (tmp_path / "a.py").write_text("x = 1\n")
    (tmp_path / "pack.toml").write_text(
        '[pack]\nname = "mine"\n[[configuration]]\nid = "r"\nfiles = ["!rules.toml"]\n'
        'format = "toml"\ntable = "t"\nkind = "messaging"\nrole = "initiate"\n'
        'endpoint = { type = "service", key = "to" }\n'
    )
    (tmp_path / "pyproject.toml").write_text(
        '[tool.archmetrics.coupling]\nrule-packs = ["pack.toml"]\n'
    )
    done = run_main(["scan", "--no-cache", "."], tmp_path)
    assert done.code == 2
    line = done.one_line_error()
    assert "pack.toml" in line and "rule 'r'" in line and "key 'files'" in line
