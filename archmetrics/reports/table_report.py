"""The terminal table (rich)."""

from __future__ import annotations

import io
import shutil
import textwrap
from collections.abc import Sequence
from typing import Literal

from rich.console import Console
from rich.table import Table

from archmetrics.complexity.thresholds import ThresholdFailure, worst_first
from archmetrics.reports import coupling_rows, diff_rows, estimate_rows
from archmetrics.reports.glossary import DIFF_LEGEND, ELEMENT_LEGEND, SCAN_LEGEND
from archmetrics.reports.model import (
    LOCATION_COLUMNS,
    CompareReport,
    DiffReport,
    EstimateReport,
    ScanReport,
    SeriesReport,
)
from archmetrics.reports.printable import shown_lines, shown_warnings


def to_text(*renderables: object, color: bool = False, width: int | None = None) -> str:
    """Render rich objects to a string (ANSI colours only when ``color``), as wide as the
    terminal, or 160 columns when there is none. Text is shown as it is: no rich markup
    or emoji code in a name is read as one."""
    width = width or terminal_width()
    out = io.StringIO()
    # names come from the measured repository: rich must not read them as its markup
    # ("[link=...]" is a terminal hyperlink, "[bold]" disappears) or emoji codes
    console = Console(
        file=out, force_terminal=color, width=width, no_color=not color, markup=False,
        emoji=False,
    )  # fmt: skip
    for item in renderables:
        console.print(item)
    return out.getvalue()


def _file_table(report: ScanReport) -> Table:
    t = report.totals
    table = Table(title=f"archmetrics scan: {report.revision}", show_footer=True)
    table.add_column("file", footer=f"total ({t.files} files)", overflow="fold")
    table.add_column("lang")
    table.add_column("λ", justify="right", footer=str(t.loc))
    table.add_column("SLOC", justify="right", footer=str(t.sloc))
    table.add_column("v_g", justify="right", footer=str(t.vg))
    table.add_column("functions", justify="right", footer=str(t.functions))
    for f in report.files:
        name = (
            f.path + ("" if f.parsed else " (not parsed)") + (" (generated)" if f.generated else "")
        )
        table.add_row(name, f.language, str(f.loc), str(f.sloc), str(f.vg), str(len(f.functions)))
    return table


def _function_table(report: ScanReport) -> Table:
    t = report.totals
    table = Table(title=f"archmetrics scan by function: {report.revision}", show_footer=True)
    table.add_column("file", footer="total", overflow="fold")
    table.add_column("function", footer=f"{t.functions} functions", overflow="fold")
    table.add_column("line", justify="right")
    table.add_column(
        "λ", justify="right", footer=str(sum(fn.loc for f in report.files for fn in f.functions))
    )
    table.add_column("v_g", justify="right", footer=str(t.vg))
    for f in report.files:
        for fn in f.functions:
            table.add_row(f.path, fn.qualified_name, str(fn.line), str(fn.loc), str(fn.vg))
    return table


def rows_table(
    title: str,
    header: tuple[str, ...],
    rows: list[list[str]],
    left: int,
    width: int | None = None,
    least_useful: Sequence[str] = (),
) -> Table:
    """A table whose ``left`` first columns name a row and whose others hold numbers, fitted
    to ``width`` (the terminal's): names wrap, never end in ``…``; numbers are never cut;
    when the columns do not fit, the ``least_useful`` ones are left out first, then the
    rightmost, and the caption says which (the JSON and CSV have them all)."""
    width = width or terminal_width()
    need = [max((len(row[i]) for row in rows), default=1) for i in range(len(header))]
    for i in range(left):  # a name shows at least this much of itself before it wraps
        need[i] = min(need[i], _NAME_WIDTH)
    need = [max(n, len(name)) for n, name in zip(need, header, strict=True)]
    order = [header.index(name) for name in least_useful if name in header]
    order += [i for i in reversed(range(left, len(header))) if i not in order]
    kept = set(range(len(header)))
    for i in order:
        if sum(need[k] + 3 for k in kept) + 1 <= width or len(kept) <= 2:
            break
        kept.discard(i)
    columns = sorted(kept)
    table = Table(title=title)
    for i in columns:
        justify: Literal["left", "right"] = "left" if i < left else "right"
        table.add_column(header[i], justify=justify, overflow="fold", min_width=need[i])
    for row in rows:
        table.add_row(*(row[i] for i in columns))
    if len(columns) < len(header):
        dropped = ", ".join(name for i, name in enumerate(header) if i not in kept)
        table.caption = f"{dropped} left out at {width} columns (--format json has them)"
    return table


