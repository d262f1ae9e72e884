"""A history in every format: the terminal table, Markdown, CSV and JSON (``archmetrics
.history/1``, docs/json.md). Each shows the same rows (reports/history_rows.py)."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Any

from archmetrics import __version__
from archmetrics.reports import history_rows as rows
from archmetrics.reports.frames import Table, history_table
from archmetrics.reports.json_report import dumps, gate_values
from archmetrics.reports.model import HISTORY_SCHEMA, LOCATION_COLUMNS, HistoryReport


class HistoryFormat(StrEnum):
    TABLE = "table"
    JSON = "json"
    MARKDOWN = "markdown"
    CSV = "csv"


@dataclass(frozen=True, slots=True)
class View:
    """What a history report shows besides its commits: the ``top`` costliest commits and
    hotspot elements, and one ``element``'s own trend."""

    top: int = 10
    element: str | None = None


def _headline(report: HistoryReport) -> str:
    failed = len(report.failures)
    gates = ", all gates hold" if report.gates else ""
    if failed:
        gates = f", {failed} gate failure(s)"
    return (
        f"{len(report.entries)} commits of {report.range} ({report.measured} measured now,"
        f" {report.parsed} file versions parsed){gates}"
    )


def history_dict(report: HistoryReport, view: View) -> dict[str, Any]:
    commits: list[dict[str, Any]] = []
    for entry in report.entries:
        failed = {f.gate.text for f in entry.failures}
        commits.append({
            "commit": entry.commit,
            "parent": entry.parent,
            "date": rows.date(entry),
            "subject": entry.subject,
            "merge": entry.merge,
            "locations": {k: entry.step.summaries[k].to_dict() for k in LOCATION_COLUMNS},
            "elements": [e.to_dict() for e in entry.step.elements],
            "gates": [
                {"gate": g, "failed": g in failed, "values": gate_values(g, entry.step.summaries)}
                for g in report.gates
            ],
        })  # fmt: skip
    document: dict[str, Any] = {
        "schema": HISTORY_SCHEMA,
        "tool": {"name": "archmetrics", "version": __version__},
        "repo": report.repo,
        "range": report.range,
        "measured": report.measured,
        "parsed": report.parsed,
        "commits": commits,
        "top": [e.commit for e in rows.costliest(report, view.top)],
        "hotspots": [
            {"element": h.element, "location": h.location, "commits": h.commits,
             "scaled_changes": h.scaled_changes, "scaled_delta_vg": h.scaled_delta_vg,
             "cost": h.cost}
            for h in rows.hotspots(report)
        ],
    }
    if view.element is not None:
        document["element"] = view.element
    return document


def render_json(report: HistoryReport, view: View) -> str:
    return dumps(history_dict(report, view))


def render_csv(report: HistoryReport, view: View) -> str:
    from archmetrics.reports.csv_report import write_csv

    table: Table = history_table(report)
    text: str = write_csv(table)
    return text


def plain_table(title: str, header: tuple[str, ...], cells: list[list[str]], width: int) -> str:
    """A table as aligned text, one line a row, the subject (third column) cut to fit
    ``width``: a history's thousands of commits, like ``git log --oneline`` (rich lays out
    5,000 rows in 10 s)."""
    widths = [max([len(h), *(len(r[i]) for r in cells)]) for i, h in enumerate(header)]
    fixed = sum(w for i, w in enumerate(widths) if i != 2) + 2 * (len(header) - 1)
    widths[2] = max(len(header[2]), min(widths[2], width - fixed))

    def line(row: list[str] | tuple[str, ...]) -> str:
        parts = []
        for i, (cell, size) in enumerate(zip(row, widths, strict=True)):
            if i == 2:
                cell = cell if len(cell) <= size else cell[: max(0, size - 1)] + "…"
                parts.append(cell.ljust(size))
            else:
                parts.append(cell.rjust(size) if i > 2 else cell.ljust(size))
        return "  ".join(parts).rstrip()

    rule = "  ".join("-" * w for w in widths)
    return "\n".join([title, line(header), rule, *(line(r) for r in cells)]) + "\n"


def render_table(report: HistoryReport, view: View) -> str:
    from archmetrics.reports.table_report import rows_table, terminal_width, to_text

    listing = plain_table(_headline(report), rows.COMMIT_HEADER,
                          rows.commit_rows(report.entries), terminal_width())  # fmt: skip
    parts: list[object] = []
    top = rows.costliest(report, view.top)
    if top:
        title = f"the {len(top)} costliest commits (highest E; read E with Γ')"
        parts.append(rows_table(title, rows.COMMIT_HEADER, rows.commit_rows(top), 3))
    spots = rows.hotspots(report, view.top)
    if spots:
        title = "integration-cost hotspots (elements by ΣΓ')"
        parts.append(rows_table(title, rows.HOTSPOT_HEADER, rows.hotspot_rows(spots), 2))
    if view.element is not None:
        trend = rows.trend_rows(report, view.element)
        parts.append(rows_table(f"{view.element}: its own trend", rows.TREND_HEADER, trend, 3))
    lines = [f"{e.commit[:12]} {f}" for e in report.entries for f in e.failures]
    tables = to_text(*parts) if parts else ""
    return listing + "\n" + tables + "".join(line + "\n" for line in lines)


def render_markdown(report: HistoryReport, view: View) -> str:
    from archmetrics.reports.markdown_report import table

    parts = [f"## archmetrics history: `{report.range}`\n", _headline(report) + "\n"]
    commits = list(rows.COMMIT_HEADER)
    top = rows.costliest(report, view.top)
    if top:
        parts += ["### Costliest commits (highest E)\n",
                  table(commits, rows.commit_rows(top), "lll" + "r" * 9)]  # fmt: skip
    spots = rows.hotspots(report, view.top)
    if spots:
        parts += ["### Integration-cost hotspots\n",
                  table(list(rows.HOTSPOT_HEADER), rows.hotspot_rows(spots), "llrrrr")]  # fmt: skip
    if view.element is not None:
        trend = rows.trend_rows(report, view.element)
        parts += [f"### `{view.element}`\n",
                  table(list(rows.TREND_HEADER), trend, "lll" + "r" * 7)]  # fmt: skip
    parts += ["### Every commit\n",
              table(commits, rows.commit_rows(report.entries), "lll" + "r" * 9)]  # fmt: skip
    failures = [f"- `{e.commit[:12]}` {f}" for e in report.entries for f in e.failures]
    return "\n".join(parts + failures) + "\n"


_RENDER = {
    HistoryFormat.TABLE: render_table,
    HistoryFormat.JSON: render_json,
    HistoryFormat.MARKDOWN: render_markdown,
    HistoryFormat.CSV: render_csv,
}
assert set(_RENDER) == set(HistoryFormat), "every history format needs a renderer"


def render_history(report: HistoryReport, fmt: HistoryFormat, view: View) -> str:
    from archmetrics.reports.printable import printable

    text = _RENDER[fmt](report, view)
    return text if fmt is HistoryFormat.JSON else printable(text)
