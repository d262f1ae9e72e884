"""Markdown: tables that read well in a pull request or a wiki page."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from archmetrics.reports.model import ScanReport


def escape(cell: object) -> str:
    return str(cell).replace("|", "\\|").replace("\n", " ")


def table(header: Sequence[str], rows: Iterable[Sequence[object]], align: str = "") -> str:
    """A Markdown table; ``align`` has one letter per column, l or r (default: l)."""
    align = align or "l" * len(header)
    marks = ["---:" if a == "r" else "---" for a in align]
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join(marks) + " |"]
    lines += ["| " + " | ".join(escape(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def render_scan(report: ScanReport, by_function: bool) -> str:
    t = report.totals
    parts = [
        f"## archmetrics scan: `{report.revision}`\n",
        f"{t.files} files, {t.functions} functions: λ = {t.loc}, SLOC = {t.sloc}, "
        f"v_g = {t.vg}\n",
    ]
    if by_function:
        rows = [
            (f"`{file.path}`", f"`{f.qualified_name}`", f.line, f.loc, f.vg)
            for file in report.files
            for f in file.functions
        ]
        parts.append(table(["file", "function", "line", "λ", "v_g"], rows, "llrrr"))
    else:
        rows2 = [
            (f"`{f.path}`", f.language, f.loc, f.sloc, f.vg, len(f.functions))
            for f in report.files
        ]
        rows2.append(("**total**", "", t.loc, t.sloc, t.vg, t.functions))
        parts.append(table(["file", "language", "λ", "SLOC", "v_g", "functions"], rows2, "llrrrr"))
    warnings = [w for f in report.files for w in f.warnings]
    if warnings:
        parts.append("\n**Warnings**\n\n" + "".join(f"- `{w}`\n" for w in warnings))
    return "\n".join(parts)
