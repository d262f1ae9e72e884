"""SARIF 2.1.0 for GitHub code scanning: every failed gate and threshold a result, located
where it is, valid against the published SARIF 2.1.0 schema (taken from the npm registry,
where Microsoft's SARIF SDK publishes it, pinned by version and digest) and against the
constraints GitHub documents for an upload ("SARIF support for code scanning" and its
limits page), checked one by one in :func:`github_accepts`."""

from __future__ import annotations

import hashlib
import io
import json
import os
import shutil
import subprocess
import tarfile
from pathlib import Path
from typing import Any

import jsonschema
import pytest

from archmetrics.cli import main
from tests.gitrepo import GitRepo

BRANCHY = "def f(a, b):\n    if a:\n        return 1\n    if b:\n        return 2\n    return 3\n"
SCHEMA_PACKAGE = "@microsoft/sarif-matcher-utils@1.0.0-beta.0"  # MIT, Microsoft's SARIF SDK
SCHEMA_MEMBER = "package/lib/schemas/sarif-2.1.0-rtm.5.json"  # the 2.1.0 schema as published
SCHEMA_SHA256 = "2d99159ae54a3eea97f81781cff48780548657c35949f4b7f25e99a2ba4de4f8"


def _unavailable(why: str) -> None:
    """CI installs what the tests need from the registries: there, a missing schema fails."""
    if os.environ.get("CI"):
        pytest.fail(f"the SARIF schema could not be fetched from the npm registry: {why}")
    pytest.skip(f"the SARIF schema could not be fetched from the npm registry: {why}")


@pytest.fixture(scope="session")
def sarif_schema(tmp_path_factory: pytest.TempPathFactory) -> Any:
    npm = shutil.which("npm")
    if npm is None:
        _unavailable("npm is not installed")
    assert npm is not None
    folder = tmp_path_factory.mktemp("sarif-schema")
    command = [npm, "pack", SCHEMA_PACKAGE, "--pack-destination", str(folder), "--silent"]
    try:
        subprocess.run(command, cwd=folder, capture_output=True, check=True, timeout=180)
    except (subprocess.SubprocessError, OSError) as error:
        _unavailable(str(error))
    [packed] = folder.glob("*.tgz")
    with tarfile.open(packed) as archive:
        member = archive.extractfile(SCHEMA_MEMBER)
        assert member is not None
        data = member.read()
    assert hashlib.sha256(data).hexdigest() == SCHEMA_SHA256  # the schema pinned, unchanged
    return json.load(io.BytesIO(data))


def github_accepts(document: dict[str, Any], root: Path) -> None:
    """What GitHub documents for a SARIF upload, beyond the schema: at most 20 runs, 25,000
    results and 25,000 rules a run; each result has a ruleId naming one of the run's rules,
    a message text and one to 1,000 locations, each a physical location whose URI is
    relative to the checkout (here: a file under ``root``) with a region starting at line 1
    or later, within the file; each rule has an id and short and full descriptions of at most
    1,024 characters, at most 20 tags, help text and an absolute helpUri."""
    runs = document["runs"]
    assert document["version"] == "2.1.0" and 1 <= len(runs) <= 20
    for run in runs:
        rules = run["tool"]["driver"]["rules"]
        assert len(run["results"]) <= 25_000 and len(rules) <= 25_000
        ids = [rule["id"] for rule in rules]
        assert len(set(ids)) == len(ids)
        for rule in rules:
            assert 0 < len(rule["shortDescription"]["text"]) <= 1024
            assert 0 < len(rule["fullDescription"]["text"]) <= 1024
            assert len(rule.get("properties", {}).get("tags", [])) <= 20
            assert rule["help"]["text"] and rule["help"]["markdown"]
            assert "://" in rule["helpUri"] or rule["helpUri"].startswith("file:")
        for result in run["results"]:
            assert result["ruleId"] in ids and result["message"]["text"]
            assert 1 <= len(result["locations"]) <= 1000
            for location in result["locations"]:
                physical = location["physicalLocation"]
                uri = physical["artifactLocation"]["uri"]
                assert ":" not in uri and not uri.startswith(("/", "../")) and ".." not in uri
                lines = (root / uri).read_text(encoding="utf-8").count("\n") or 1
                assert 1 <= physical["region"]["startLine"] <= lines


