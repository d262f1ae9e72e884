"""archmetrics.api: the commands' tables as pandas DataFrames, measured on real repositories."""

from __future__ import annotations

import io
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from archmetrics import api
from archmetrics.cli import main
from tests.gitrepo import GitRepo

V1 = "def f(a):\n    if a:\n        return 1\n    return 2\n"
V2 = V1 + "\n\ndef g(b):\n    while b:\n        b -= 1\n    return b\n"
C_SRC = '#include "m.h"\nint m(int a) {\n    return a > 0 && a < 9;\n}\n'


@pytest.fixture
def stages(repo: GitRepo) -> GitRepo:
    repo.commit("one", tag="baseline", files={"core/m.py": V1})
    repo.commit(
        "two", tag="first", files={"core/m.py": V2, "new/n.c": C_SRC, "new/m.h": "int m(int);\n"}
    )
    repo.commit(
        "three", tag="second", files={"new/n.c": C_SRC.replace("a < 9", "a < 9 || a == 20")}
    )
    return repo


def _csv(capsys: pytest.CaptureFixture[str], *argv: str) -> pd.DataFrame:
    assert main([*argv, "--format", "csv", "-q", "--no-cache"]) == 0
    return pd.read_csv(io.StringIO(capsys.readouterr().out), keep_default_na=True)


def _same(frame: pd.DataFrame, csv: pd.DataFrame) -> None:
    """The same table, but for how each side spells a missing text (None in the frame, NaN
    as pandas reads an empty CSV cell)."""
    pd.testing.assert_frame_equal(
        frame.replace({None: np.nan}), csv.replace({None: np.nan}), check_dtype=False
    )


@pytest.mark.parametrize("by", ["file", "function", "element", "link"])
def test_a_scan_frame_has_the_rows_and_columns_of_the_csv(
    stages: GitRepo, capsys: pytest.CaptureFixture[str], by: str
) -> None:
    frame = api.scan(stages.root, by=by, cache=False, exclude=["*.h"])
    assert len(frame) > 0
    csv = _csv(capsys, "scan", str(stages.root), "--by", by, "--exclude", "*.h")
    if by == "file":  # the CSV also lists each excluded file, with its reason, last
        listed = csv[csv["excluded"].notna()]
        assert listed[["path", "excluded"]].values.tolist() == [["new/m.h", "exclude:*.h"]]
        assert listed.drop(columns=["path", "excluded"]).isna().all().all()
        csv = csv[csv["excluded"].isna()].drop(columns="excluded")
    _same(frame, csv)


def test_a_scan_frame_holds_numbers_as_numbers(stages: GitRepo) -> None:
    functions = api.scan(stages.root, by="function", cache=False)
    assert functions.set_index("function")["vg"].to_dict() == {"f": 2, "g": 2, "m": 3}
    assert pd.api.types.is_integer_dtype(functions["vg"])
    at_first = api.scan(stages.root, rev="baseline", cache=False)
    assert list(at_first["path"]) == ["core/m.py"]
    without = api.scan(stages.root, exclude=["new/**"], cache=False)
    assert list(without["path"]) == ["core/m.py"]
    with pytest.raises(ValueError, match="by='module'"):
        api.scan(stages.root, by="module")


def test_a_diff_frame_has_a_row_per_location_then_per_element(
    stages: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    frame = api.diff(stages.root, "baseline", "second", new=["new/**"], cache=False)
    locations = frame[frame["row"] == "location"].set_index("name")
    assert list(locations.index) == ["base", "new", "framework", "total"]
    assert locations.loc["new", "added"] > 0 and locations.loc["base", "added"] > 0
    elements = frame[frame["row"] == "element"].set_index("name")
    assert elements.loc["new/n", "status"] == "added"
    assert elements.loc["new/n", "post_vg"] == 3  # 1, &&, ||
    assert math.isnan(elements.loc["new/n", "pre_vg"])
    csv = _csv(capsys, "diff", "-C", str(stages.root), "--base", "baseline", "--head", "second",
               "--new", "new/**")  # fmt: skip
    _same(frame, csv)


def test_series_and_compare_frames_have_a_row_per_stage_and_location(
    stages: GitRepo, tmp_path: Path
) -> None:
    revisions = ["baseline", "first", "second"]
    frame = api.series(stages.root, revisions, new=["new/**"], cache=False)
    assert list(frame["stage"].unique()) == revisions
    assert len(frame) == 3 * 4
    new = frame[frame["location"] == "new"].set_index("stage")
    assert new.loc["first", "changes"] > 0 and new.loc["second", "changes"] > 0
    both = api.compare({"a": stages.root, "b": stages.root}, new=["new/**"], cache=False)
    assert list(both["approach"].unique()) == ["a", "b"]  # the tags, in history order
    assert list(both["stage"].unique()) == revisions
    pd.testing.assert_frame_equal(
        both[both["approach"] == "a"].drop(columns="approach").reset_index(drop=True),
        frame.drop(columns="approach"),
    )


def test_the_api_uses_the_facts_cache_the_configuration_names(
    stages: GitRepo, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    monkeypatch.setenv("ARCHMETRICS_CACHE", str(tmp_path / "api.sqlite3"))
    first = api.scan(stages.root, by="function")
    assert (tmp_path / "api.sqlite3").exists()
    pd.testing.assert_frame_equal(api.scan(stages.root, by="function"), first)


def test_an_estimate_frame_has_the_rows_and_columns_of_the_csv(
    stages: GitRepo, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    plan = tmp_path / "plan.toml"
    plan.write_text(
        '[[architecture.a.element]]\nname = "core/m.py"\nstatements_added = 3\n'
        "functions_added = 1\ndecisions_added = 1\n"
        '[architecture.b]\nsketch = { revision = "first" }\n',
        encoding="utf-8",
    )
    frame = api.estimate(plan, stages.root, "baseline", cache=False)
    argv = ["estimate", str(plan), "-C", str(stages.root), "--base", "baseline"]
    _same(frame, _csv(capsys, *argv))
    assert set(frame["architecture"]) == {"a", "b"}
    errors = api.estimate(plan, stages.root, "baseline", actual="first", cache=False)
    _same(errors, _csv(capsys, *argv, "--actual", "--head", "first"))
    total = errors.query("architecture == 'b' and name == 'total' and figure == 'cost'")
    assert total["error"].tolist() == [0.0]  # the sketch is the measured change


def test_a_history_frame_has_the_rows_and_columns_of_the_csv(
    stages: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    frame = api.history(stages.root, new=["new/**"])
    assert list(frame["subject"].unique()) == ["one", "two", "three"]
    assert len(frame) == 3 * 4
    new = frame[frame["location"] == "new"].set_index("subject")
    assert new.loc["two", "changes"] > 0 and new.loc["one", "changes"] == 0
    csv = _csv(capsys, "history", "-C", str(stages.root), "--new", "new/**")
    _same(frame, csv)
