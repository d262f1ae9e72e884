"""archmetrics/schemas/estimate-1.schema.json holds every document `estimate` writes, with and
without --actual, and carries diff/1's stage definitions unchanged."""

from __future__ import annotations

import json
import textwrap
from importlib import resources
from pathlib import Path
from typing import Any

import pytest
from jsonschema import Draft202012Validator

from archmetrics.cli import main
from tests.gitrepo import GitRepo

PLAN = """\
[[architecture.planned.element]]
name = "app.py"
statements_added = 2
decisions_added = 1
[[architecture.planned.element]]
name = "lib.py"
new = true
statements_added = 3
functions_added = 1
[architecture.sketched]
sketch = { revision = "v2" }
"""


def _schema(name: str) -> Any:
    return json.loads((resources.files("archmetrics") / "schemas" / name).read_text("utf-8"))


def _validator() -> Draft202012Validator:
    schema = _schema("estimate-1.schema.json")
    Draft202012Validator.check_schema(schema)
    return Draft202012Validator(schema)


@pytest.fixture
def history(repo: GitRepo) -> GitRepo:
    app = "def main(x):\n    return x\n"
    repo.commit("one", tag="v1", files={"app.py": app})
    two = "import lib\n\n\ndef main(x):\n    if x:\n        return lib.f(x)\n    return x\n"
    repo.commit("two", tag="v2", files={"app.py": two, "lib.py": "def f(x):\n    return x\n"})
    return repo


def _document(capsys: pytest.CaptureFixture[str], root: Path, plan: Path, *argv: str) -> Any:
    code = main(["estimate", str(plan), "-C", str(root), "--base", "v1", "--format", "json",
                 "-q", "--no-cache", *argv])  # fmt: skip
    out, err = capsys.readouterr()
    assert code == 0, err
    return json.loads(out)


def test_every_estimate_document_holds_to_its_schema(
    history: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = tmp_path / "plan.toml"
    plan.write_text(textwrap.dedent(PLAN), encoding="utf-8")
    document = _document(capsys, history.root, plan)
    _validator().validate(document)
    assert set(document["architectures"]) == {"planned", "sketched"}
    actual = _document(capsys, history.root, plan, "--actual", "--head", "v2")
    _validator().validate(actual)
    assert actual["accuracy"]["sketched"]["locations"]["total"]["cost"]["error"] == 0
    del actual["accuracy"]
    assert not _validator().is_valid(actual)  # a measured change without its errors
    document["architectures"]["planned"]["stages"][0]["locations"].pop("new")
    assert not _validator().is_valid(document)


def test_the_estimate_schema_carries_the_diff_definitions_unchanged() -> None:
    diff = _schema("diff-1.schema.json")
    copied = _schema("estimate-1.schema.json")["$defs"]
    assert {k: copied[k] for k in diff["$defs"]} == diff["$defs"]
    stage = copied["stage"]["properties"]
    expected = {k: v for k, v in diff["properties"].items() if k != "schema"}
    assert {k: v for k, v in stage.items() if k != "label"} == expected
    assert copied["actual"]["properties"] == expected
    docs = (Path(__file__).resolve().parents[2] / "docs" / "json.md").read_text()
    assert "archmetrics/schemas/estimate-1.schema.json" in docs
    assert "archmetrics/schemas/plan-1.schema.json" in docs