_NAME_WIDTH = 24  # characters of a row's name shown on one line before it wraps


def legend_lines(legend: str) -> str:
    """``legend: ...`` wrapped to the terminal's width (its lines joined by line breaks)."""
    return textwrap.fill(f"legend: {legend}", terminal_width(), break_on_hyphens=False)


def terminal_width() -> int:
    """The terminal's columns (at least 60), or 160 when there is none."""
    return max(60, shutil.get_terminal_size((160, 24)).columns)


def render_scan(report: ScanReport, grouping: str, color: bool = False) -> str:
    if grouping == "function":
        table = _function_table(report)
    elif grouping == "element":
        rows = coupling_rows.element_rows(report)
        title = f"archmetrics scan by element: {report.revision}"
        table = rows_table(title, coupling_rows.ELEMENT_HEADER, rows, 2, None, ("files",))
    elif grouping == "link":
        rows = coupling_rows.link_rows(report.coupling)
        title = f"archmetrics scan, every link: {report.revision}"
        table = rows_table(title, coupling_rows.LINK_HEADER, rows, 8)
    else:
        table = _file_table(report)
    warnings = shown_warnings([w for f in report.files for w in f.warnings])
    reading = report.totals.reading().line()
    extra = ["", f"warnings ({reading}):", *("  " + w for w in warnings)] if warnings else []
    extra += [f"excluded {x.path}: {x.reason}" for x in report.excluded]
    extra += [f"note: {note}" for note in report.notes]
    legend = SCAN_LEGEND + (" " + ELEMENT_LEGEND if grouping == "element" else "")
    extra += [legend_lines(legend), *gate_lines(report)]
    return to_text(table, color=color) + "\n".join(extra) + ("\n" if extra else "")


SHOWN_FAILURES = 50  # failed units listed in a table, Markdown or on stderr; JSON lists all


def gate_lines(report: ScanReport | DiffReport) -> list[str]:
    """The failed thresholds (a diff: its touched units over a unit gate), one line per
    failing unit, worst first, at most ``SHOWN_FAILURES``; then the units a suppression
    comment exempts (every one: nothing hides silently) and those the baseline knows."""
    failures = report.failures if isinstance(report, ScanReport) else report.offenders
    more = "... and {count} more failing units (--format json lists them all)"
    lines = shown_lines(worst_first(failures), SHOWN_FAILURES, more)
    lines += [f"suppressed by a comment: {_excused(f)}" for f in worst_first(report.suppressed)]
    if report.baselined:
        known = worst_first(report.baselined)
        lines.append(f"{len(known)} offenders the baseline knows, none worse (not failing):")
        more = "  ... and {count} more (--format json lists them all)"
        lines += [f"  {_excused(f)}" for f in known[:SHOWN_FAILURES]]
        lines += [more.format(count=len(known) - SHOWN_FAILURES)] * (len(known) > SHOWN_FAILURES)
    return lines


def _excused(failure: ThresholdFailure) -> str:
    return str(failure).removeprefix("gate failed: ")


