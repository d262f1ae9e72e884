"""Offenders: `--format warnings` (one compiler-style line per offender, worst first, nothing
else), reviewed functions (`archmetrics: ignore[vg]`, C, C++ and Python), the baseline
(`archmetrics baseline`, `--baseline FILE`), and a diff's function gates over the functions
the change touches.

The tree, v_g by hand (1 + one per `if`, `&&`, `||`): C `small` 1, `step` 5 (four ifs),
`reviewed` 7 (six ifs, a comment exempts it); C++ `Motor::drive` 4 (three ifs); Python
`plan` 6 (five ifs), `tidy` 6 (five ifs, exempted on its `def` line). Over
`vg(function) > 3`, worst first by (v_g - 3) / 3: plan 1.0, step 0.67, drive 0.33.
"""

from __future__ import annotations

import json
from importlib import resources
from pathlib import Path
from typing import Any

import pytest
from jsonschema import Draft202012Validator

from archmetrics.cli import main
from tests.gitrepo import GitRepo

MOTOR = """\
int small(int a)
{
    return a;
}

int step(int a, int b)
{
    if (a) return 1;
    if (b) return 2;
    if (a > b) return 3;
    if (a < b) return 4;
    return 0;
}

/* a dispatch table, reviewed:
 * archmetrics: ignore[vg] */
int reviewed(int a)
{
    if (a == 1) return 1;
    if (a == 2) return 2;
    if (a == 3) return 3;
    if (a == 4) return 4;
    if (a == 5) return 5;
    if (a == 6) return 6;
    return 0;
}
"""
DRIVE = """\
class Motor {
  public:
    int drive(int a);
};

int Motor::drive(int a)
{
    if (a > 10) return 10;
    if (a < 0) return 0;
    if (a == 5) return 6;
    return a;
}
"""
PLAN = """\
def plan(a):
    if a == 1:
        return 1
    if a == 2:
        return 2
    if a == 3:
        return 3
    if a == 4:
        return 4
    if a == 5:
        return 5
    return 0


def tidy(a):  # archmetrics: ignore[vg]
    if a == 1:
        return 1
    if a == 2:
        return 2
    if a == 3:
        return 3
    if a == 4:
        return 4
    if a == 5:
        return 5
    return 0
"""
GATE = "vg(function) > 3"


@pytest.fixture
def tree(repo: GitRepo) -> GitRepo:
    repo.commit("v1", tag="v1", files={"src/motor.c": MOTOR, "src/drive.cpp": DRIVE,
                                       "src/plan.py": PLAN})  # fmt: skip
    return repo


def _run(capsys: pytest.CaptureFixture[str], *argv: str, status: int) -> tuple[str, str]:
    assert main([*argv, "-q", "--no-cache"]) == status
    captured = capsys.readouterr()
    return captured.out, captured.err


