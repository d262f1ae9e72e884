"""The surprises of E that docs/ci.md ("Choosing gates") and docs/glossary.md ("Reading E")
explain, shown on real repositories, every number derived by hand (a statement is a logical
line; the `def` line counts; v_g is 1 + the ifs of a function)."""

from __future__ import annotations

import json
from typing import Any

import pytest

from archmetrics.cli import main
from tests.gitrepo import GitRepo

RUN = "def run(x):\n    if x:\n        return 1\n    return 0\n"  # λ 4, v_g 2


def _total(repo: GitRepo, capsys: pytest.CaptureFixture[str], *gates: str, status: int) -> Any:
    argv = ["diff", "-C", str(repo.root), "--base", "v1", "--head", "v2", "-q", "--no-cache"]
    argv += ["--format", "json", *(a for g in gates for a in ("--fail-on", g))]
    assert main(argv) == status
    return json.loads(capsys.readouterr().out)["locations"]["total"]


def test_forty_sequential_statements_cost_e_0_and_pass_a_cost_gate(
    repo: GitRepo, capsys: pytest.CaptureFixture[str]
) -> None:
    repo.commit("v1", tag="v1", files={"app.py": RUN})
    body = "".join(f"    v{i} = x\n" for i in range(40))
    longer = RUN.replace("def run(x):\n", "def run(x):\n" + body)
    repo.commit("v2", tag="v2", files={"app.py": longer})
    total = _total(repo, capsys, "cost > 3", status=0)
    # Γ = 40 added; ΔVg = 0 so ΔVg' = 0 and E = 0 (eq. 6.38)
    assert (total["changes"], total["delta_vg"], total["cost"]) == (40, 0, 0.0)
    assert any(n.startswith("cost_zero_no_complexity_change") for n in total["notes"])
    # the size gate sees it: λ̂ = 44 / 4 = 11, Γ' = 11 · 40 = 440
    total = _total(repo, capsys, "cost > 3", "scaled_changes > 200", status=1)
    assert total["scaled_changes"] == 440.0


def test_a_trivial_function_lowers_e(repo: GitRepo, capsys: pytest.CaptureFixture[str]) -> None:
    """run: def, 10 assignments, if, 2 returns: λ 14, v_g 2. Adding check (4 statements, one
    if: v_g 2) gives Γ' = 4 · 18/14, ΔVg' = 2 · 4/2, E = 1.2857; adding a trivial noop too
    (2 statements, v_g 1) gives Γ' = 6 · 20/14, ΔVg' = 3 · 5/2, E = 1.1429: lower, for a
    larger change."""
    ten = "".join(f"    v{i} = x\n" for i in range(10))
    base = RUN.replace("def run(x):\n", "def run(x):\n" + ten)
    check = "\n\ndef check(y):\n    if y > 1:\n        return y\n    return 1\n"
    noop = "\n\ndef noop():\n    return None\n"
    repo.commit("v1", tag="v1", files={"app.py": base})
    repo.commit("v2", tag="v2", files={"app.py": base + check})
    first = _total(repo, capsys, status=0)
    assert first["scaled_changes"] == pytest.approx(4 * 18 / 14)
    assert first["scaled_delta_vg"] == pytest.approx(4.0)
    assert first["cost"] == pytest.approx(4 * 18 / 14 / 4)  # 1.2857
    repo.git("tag", "-d", "v2")
    repo.commit("v2 with a trivial function", tag="v2", files={"app.py": base + check + noop})
    second = _total(repo, capsys, status=0)
    assert second["scaled_changes"] == pytest.approx(6 * 20 / 14)
    assert second["scaled_delta_vg"] == pytest.approx(3 * 5 / 2)
    assert second["cost"] == pytest.approx(6 * 20 / 14 / 7.5)  # 1.1429
    assert second["cost"] < first["cost"] and second["changes"] > first["changes"]