def _sarif(
    capsys: pytest.CaptureFixture[str],
    schema: Any,
    *argv: str,
    status: int,
    root: Path | None = None,
) -> dict[str, Any]:
    assert main([*argv, "--format", "sarif", "-q", "--no-cache"]) == status
    document: dict[str, Any] = json.loads(capsys.readouterr().out)
    jsonschema.Draft4Validator(schema).validate(document)
    if root is not None:
        github_accepts(document, root)
    [run] = document["runs"]
    assert run["tool"]["driver"]["name"] == "archmetrics"
    rules = [r["id"] for r in run["tool"]["driver"]["rules"]]
    for result in run["results"]:
        assert rules[result["ruleIndex"]] == result["ruleId"]
        assert result["level"] == "error"
    return document


def _located(document: dict[str, Any]) -> set[tuple[str, str, int]]:
    return {
        (
            r["ruleId"],
            r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"],
            r["locations"][0]["physicalLocation"]["region"]["startLine"],
        )
        for r in document["runs"][0]["results"]
    }


def test_a_scan_threshold_is_a_result_at_its_function_or_file(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], sarif_schema: Any
) -> None:
    repo.commit("one", files={"src/m.py": "import os\n\n\n" + BRANCHY, "src/ok.py": "x = 1\n"})
    argv = ["scan", str(repo.root), "--fail-on", "vg(function) > 2", "--fail-on", "loc(file) > 5"]
    document = _sarif(capsys, sarif_schema, *argv, status=1)
    assert _located(document) == {
        ("vg(function) > 2", "src/m.py", 4),
        ("loc(file) > 5", "src/m.py", 1),
    }
    again = _sarif(capsys, sarif_schema, *argv, status=1)
    prints = [r["partialFingerprints"] for r in document["runs"][0]["results"]]
    assert [r["partialFingerprints"] for r in again["runs"][0]["results"]] == prints
    assert len({p["archmetrics/v1"] for p in prints}) == 2
    # the same fingerprints as the Code Climate report's, so both name one finding alike
    assert main([*argv, "--format", "codeclimate", "-q", "--no-cache"]) == 1
    issues = json.loads(capsys.readouterr().out)
    assert sorted(i["fingerprint"] for i in issues) == sorted(p["archmetrics/v1"] for p in prints)
    quiet = _sarif(
        capsys, sarif_schema, "scan", str(repo.root), "--fail-on", "vg(file) > 9", status=0
    )
    assert quiet["runs"][0]["results"] == [] and quiet["runs"][0]["tool"]["driver"]["rules"] == []


def test_a_diff_gate_is_shown_at_the_file_the_change_touched_most(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], sarif_schema: Any, tmp_path: Path
) -> None:
    repo.commit("one", tag="v1", files={"a.py": "x = 1\n", "b.py": "y = 1\n"})
    repo.commit("two", tag="v2", files={"a.py": "x = 2\n", "b.py": "y = 1\n" + BRANCHY})
    argv = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2"]
    document = _sarif(capsys, sarif_schema, *argv, "--fail-on", "changes > 2", status=1)
    assert _located(document) == {("changes > 2", "b.py", 1)}
    [result] = document["runs"][0]["results"]
    assert result["message"]["text"].startswith("changes > 2 (changes(total) = ")
    assert result["message"]["text"].endswith("shown at the file it changed most)")
    passing = _sarif(capsys, sarif_schema, *argv, "--fail-on", "changes > 100", status=0)
    assert passing["runs"][0]["results"] == []
    staged = _sarif(capsys, sarif_schema, "series", "v1", "v2", "--repo", str(repo.root),
                    "--fail-on", "changes > 2", status=1)  # fmt: skip
    texts = [r["message"]["text"].split(":")[0] for r in staged["runs"][0]["results"]]
    assert texts == ["v2"]  # the stage that failed
    github_accepts(staged, repo.root)
    out = tmp_path / "scan.sarif"  # the suffix names the format
    assert main([*argv, "--fail-on", "changes > 2", "-q", "--no-cache", "-o", str(out)]) == 1
    jsonschema.Draft4Validator(sarif_schema).validate(json.loads(out.read_text()))


