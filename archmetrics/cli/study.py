"""``replicate``: the thesis's study on the bundled subjects, with findings and charts."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from archmetrics.cli.common import EXIT_OK, UsageError, facts_cache, shown_progress
from archmetrics.config import Settings
from archmetrics.reports.charts import charts_missing
from archmetrics.reports.formats import OutputFormat
from archmetrics.study.findings import FINDINGS
from archmetrics.study.report import (
    StudyReport,
    VariantResult,
    agreements,
    outcome,
    verdict_word,
)

if TYPE_CHECKING:
    from archmetrics.study.causes import Cause


def replicate_command(args: argparse.Namespace) -> int:
    from archmetrics.app.replicate import ReplicateRequest, run_replicate, subjects_root
    from archmetrics.study.causes import load_causes
    from archmetrics.study.report import render_json, render_markdown

    missing = None if args.no_charts else charts_missing()
    if missing is not None:  # said before the study runs, not after
        raise UsageError(f"the study's {missing}; or give --no-charts")
    request = ReplicateRequest(subjects_root(), tuple(args.subject), args.jobs, args.keep_repos)
    shown = shown_progress(OutputFormat.TABLE, args.quiet)
    with facts_cache(args, Settings()) as cache, shown as progress:
        report = run_replicate(request, progress, cache)
    causes = load_causes()
    out: Path = args.out
    charts: dict[str, list[str]] = {}
    try:
        out.mkdir(parents=True, exist_ok=True)
        if not args.no_charts:
            charts = write_charts(report, out / "charts")
        (out / "report.json").write_text(render_json(report, causes), encoding="utf-8")
        (out / "report.md").write_text(render_markdown(report, causes, charts), encoding="utf-8")
    except OSError as error:
        raise UsageError(f"{out}: cannot write the report: {error.strerror}") from error
    sys.stdout.write(findings_summary(report, causes, out))
    return EXIT_OK


def write_charts(report: StudyReport, folder: Path) -> dict[str, list[str]]:
    """Every chart of every variant and subject as PNG and SVG, in one folder per variant (the
    ``*_total`` charts over base + framework, the findings' scope); the PNG names per
    "<variant>/<subject>", for report.md."""
    from archmetrics.reports.charts import render_all
    from archmetrics.reports.charts_data import INTEGRATION

    written: dict[str, list[str]] = {}
    for variant in report.variants:
        (folder / variant.variant).mkdir(parents=True, exist_ok=True)
        for result in variant.subjects:
            key = f"{variant.variant}/{result.subject}"
            for fmt in ("png", "svg"):
                # the summary charts over base + framework, where the findings are judged
                for stem, data in render_all(result.compare, fmt, INTEGRATION).items():
                    name = f"{key}-{stem}.{fmt}"
                    (folder / name).write_bytes(data)
                    if fmt == "png":
                        written.setdefault(key, []).append(name)
    return written


def _unmeasured(variant: VariantResult) -> int:
    return sum(o.verdict.agrees is None for o in variant.outcomes)


def findings_summary(
    report: StudyReport, causes: Mapping[tuple[str, str], Cause], out: Path
) -> str:
    """What the terminal shows, at most 100 columns wide: each finding with its two verdicts,
    how many agree, the headline (the cheapest architecture stage by stage) and where the
    full report is (why each verdict differs, the figures and the charts)."""
    from archmetrics.study.headline import headline

    names = [v.variant for v in report.variants]
    lines = ["The thesis's findings (chapter 7) measured on the bundled subjects:", ""]
    lines.append(f"{'finding':20} {'as described':13} {'idiomatic':13} the thesis says")
    for finding in FINDINGS:
        verdicts = [verdict_word(outcome(report, v, finding).verdict.agrees) for v in names]
        claim = _cut(f"{finding.claim} (p. {finding.pages})", WIDTH - 49)
        lines.append(f"{finding.id:20} {verdicts[0]:13} {verdicts[1]:13} {claim}")
    said = "; ".join(
        f"{v.variant} {agreements(report)[v.variant]} of {len(FINDINGS)}"
        + (f" ({missing} not measured)" if (missing := _unmeasured(v)) else "")
        for v in report.variants
    )
    lines += [f"Agree: {said}.", ""]
    lines.append("Cheapest integration by stage: the lowest E = Γ'/ΔVg' (statements changed per")
    lines.append("decision point added) over base + framework, " + " / ".join(names) + ":")
    for row in headline(report):
        cells = " / ".join("n/a" if c is None else str(c) for c in row.cheapest)
        lines.append(f"  {row.subject:11} {row.stage:9} {cells}")
    lines += [
        "",
        f"Full report (why each verdict differs, every figure): {out / 'report.md'}",
        f"and {out / 'report.json'}; charts in {out / 'charts'}",
    ]
    return "\n".join(lines) + "\n"


WIDTH = 100  # the terminal summary's widest line


def _cut(text: str, width: int) -> str:
    """``text`` in at most ``width`` characters, an ellipsis where it was cut."""
    return text if len(text) <= width else text[: width - 1].rstrip() + "…"
