"""docs/study.md shows what `replicate` measures now: every region between
``<!-- generated:NAME -->`` markers equals what docs/study_tables.py writes from a fresh run of
the bundled study (the tables and verdicts must never be edited by hand or left stale)."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path
from types import ModuleType

from archmetrics.app.replicate import ReplicateRequest, run_replicate, subjects_root

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "study.md"
REGION = re.compile(r"<!-- generated:([\w-]+) -->\n(.*?)\n<!-- /generated:\1 -->", re.S)


def _study_tables() -> ModuleType:
    """docs/study_tables.py, the maintainer's script (not part of the installed package)."""
    spec = importlib.util.spec_from_file_location("study_tables", ROOT / "docs" / "study_tables.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_generated_regions_of_the_study_page_match_a_fresh_run() -> None:
    tables = _study_tables()
    fresh: dict[str, str] = tables.regions(run_replicate(ReplicateRequest(subjects_root())))
    committed = dict(REGION.findall(PAGE.read_text(encoding="utf-8")))
    assert committed.keys() == fresh.keys()
    stale = [name for name in fresh if committed[name] != fresh[name]]
    assert not stale, f"stale in docs/study.md: {stale} (run .venv/bin/python docs/study_tables.py)"
