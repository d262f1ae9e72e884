"""Regenerate the measured tables of docs/study.md from a real run of the bundled study.

Runs ``archmetrics replicate`` in process (the same use case as the CLI) and rewrites every
region of docs/study.md between ``<!-- generated:NAME -->`` and ``<!-- /generated:NAME -->``:
``findings`` (the verdicts on both variants) and one region per variant and subject
(``<variant>-<subject>``: per approach, stage and location).
Numbers in those regions are never edited by hand.

usage: .venv/bin/python docs/study_tables.py [docs/study.md]
"""

from __future__ import annotations

import sys
from pathlib import Path

from archmetrics.app.replicate import ReplicateRequest, run_replicate, subjects_root
from archmetrics.changeset.model import Summary
from archmetrics.reports.model import SeriesReport
from archmetrics.study.causes import load_causes
from archmetrics.study.findings import FINDINGS, INTEGRATION, summary
from archmetrics.study.manifest import VARIANTS
from archmetrics.study.report import StudyReport, cause_text, outcome, verdict_word

LOCATIONS = ("base", "framework", INTEGRATION, "new", "total")
LABEL = {INTEGRATION: "base + framework"}
COLUMNS = (
    "| approach | stage | location | Δs_a | Δs_e | Δd_a | Δd_e | λ_pre | λ_post"
    " | Γ | Γ' | ΔVg | ΔVg' | E |"
)


def _number(value: float | None) -> str:
    if value is None:
        return "n/a"
    return str(value) if isinstance(value, int) else f"{value:.2f}"


def _row(approach: str, stage: str, location: str, s: Summary) -> str:
    cells = (
        s.delta_s_a,
        s.delta_s_e,
        s.delta_d_a,
        s.delta_d_e,
        s.loc_pre,
        s.loc_post,
        s.changes,
        s.scaled_changes,
        s.delta_vg,
        s.scaled_delta_vg,
        s.cost,
    )
    where = LABEL.get(location, location)
    return f"| {approach} | {stage} | {where} | " + " | ".join(map(_number, cells)) + " |"


def subject_table(series: dict[str, SeriesReport]) -> str:
    """Every approach, stage and location of one subject, as measured."""
    lines = [COLUMNS, "|" + " --- |" * 3 + " ---: |" * 11]
    for approach in sorted(series):
        for stage in series[approach].stages:
            for location in LOCATIONS:
                measured = summary(series[approach], stage.label, location)
                lines.append(_row(approach, stage.label, location, measured))
    return "\n".join(lines)


def findings_table(report: StudyReport) -> str:
    """The verdict of every finding on each variant, what was measured and the recorded cause,
    as replicate reports them."""
    causes = load_causes()
    lines = [
        "| finding | variant | verdict | we measured | cause |",
        "| --- | --- | --- | --- | --- |",
    ]
    for finding in FINDINGS:
        for variant in VARIANTS:
            o = outcome(report, variant, finding)
            cells = (
                finding.id,
                variant,
                verdict_word(o.verdict.agrees),
                o.verdict.measured,
                cause_text(o, variant, causes),
            )
            lines.append("| " + " | ".join(c.replace("|", "\\|") for c in cells) + " |")
    return "\n".join(lines)


def regions(report: StudyReport) -> dict[str, str]:
    found = {"findings": findings_table(report)}
    for variant in report.variants:
        for result in variant.subjects:
            name = f"{variant.variant}-{result.subject}"
            found[name] = subject_table(dict(result.compare.series))
    return found


def rewrite(text: str, generated: dict[str, str]) -> str:
    """``text`` with every generated region replaced; a region with no marker is an error."""
    for name, body in generated.items():
        begin, end = f"<!-- generated:{name} -->\n", f"\n<!-- /generated:{name} -->"
        start, stop = text.find(begin), text.find(end)
        if start < 0 or stop < start:
            raise SystemExit(f"docs/study.md has no region for {name!r}")
        text = text[: start + len(begin)] + body + text[stop:]
    return text


def main(argv: list[str]) -> int:
    doc = Path(argv[0]) if argv else Path(__file__).with_name("study.md")
    report = run_replicate(ReplicateRequest(subjects_root()))
    doc.write_text(rewrite(doc.read_text(encoding="utf-8"), regions(report)), encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