def test_warnings_list_every_offender_worst_first_and_nothing_else(
    tree: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    out, err = _run(capsys, "scan", str(tree.root), "--fail-on", GATE, "--format", "warnings",
                    status=1)  # fmt: skip
    assert out == (
        "src/plan.py:1:1: error: vg(function) > 3: plan (vg = 6)\n"
        "src/motor.c:6:1: error: vg(function) > 3: step (vg = 5)\n"
        "src/drive.cpp:6:1: error: vg(function) > 3: Motor::drive (vg = 4)\n"
    )
    assert err == ""  # the failures are the output: not printed twice
    out, _ = _run(capsys, "scan", str(tree.root), "--fail-on", "vg(function) > 9",
                  "--format", "warnings", status=0)  # fmt: skip
    assert out == ""


def test_a_reviewed_function_is_exempt_counted_and_listed(
    tree: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    out, _ = _run(capsys, "scan", str(tree.root), "--fail-on", GATE, status=1)
    assert "suppressed by a comment: vg(function) > 3: src/motor.c:17 reviewed (vg = 7)" in out
    assert "suppressed by a comment: vg(function) > 3: src/plan.py:15 tidy (vg = 6)" in out
    document: Any = json.loads(_run(capsys, "scan", str(tree.root), "--fail-on", GATE,
                                    "--format", "json", status=1)[0])  # fmt: skip
    [gate] = document["gates"]
    assert [f["name"] for f in gate["failures"]] == ["plan", "step", "Motor::drive"]
    assert [(s["name"], s["values"]) for s in gate["suppressed"]] == [
        ("reviewed", {"vg": 7}), ("tidy", {"vg": 6})
    ]
    assert gate["baselined"] == []
    # the comment changes no number: v_g of the tree is 1 + 5 + 7 + 4 + 6 + 6
    assert document["totals"]["vg"] == 29
    # it names vg only: a loc threshold still sees the function (14 statements)
    out, _ = _run(capsys, "scan", str(tree.root), "--fail-on", "loc(function) > 13",
                  "--format", "warnings", status=1)  # fmt: skip
    assert out == "src/motor.c:17:1: error: loc(function) > 13: reviewed (loc = 14)\n"


def test_a_baseline_keeps_known_offenders_and_fails_new_or_worse_ones(
    tree: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    baseline = tmp_path / "baseline.json"
    out, _ = _run(capsys, "baseline", str(tree.root), "--fail-on", GATE, "-o", str(baseline),
                  status=0)  # fmt: skip
    assert out == f"archmetrics: 3 offenders of {GATE} written to {baseline}\n"
    written = json.loads(baseline.read_text())
    schema = resources.files("archmetrics") / "schemas" / "baseline-1.schema.json"
    Draft202012Validator(json.loads(schema.read_text(encoding="utf-8"))).validate(written)
    assert [(o["kind"], o["path"], o["name"], o["values"]) for o in written["offenders"]] == [
        ("function", "src/drive.cpp", "Motor::drive", {"vg": 4, "loc": 8}),
        ("function", "src/motor.c", "step", {"vg": 5, "loc": 10}),
        ("function", "src/plan.py", "plan", {"vg": 6, "loc": 12}),
    ]
    scan = ["scan", str(tree.root), "--fail-on", GATE, "--baseline", str(baseline)]
    out, _ = _run(capsys, *scan, "--format", "warnings", status=0)
    assert out == ""  # every offender known, none worse
    # step moves down five lines, unchanged: still known (matched by file and name)
    tree.write({"src/motor.c": "/* moved */\n" * 5 + MOTOR})
    assert _run(capsys, *scan, "--format", "warnings", status=0)[0] == ""
    # drive gets one more `if` (v_g 5): worse; a new function over the limit: new
    worse = DRIVE.replace("    return a;\n", "    if (a == 7) return 8;\n    return a;\n")
    fresh = "\nint fresh(int a)\n{\n    if (a) return 1;\n    if (!a) return 2;\n" \
        "    if (a > 2) return 3;\n    return 0;\n}\n"
    tree.write({"src/drive.cpp": worse + fresh})
    out, _ = _run(capsys, *scan, "--format", "warnings", status=1)
    assert out == (
        "src/drive.cpp:6:1: error: vg(function) > 3: Motor::drive (vg = 5)\n"
        "src/drive.cpp:15:1: error: vg(function) > 3: fresh (vg = 4)\n"
    )
    out, _ = _run(capsys, *scan, status=1)
    assert "2 offenders the baseline knows, none worse (not failing):" in out


def test_a_broken_baseline_is_refused_in_one_line(
    tree: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    bad = tmp_path / "bad.json"
    for text, said in (
        ("[]", "not an archmetrics.baseline/1 document"),
        ('{"schema": "archmetrics.baseline/1", "offenders": [{"kind": "x"}]}',
         "offenders[0]: kind: expected function, file, element or total"),
        ("{", "not JSON"),
    ):  # fmt: skip
        bad.write_text(text)
        _, err = _run(capsys, "scan", str(tree.root), "--fail-on", GATE, "--baseline",
                      str(bad), status=2)  # fmt: skip
        assert said in err and len(err.strip().splitlines()) == 1
    _, err = _run(capsys, "baseline", str(tree.root), status=2)
    assert "a baseline records the offenders of thresholds" in err


def test_a_diff_gates_only_the_functions_the_change_touches(
    tree: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    """v2 gives `small` three ifs (v_g 4) and edits `reviewed` (exempt); step (5), drive (4)
    and plan (6) are over the limit but untouched: not this change's offenders."""
    busy = "int small(int a)\n{\n    if (a > 1) return 1;\n    if (a > 2) return 2;\n" \
        "    if (a > 3) return 3;\n    return a;\n}\n"
    motor = MOTOR.replace("int small(int a)\n{\n    return a;\n}\n", busy)
    motor = motor.replace("if (a == 6) return 6;", "if (a == 6) return 7;")
    tree.commit("v2", tag="v2", files={"src/motor.c": motor})
    diff = ["diff", "-C", str(tree.root), "--base", "v1", "--head", "v2", "--fail-on", GATE]
    out, _ = _run(capsys, *diff, "--format", "warnings", status=1)
    assert out == "src/motor.c:1:1: error: vg(function) > 3: small (vg = 4)\n"
    document: Any = json.loads(_run(capsys, *diff, "--format", "json", status=1)[0])
    [gate] = [g for g in document["gates"] if g["gate"] == GATE]
    assert gate["gate"] == GATE and gate["failed"] and gate["values"] == {}
    assert [(f["name"], f["line"]) for f in gate["failures"]] == [("small", 1)]
    assert [s["name"] for s in gate["suppressed"]] == ["reviewed"]
    markdown, _ = _run(capsys, *diff, "--format", "markdown", status=1)
    assert "**1 gate failure(s)**" in markdown
    assert "suppressed by a comment: vg(function) > 3: src/motor.c:20 reviewed (vg = 7)" in markdown


def test_a_diff_with_a_baseline_fails_a_touched_offender_only_when_worse(
    tree: GitRepo, capsys: pytest.CaptureFixture[str], tmp_path: Path
) -> None:
    baseline = tmp_path / "baseline.json"
    _run(capsys, "baseline", str(tree.root), "--fail-on", GATE, "-o", str(baseline), status=0)
    same = MOTOR.replace("if (b) return 2;", "if (b) return 22;")  # step touched, v_g 5
    tree.commit("v2", tag="v2", files={"src/motor.c": same})
    diff = ["diff", "-C", str(tree.root), "--fail-on", GATE, "--baseline", str(baseline)]
    out, _ = _run(capsys, *diff, "--base", "v1", "--head", "v2", "--format", "json", status=0)
    [gate] = [g for g in json.loads(out)["gates"] if g["gate"] == GATE]
    assert gate["failures"] == [] and [b["name"] for b in gate["baselined"]] == ["step"]
    end = "    return 0;\n}\n\n/*"  # the end of step
    worse = same.replace(end, "    if (a == b) return 5;\n" + end)
    tree.commit("v3", tag="v3", files={"src/motor.c": worse})
    out, _ = _run(capsys, *diff, "--base", "v2", "--head", "v3", "--format", "warnings",
                  status=1)  # fmt: skip
    assert out == "src/motor.c:6:1: error: vg(function) > 3: step (vg = 6)\n"
