"""CSV: one row per file or per function, for spreadsheets and pandas."""

from __future__ import annotations

import csv
import io

from archmetrics.reports.model import ScanReport


def render_scan(report: ScanReport, by_function: bool) -> str:
    out = io.StringIO()
    writer = csv.writer(out, lineterminator="\n")
    if by_function:
        writer.writerow(["path", "language", "function", "line", "loc", "vg"])
        for file in report.files:
            for f in file.functions:
                writer.writerow([file.path, file.language, f.qualified_name, f.line, f.loc, f.vg])
    else:
        writer.writerow(["path", "language", "loc", "sloc", "vg", "functions", "warnings"])
        for file in report.files:
            writer.writerow(
                [file.path, file.language, file.loc, file.sloc, file.vg,
                 len(file.functions), len(file.warnings)]
            )
    return out.getvalue()