def _results(document: dict[str, Any]) -> list[tuple[str, str, int, str]]:
    return [
        (
            r["ruleId"],
            r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"],
            r["locations"][0]["physicalLocation"]["region"]["startLine"],
            r["message"]["text"],
        )
        for r in document["runs"][0]["results"]
    ]


def test_every_scan_threshold_kind_has_a_file_and_the_worst_comes_first(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], sarif_schema: Any
) -> None:
    """Function, file, element and total thresholds: each result at a file of the tree, the
    tree-wide and element-wide ones at the file contributing most, saying so."""
    small = "def g(a):\n    if a:\n        return 1\n    return 0\n"  # v_g 2
    repo.commit("one", files={"src/m.py": BRANCHY, "src/n.py": small, "lib/big.py": BRANCHY
                              + "def h(a, b, c):\n    if a and b or c:\n        return 1\n"
                              "    return 0\n", "lib/broken.py": "def (\n"})  # fmt: skip
    argv = ["scan", str(repo.root), "--fail-on", "vg(function) > 1", "--fail-on",
            "vg(total) > 5", "--fail-on", "vg(element) > 2", "--fail-on", "unparsed(total) > 0",
            "--fail-on", "files(total) > 1"]  # fmt: skip
    document = _sarif(capsys, sarif_schema, *argv, status=1, root=repo.root)
    found = _results(document)
    assert len(found) == len(document["runs"][0]["results"])
    function = [(path, line) for rule, path, line, _ in found if rule == "vg(function) > 1"]
    # worst first: h (v_g 4) over f (v_g 3) twice over g (v_g 2)
    assert function == [("lib/big.py", 7), ("lib/big.py", 1), ("src/m.py", 1), ("src/n.py", 1)]
    [total] = [r for r in found if r[0] == "vg(total) > 5"]
    assert total[1:3] == ("lib/big.py", 1) and "highest v_g" in total[3]
    [unparsed] = [r for r in found if r[0] == "unparsed(total) > 0"]
    assert unparsed[1] == "lib/broken.py" and "could not be parsed" in unparsed[3]
    elements = {(path, text.split(": ")[1].split(" (")[0]) for rule, path, _, text in found
                if rule == "vg(element) > 2"}  # fmt: skip
    assert ("lib/big.py", "lib") in elements or ("lib/big.py", "lib/big.py") in elements
    assert _sarif(capsys, sarif_schema, *argv, status=1, root=repo.root) == document  # stable


