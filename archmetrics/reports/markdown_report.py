"""Markdown: tables that read well in a pull request or a wiki page."""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from archmetrics.reports import coupling_rows, diff_rows
from archmetrics.reports.model import (
    LOCATION_COLUMNS,
    CompareReport,
    DiffReport,
    ScanReport,
    SeriesReport,
)
from archmetrics.reports.printable import shown_warnings


def escape(cell: object) -> str:
    return str(cell).replace("|", "\\|").replace("\n", " ")


def table(header: Sequence[str], rows: Iterable[Sequence[object]], align: str = "") -> str:
    """A Markdown table; ``align`` has one letter per column, l or r (default: l)."""
    align = align or "l" * len(header)
    marks = ["---:" if a == "r" else "---" for a in align]
    lines = ["| " + " | ".join(header) + " |", "| " + " | ".join(marks) + " |"]
    lines += ["| " + " | ".join(escape(c) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def _scan_table(report: ScanReport, grouping: str) -> str:
    t = report.totals
    if grouping == "function":
        rows = [
            (f"`{file.path}`", f"`{f.qualified_name}`", f.line, f.loc, f.vg)
            for file in report.files
            for f in file.functions
        ]
        return table(["file", "function", "line", "λ", "v_g"], rows, "llrrr")
    if grouping == "element":
        header = list(coupling_rows.ELEMENT_HEADER)
        return table(header, coupling_rows.element_rows(report), "ll" + "r" * 7)
    if grouping == "link":
        return table(list(coupling_rows.LINK_HEADER), coupling_rows.link_rows(report.coupling))
    files: list[tuple[object, ...]] = [
        (f"`{f.path}`", f.language, f.loc, f.sloc, f.vg, len(f.functions)) for f in report.files
    ]
    files.append(("**total**", "", t.loc, t.sloc, t.vg, t.functions))
    return table(["file", "language", "λ", "SLOC", "v_g", "functions"], files, "llrrrr")


def render_scan(report: ScanReport, grouping: str) -> str:
    t = report.totals
    parts = [
        f"## archmetrics scan: `{report.revision}`\n",
        f"{t.files} files, {t.functions} functions: λ = {t.loc}, SLOC = {t.sloc}, v_g = {t.vg}\n",
        _scan_table(report, grouping),
    ]
    warnings = shown_warnings([w for f in report.files for w in f.warnings])
    if warnings:
        parts.append("\n**Warnings**\n\n" + "".join(f"- `{w}`\n" for w in warnings))
    if report.excluded:
        parts.append("".join(f"- excluded `{x.path}`: {x.reason}\n" for x in report.excluded))
    return "\n".join(parts)


def render_diff(report: DiffReport) -> str:
    """A pull-request comment: verdict line, summary table, changed elements, notes."""
    total = report.change.total
    verdict = (
        f"**{len(report.failures)} gate(s) failed**"
        if report.failures
        else ("all gates hold" if report.gates else "no gates configured")
    )
    parts = [
        f"## archmetrics: `{report.base}` → `{report.head}`\n",
        f"Γ = {total.changes} changed statements, ΔVg = {total.delta_vg}, "
        f"E = {diff_rows.number(total.cost)} · {verdict}\n",
        table(["metric", "eq.", *LOCATION_COLUMNS], diff_rows.summary_rows(report), "llrrrr"),
    ]
    changed = [e for e in report.change.elements if e.status.value != "unchanged"]
    if changed:
        rows = [diff_rows.element_row(e) for e in changed]
        parts.append(f"<details><summary>{len(changed)} changed elements</summary>\n")
        parts.append(table(list(diff_rows.ELEMENT_HEADER), rows, "lll" + "r" * 11))
        parts.append("</details>\n")
    bullets = [f"- {f}" for f in report.failures]
    bullets += [f"- note {n}" for n in diff_rows.notes(report)]
    bullets += [f"- excluded `{x.path}`: {x.reason}" for x in report.change.excluded]
    bullets += [f"- warning `{w}`" for w in shown_warnings(report.warnings)]
    if bullets:
        parts.append("\n".join(bullets) + "\n")
    return "\n".join(parts)


def render_series(report: SeriesReport) -> str:
    parts = [
        render_diff(s.report).replace("## archmetrics:", f"## stage {s.label}:", 1)
        for s in report.stages
    ]
    rows = [r[1:] for r in diff_rows.trend_rows(report)]
    parts.append("## Per location, across stages\n")
    parts.append(table(list(diff_rows.TREND_HEADER[1:]), rows, "ll" + "r" * 10))
    return "\n".join(parts)


def render_compare(report: CompareReport) -> str:
    names = ", ".join(f"`{name}`" for name, _ in report.series)
    return f"## Compared: {names}\n\n" + table(
        list(diff_rows.TREND_HEADER), diff_rows.compare_rows(report), "lll" + "r" * 10
    )
