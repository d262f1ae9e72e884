"""``replicate``: the thesis's study on the bundled subjects, with findings and charts."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from archmetrics.cli.common import EXIT_OK, UsageError, facts_cache, shown_progress
from archmetrics.config import Settings
from archmetrics.reports.formats import OutputFormat
from archmetrics.study.report import StudyReport


def replicate_command(args: argparse.Namespace) -> int:
    from archmetrics.app.replicate import ReplicateRequest, run_replicate, subjects_root
    from archmetrics.study.report import render_json, render_markdown

    request = ReplicateRequest(subjects_root(), tuple(args.subject), args.jobs, args.keep_repos)
    shown = shown_progress(OutputFormat.TABLE, args.quiet)
    with facts_cache(args, Settings()) as cache, shown as progress:
        report = run_replicate(request, progress, cache)
    out: Path = args.out
    charts: dict[str, list[str]] = {}
    try:
        out.mkdir(parents=True, exist_ok=True)
        if not args.no_charts:
            charts = write_charts(report, out / "charts")
        (out / "report.json").write_text(render_json(report), encoding="utf-8")
        (out / "report.md").write_text(render_markdown(report, charts), encoding="utf-8")
    except OSError as error:
        raise UsageError(f"{out}: cannot write the report: {error.strerror}") from error
    sys.stdout.write(findings_summary(report, out))
    return EXIT_OK


def write_charts(report: StudyReport, folder: Path) -> dict[str, list[str]]:
    """Every chart of every subject as PNG and SVG; the PNG names per subject, for report.md."""
    from archmetrics.reports.charts import render_all

    folder.mkdir(parents=True, exist_ok=True)
    written: dict[str, list[str]] = {}
    for result in report.subjects:
        for fmt in ("png", "svg"):
            for stem, data in render_all(result.compare, fmt).items():
                name = f"{result.subject}-{stem}.{fmt}"
                (folder / name).write_bytes(data)
                if fmt == "png":
                    written.setdefault(result.subject, []).append(name)
    return written


def findings_summary(report: StudyReport, out: Path) -> str:
    from archmetrics.reports.table_report import rows_table, to_text
    from archmetrics.study.report import FINDINGS_HEADER, findings_rows

    rows = findings_rows(report)
    table = rows_table("the thesis's findings against our measurements", FINDINGS_HEADER, rows, 5)
    agree = sum(o.verdict.agrees is True for o in report.outcomes)
    return (
        to_text(table)
        + f"{agree} of {len(report.outcomes)} findings agree. "
        + f"Report: {out / 'report.md'}, {out / 'report.json'}, charts in {out / 'charts'}\n"
    )
