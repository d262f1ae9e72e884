"""Reports list at most a screenful of warnings and count the rest (JSON keeps them all)."""

from __future__ import annotations

import json

from archmetrics.reports.printable import SHOWN_WARNINGS
from tests.gitrepo import GitRepo
from tests.untrusted import run_cli

# a member tree-sitter cannot read (a macro-made member missing its `;`): one region lost
LOSSY = """template <typename T> class A {
  int f(int a) { if (a) return 1; return 2; }
  int g(int a) { MACRO(int, x) while (a) a--; return h(a); }
};
"""


def test_a_scan_lists_twenty_warnings_and_counts_the_rest(repo: GitRepo) -> None:
    files = {f"src/members_{i:02}.cc": LOSSY for i in range(SHOWN_WARNINGS + 5)}
    repo.commit("v1", files=files)
    every = json.loads(run_cli(["scan", ".", "--no-cache", "--format", "json"], repo.root).out)
    warnings = [w for f in every["files"] for w in f["warnings"]]
    assert len(warnings) == SHOWN_WARNINGS + 5
    assert all("not counted" in w["message"] for w in warnings)
    for form in ("table", "markdown"):
        out = run_cli(["scan", ".", "--no-cache", "--format", form], repo.root).out
        assert out.count("not counted") == SHOWN_WARNINGS
        # the summary line: every file warned, no function estimated
        assert "read with warnings: 25 of 25 files (100.0%); v_g estimated from tokens:" in out
        assert "... and 5 more warnings in 5 files (--format json lists them all)" in out
