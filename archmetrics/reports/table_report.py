"""The terminal table (rich)."""

from __future__ import annotations

import io

from rich.console import Console
from rich.table import Table

from archmetrics.reports.model import ScanReport


def to_text(*renderables: object, color: bool = False, width: int = 120) -> str:
    """Render rich objects to a string (ANSI colours only when ``color``)."""
    out = io.StringIO()
    console = Console(file=out, force_terminal=color, width=width, no_color=not color)
    for item in renderables:
        console.print(item)
    return out.getvalue()


def _file_table(report: ScanReport) -> Table:
    t = report.totals
    table = Table(title=f"archmetrics scan: {report.revision}", show_footer=True)
    table.add_column("file", footer=f"total ({t.files} files)")
    table.add_column("lang")
    table.add_column("λ", justify="right", footer=str(t.loc))
    table.add_column("SLOC", justify="right", footer=str(t.sloc))
    table.add_column("v_g", justify="right", footer=str(t.vg))
    table.add_column("functions", justify="right", footer=str(t.functions))
    for f in report.files:
        name = f.path + ("" if f.parsed else " (not parsed)") + (" (generated)" if f.generated else "")
        table.add_row(name, f.language, str(f.loc), str(f.sloc), str(f.vg), str(len(f.functions)))
    return table


def _function_table(report: ScanReport) -> Table:
    t = report.totals
    table = Table(title=f"archmetrics scan by function: {report.revision}", show_footer=True)
    table.add_column("file", footer="total")
    table.add_column("function", footer=f"{t.functions} functions")
    table.add_column("line", justify="right")
    table.add_column("λ", justify="right", footer=str(sum(
        fn.loc for f in report.files for fn in f.functions)))
    table.add_column("v_g", justify="right", footer=str(t.vg))
    for f in report.files:
        for fn in f.functions:
            table.add_row(f.path, fn.qualified_name, str(fn.line), str(fn.loc), str(fn.vg))
    return table


def render_scan(report: ScanReport, by_function: bool, color: bool = False) -> str:
    table = _function_table(report) if by_function else _file_table(report)
    warnings = [str(w) for f in report.files for w in f.warnings]
    extra = ["", "warnings:", *("  " + w for w in warnings)] if warnings else []
    return to_text(table, color=color) + "\n".join(extra) + ("\n" if extra else "")
