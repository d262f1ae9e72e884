"""The ``estimate`` command: an integration plan priced against a measured base (p. 109)."""

from __future__ import annotations

import argparse
from pathlib import Path

from archmetrics.cli.common import UsageError, emit, facts_cache, gate_status, shown_progress
from archmetrics.cli.measure import check_chart, diff_request, write_chart
from archmetrics.reports.formats import OutputFormat, render_estimate
from archmetrics.reports.model import CompareReport
from archmetrics.sources.checkout import open_checkout


def estimate_command(args: argparse.Namespace) -> int:
    from archmetrics.app.estimate import EstimateRequest, run_estimate  # only when asked

    check_chart(args)
    fmt = OutputFormat(args.format)
    if not args.actual and (args.head is not None or args.stage is not None):
        raise UsageError("--head and --stage go with --actual")
    if args.actual and args.head is None:
        raise UsageError("--actual needs --head: the revision the integration was done in")
    checkout = open_checkout(args.repo)
    request = EstimateRequest(
        Path(args.plan),
        diff_request(args, checkout, args.base, "", config_head=args.head if args.actual else None),
        args.head if args.actual else None,
        args.stage,
        tuple(args.architecture),
    )
    with facts_cache(args, request.diff.settings) as cache, shown_progress(fmt, args.quiet) as p:
        report = run_estimate(request, p, cache, checkout)
        p.phase("writing the report")
        text = render_estimate(report, fmt)
    emit(text, args.output)
    # the chart says it is an estimate, as every report does: each series is named so
    estimated = tuple((f"{name} (estimate)", series) for name, series in report.compare().series)
    write_chart(args, CompareReport(estimated))
    return gate_status(report.failures, args)
