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
from archmetrics.study.report import StudyReport, VariantResult

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
    from rich.markup import escape

    from archmetrics.reports.table_report import rows_table, to_text
    from archmetrics.study.report import FINDINGS_HEADER, agreements, findings_rows

    # the causes name elements in [brackets], which rich would take for markup
    rows = [[escape(cell) for cell in row] for row in findings_rows(report, causes)]
    title = "the thesis's findings on both variants of the subjects"
    table = rows_table(title, FINDINGS_HEADER, rows, 5)
    said = "; ".join(
        f"{v.variant}: {agreements(report)[v.variant]} of {len(FINDINGS)} agree"
        + (f" ({missing} not measured)" if (missing := _unmeasured(v)) else "")
        for v in report.variants
    )
    return (
        to_text(table)
        + f"Findings: {said}. "
        + f"Report: {out / 'report.md'}, {out / 'report.json'}, charts in {out / 'charts'}\n"
    )