def test_a_configured_gate_points_at_its_line_and_a_change_of_nothing_at_the_largest_file(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], sarif_schema: Any
) -> None:
    config = '# gates\ngates = [\n  "changes > 100",\n  "changes >= 0",\n]\n'
    repo.commit("one", tag="v1", files={"archmetrics.toml": config, "a.py": "x = 1\n",
                                        "b.py": BRANCHY})  # fmt: skip
    repo.commit("two", tag="v2", files={"README.md": "docs only\n"})
    argv = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2"]
    document = _sarif(capsys, sarif_schema, *argv, "--fail-on", "loc_post >= 0", status=1,
                      root=repo.root)  # fmt: skip
    found = {r[0]: r[1:] for r in _results(document)}
    assert found["changes >= 0"][:2] == ("archmetrics.toml", 4)  # the gate's own line
    assert found["changes >= 0"][2].endswith("the gate is set in archmetrics.toml)")
    assert found["loc_post >= 0"][:2] == ("b.py", 1)  # no file changed: the largest one
    assert "it changed no file: shown at its largest file" in found["loc_post >= 0"][2]
    compared = _sarif(capsys, sarif_schema, "compare", f"one={repo.root}", "--revisions",
                      "v1,v2", "--fail-on", "loc_post >= 0", status=1, root=repo.root)  # fmt: skip
    located = sorted((r[0], r[1], r[3].split(":")[0]) for r in _results(compared))
    assert located == [  # per stage: the first (from the empty tree) changed b.py most
        ("changes >= 0", "archmetrics.toml", "one v1"),
        ("changes >= 0", "archmetrics.toml", "one v2"),
        ("loc_post >= 0", "b.py", "one v1"),
        ("loc_post >= 0", "b.py", "one v2"),
    ]


def test_an_estimate_gate_points_at_the_plan(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], sarif_schema: Any
) -> None:
    plan = (
        '[[architecture.flat.element]]\nname = "new.py"\nnew = true\nstatements_added = 9\n'
        "functions_added = 1\ndecisions_added = 2\n"
    )
    repo.commit("one", files={"plans/plan.toml": plan, "a.py": BRANCHY})
    argv = ["estimate", str(repo.root / "plans" / "plan.toml"), "-C", str(repo.root)]
    document = _sarif(capsys, sarif_schema, *argv, "--fail-on", "changes > 1", status=1,
                      root=repo.root)  # fmt: skip
    [(rule, path, line, text)] = _results(document)
    assert (rule, path, line) == ("changes > 1", "plans/plan.toml", 1)
    assert text.startswith("flat estimate: changes > 1") and text.endswith("shown at the plan)")


def test_a_finding_about_nothing_measured_is_a_notification_not_a_result(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], sarif_schema: Any
) -> None:
    repo.commit("one", tag="v1", files={"README.md": "docs\n"})
    repo.commit("two", tag="v2", files={"README.md": "more docs\n"})
    argv = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2"]
    document = _sarif(capsys, sarif_schema, *argv, "--fail-on", "changes == 0", status=1,
                      root=repo.root)  # fmt: skip
    [run] = document["runs"]
    assert run["results"] == []
    [note] = run["invocations"][0]["toolExecutionNotifications"]
    assert note["message"]["text"].startswith("changes == 0 (changes(total) = 0)")
    assert "nothing was measured" in note["message"]["text"]


def test_rules_carry_help_and_a_help_uri_into_the_docs(
    repo: GitRepo, capsys: pytest.CaptureFixture[str], sarif_schema: Any,
    monkeypatch: pytest.MonkeyPatch,
) -> None:  # fmt: skip
    repo.commit("one", files={"m.py": BRANCHY})
    argv = ["scan", str(repo.root), "--fail-on", "vg(function) > 2"]
    document = _sarif(capsys, sarif_schema, *argv, status=1, root=repo.root)
    [rule] = document["runs"][0]["tool"]["driver"]["rules"]
    assert "McCabe complexity" in rule["help"]["text"]
    uri, anchor = rule["helpUri"].split("#")
    page = Path(uri.removeprefix("file://"))
    assert page.name == "ci.md" and page.is_file() and anchor == "gates"
    assert "\n## Gates\n" in page.read_text(encoding="utf-8")
    monkeypatch.setenv("ARCHMETRICS_DOCS_URL", "https://docs.example.invalid/archmetrics/")
    document = _sarif(capsys, sarif_schema, *argv, status=1, root=repo.root)
    [rule] = document["runs"][0]["tool"]["driver"]["rules"]
    assert rule["helpUri"] == "https://docs.example.invalid/archmetrics/ci.md#gates"