def render_diff(report: DiffReport, color: bool = False) -> str:
    """The per-location summary (thesis appendix tables C-I), then the per-element detail."""
    summary = Table(title=f"archmetrics diff: {report.base} → {report.head}")
    summary.add_column("metric")
    summary.add_column("eq.", style="dim")
    for column in LOCATION_COLUMNS:
        summary.add_column(column, justify="right")
    for row in diff_rows.summary_rows(report):
        summary.add_row(*row)
    changed = [
        diff_rows.element_row(e) for e in diff_rows.most_changed_first(report.change.changed())
    ]
    least_useful = ("d_e", "d_a", "s_e", "s_a", "location", "λ pre", "v_g pre")
    title = "changed elements, the most changed first"
    detail = rows_table(title, diff_rows.ELEMENT_HEADER, changed, 3, None, least_useful)
    linked = diff_rows.link_rows(report.change.changed())
    tables = [summary, detail]
    if linked:
        tables.append(rows_table("links added and removed", diff_rows.LINK_HEADER, linked, 1))
    unchanged = report.change.unchanged_count()
    lines = [f"{unchanged} unchanged elements not shown (see --format json)"] if unchanged else []
    lines.append(legend_lines(DIFF_LEGEND))
    lines += [f"note {n}" for n in diff_rows.notes(report)]
    lines += [f"excluded {x.path}: {x.reason}" for x in report.change.excluded]
    lines += [f"warning {w}" for w in shown_warnings(report.warnings)]
    lines += [f"warning: {diff_rows.unmatched_glob(g)}" for g in report.change.unmatched]
    lines += diff_rows.unparsed_line(report)
    if report.reading is not None and report.warnings:
        lines.append(report.reading.line())
    lines += [str(f) for f in report.failures]
    lines += gate_lines(report)
    lines.append(f"verdict: {diff_rows.verdict(report)}")
    return to_text(*tables, color=color) + "".join(line + "\n" for line in lines)


def render_series(report: SeriesReport, color: bool = False) -> str:
    """One diff per stage, then the per-location summary across stages."""
    parts = [f"== stage {s.label} ==\n" + render_diff(s.report, color) for s in report.stages]
    rows = diff_rows.trend_rows(report)
    header = diff_rows.TREND_HEADER[1:]
    trend = rows_table("per location, across stages", header, [r[1:] for r in rows], 2)
    return "\n".join(parts) + "\n" + to_text(trend, color=color)


def render_compare(report: CompareReport, color: bool = False) -> str:
    rows = diff_rows.compare_rows(report)
    names = ", ".join(name for name, _ in report.series)
    table = rows_table(f"compared: {names}", diff_rows.TREND_HEADER, rows, 3)
    return to_text(table, color=color)


def render_estimate(report: EstimateReport, color: bool = False) -> str:
    """Per stage: the per-location figures, one column group per architecture, and each
    architecture's changed elements; then the ranking. Every title says it is an estimate."""
    parts: list[object] = []
    for label in report.stage_labels():
        header = estimate_rows.summary_header(report, label)
        title = f"archmetrics estimate ({estimate_rows.LABEL}): {report.plan} on {report.base}"
        stage = "" if label == "estimate" else f", stage {label}"
        # on a narrow terminal the totals stay longest: framework, base, then new go first
        least_useful = [
            h for where in (" framework", " base", " new") for h in header if h.endswith(where)
        ]
        rows = estimate_rows.summary_rows(report, label)
        parts.append(rows_table(title + stage, tuple(header), rows, 2, None, least_useful))
        element_header = ("architecture", *diff_rows.ELEMENT_HEADER)
        rows = estimate_rows.element_rows(report, label)
        if rows:
            parts.append(rows_table("changed elements", element_header, rows, 4))
    ranking = estimate_rows.ranking_rows(report)
    parts.append(
        rows_table("ranking: cheapest total E first", estimate_rows.RANKING_HEADER, ranking, 3)
    )
    parts += accuracy_parts(report)
    lines = [
        f"note {n}" for label in report.stage_labels() for n in estimate_rows.notes(report, label)
    ]
    lines += [str(f) for f in report.failures]
    return to_text(*parts, color=color) + "".join(line + "\n" for line in lines)


def accuracy_parts(report: EstimateReport) -> list[object]:
    """--actual: each architecture's figures against the measured change."""
    if report.actual is None:
        return []
    title = (
        f"accuracy: the estimate against the measured {report.actual.base} → {report.actual.head}"
    )
    rows = estimate_rows.accuracy_rows(report)
    parts: list[object] = [rows_table(title, estimate_rows.ACCURACY_HEADER, rows, 3)]
    elements = estimate_rows.element_accuracy_rows(report)
    if elements:
        title = "elements: the figures the estimate got wrong"
        parts.append(rows_table(title, estimate_rows.ELEMENT_ACCURACY_HEADER, elements, 4))
    return parts
