"""Markdown: tables that read well in a pull request or a wiki page.

Every text the measured repository decides (file, element and function names, endpoints,
tags, warnings, notes, excluded files' reasons, gates from its configuration, a plan's
names) is written as a code span (:func:`archmetrics.markup.code_span`), where Markdown
reads no HTML, link or emphasis; only this module's own words and numbers are plain.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from archmetrics.changeset.model import ElementChange, ExcludedFile
from archmetrics.markup import code_span as code
from archmetrics.markup import table_cell
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
from archmetrics.reports.printable import shown_warnings
from archmetrics.reports.table_report import gate_lines


def table(header: Sequence[str], rows: Iterable[Sequence[object]], align: str = "") -> str:
    """A Markdown table; ``align`` has one letter per column, l or r (default: l)."""
    align = align or "l" * len(header)
    marks = ["---:" if a == "r" else "---" for a in align]
    head = "| " + " | ".join(table_cell(str(c)) for c in header) + " |"
    lines = [head, "| " + " | ".join(marks) + " |"]
    lines += ["| " + " | ".join(table_cell(str(c)) for c in row) + " |" for row in rows]
    return "\n".join(lines) + "\n"


def _scan_table(report: ScanReport, grouping: str) -> str:
    t = report.totals
    if grouping == "function":
        rows = [
            (code(file.path), code(f.qualified_name), f.line, f.loc, f.vg)
            for file in report.files
            for f in file.functions
        ]
        return table(["file", "function", "line", "λ", "v_g"], rows, "llrrr")
    if grouping == "element":
        header = list(coupling_rows.ELEMENT_HEADER)
        elements = _coded(coupling_rows.element_rows(report), 0, 1)
        return table(header, elements, "ll" + "r" * 7)
    if grouping == "link":
        links = _coded(coupling_rows.link_rows(report.coupling), 0, 1, 3, 6)
        return table(list(coupling_rows.LINK_HEADER), links)
    files: list[tuple[object, ...]] = [
        (code(f.path), f.language, f.loc, f.sloc, f.vg, len(f.functions)) for f in report.files
    ]
    files.append(("**total**", "", t.loc, t.sloc, t.vg, t.functions))
    return table(["file", "language", "λ", "SLOC", "v_g", "functions"], files, "llrrrr")


def _coded(rows: Iterable[Sequence[str]], *columns: int) -> list[list[str]]:
    """``rows`` with the cells of ``columns`` (the repository's text) as code spans."""
    return [[code(c) if i in columns else c for i, c in enumerate(row)] for row in rows]


def _bullets(lines: Iterable[object], prefix: str = "") -> list[str]:
    """One list item per line of the repository's text, each a code span."""
    return [f"- {prefix}{code(line)}" for line in lines]


def render_scan(report: ScanReport, grouping: str) -> str:
    t = report.totals
    parts = [
        f"## archmetrics scan: {code(report.revision)}\n",
        f"{t.files} files, {t.functions} functions: λ = {t.loc}, SLOC = {t.sloc}, v_g = {t.vg}\n",
        _scan_table(report, grouping),
        f"<sub>{SCAN_LEGEND}{' ' + ELEMENT_LEGEND if grouping == 'element' else ''}</sub>\n",
    ]
    warnings = shown_warnings([w for f in report.files for w in f.warnings])
    if warnings:
        parts.append(
            f"\n**Warnings**: {t.reading().line()}\n\n"
            + "".join(f"{w}\n" for w in _bullets(warnings))
        )
    if report.excluded:
        parts.append("".join(f"{line}\n" for line in _excluded(report.excluded)))
    parts += [f"*Note: {table_cell(str(note))}*\n" for note in report.notes]
    if report.gates:
        verdict = f"**{len(report.failures)} failing unit(s)**" if report.failures else "all hold"
        lines = "".join(f"{line}\n" for line in _bullets(gate_lines(report)))
        gates = ", ".join(code(gate) for gate in report.gates)
        parts.append(f"\n**Gates** ({gates}): {verdict}\n\n{lines}")
    return "\n".join(parts)


COMMENT_LIMIT = 65_536  # characters GitHub takes in one pull-request comment
_ROOM = 1_000  # for the lines that say what was left out
_SHOWN_EXCLUDED = 20


def _elements(changed: list[ElementChange], budget: int, max_rows: int | None) -> list[str]:
    """The changed elements' table, worst first: at most ``max_rows`` rows (0: all), or by
    default as many as fit in ``budget`` characters, and a line saying what was left out."""
    rows = _coded((diff_rows.element_row(e) for e in diff_rows.most_changed_first(changed)), 0)
    header, align = list(diff_rows.ELEMENT_HEADER), "lll" + "r" * 11
    if max_rows:
        shown = rows[:max_rows]
    elif max_rows == 0:
        shown = rows
    else:  # the most rows whose table fits (a table grows with its rows)
        low, high = 0, len(rows)
        while low < high:
            middle = (low + high + 1) // 2
            if len(table(header, rows[:middle], align)) <= budget:
                low = middle
            else:
                high = middle - 1
        shown = rows[:low]
    parts = [f"<details><summary>{len(changed)} changed elements</summary>\n"]
    parts.append(table(header, shown, align))
    if len(shown) < len(rows):
        parts.append(
            f"{len(rows) - len(shown)} more changed elements not shown (the most changed are"
            " above; `--max-rows 0` shows them all, `--format json` has every element)\n"
        )
    parts.append("</details>\n")
    return parts


def render_diff(report: DiffReport, max_rows: int | None = None) -> str:
    """A pull-request comment: verdict line, summary table, changed elements (worst first),
    notes. By default the comment fits GitHub's limit (``COMMENT_LIMIT``): the elements that
    do not fit are counted, not shown; ``max_rows``: at most that many (0: every one)."""
    line = diff_rows.verdict(report)
    if report.failed:
        head, _, said = line.rpartition(": ")
        line = f"{head}: **{said}**"
    parts = [
        f"## archmetrics: {code(report.base)} → {code(report.head)}\n",
        line + "\n",
        table(["metric", "eq.", *LOCATION_COLUMNS], diff_rows.summary_rows(report), "llrrrr"),
        f"<sub>{DIFF_LEGEND}</sub>\n",
    ]
    bullets = _bullets(report.failures)
    bullets += _bullets(gate_lines(report))
    bullets += [f"- **{line}**" for line in diff_rows.unparsed_line(report)]
    bullets += _bullets(diff_rows.notes(report), "note ")
    excluded = report.change.excluded
    bullets += _excluded(excluded[:_SHOWN_EXCLUDED])
    if len(excluded) > _SHOWN_EXCLUDED:
        more = len(excluded) - _SHOWN_EXCLUDED
        bullets.append(f"- ... and {more} more excluded files (`--format json` lists them all)")
    bullets += _bullets(shown_warnings(report.warnings), "warning ")
    bullets += _bullets((diff_rows.unmatched_glob(g) for g in report.change.unmatched), "warning: ")
    if report.reading is not None and report.warnings:
        bullets.append(f"- {report.reading.line()}")
    tail = ["\n".join(bullets) + "\n"] if bullets else []
    changed = report.change.changed()
    if changed:
        links = _links(changed)
        budget = COMMENT_LIMIT - _ROOM - len("\n".join(parts + tail + links))
        parts += _elements(changed, budget, max_rows)
        if len("\n".join(parts + links + tail)) <= COMMENT_LIMIT - _ROOM:
            parts += links
    return "\n".join(parts + tail)


def _links(changed: list[ElementChange]) -> list[str]:
    """The link sites each changed element gains and loses (+/-), by role and endpoint."""
    rows = diff_rows.link_rows(changed)
    if not rows:
        return []
    return [
        f"<details><summary>{len(rows)} link changes</summary>\n",
        table(list(diff_rows.LINK_HEADER), _coded(rows, 0, 3), "lllll"),  # names as code
        "</details>\n",
    ]


def _excluded(files: Iterable[ExcludedFile]) -> list[str]:
    return [f"- excluded {code(x.path)}: {code(x.reason)}" for x in files]


def render_series(report: SeriesReport, max_rows: int | None = None) -> str:
    parts = [
        render_diff(s.report, max_rows).replace(
            "## archmetrics:", f"## stage {code(s.label)}:", 1
        )
        for s in report.stages
    ]
    rows = _coded((r[1:] for r in diff_rows.trend_rows(report)), 0)
    parts.append("## Per location, across stages\n")
    parts.append(table(list(diff_rows.TREND_HEADER[1:]), rows, "ll" + "r" * 10))
    return "\n".join(parts)


def render_compare(report: CompareReport) -> str:
    names = ", ".join(code(name) for name, _ in report.series)
    rows = _coded(diff_rows.compare_rows(report), 0, 1)
    return f"## Compared: {names}\n\n" + table(list(diff_rows.TREND_HEADER), rows, "lll" + "r" * 10)


def render_estimate(report: EstimateReport) -> str:
    """Per stage, the per-location figures with one column group per architecture and the
    changed elements; then the ranking. The heading says it is an estimate."""
    parts = [
        f"## archmetrics estimate: {code(report.plan)} on {code(report.base)}\n",
        f"*{estimate_rows.LABEL}*\n",
    ]
    for label in report.stage_labels():
        if label != "estimate":
            parts.append(f"### Stage {code(label)}\n")
        header = estimate_rows.summary_header(report, label)
        parts.append(
            table(header, estimate_rows.summary_rows(report, label), "ll" + "r" * (len(header) - 2))
        )
        rows = _coded(estimate_rows.element_rows(report, label), 0, 1)
        if rows:
            element_header = ["architecture", *diff_rows.ELEMENT_HEADER]
            parts.append(table(element_header, rows, "llll" + "r" * (len(element_header) - 4)))
    parts.append("### Ranking: cheapest total E first\n")
    ranking = _coded(estimate_rows.ranking_rows(report), 0, 2)
    parts.append(table(estimate_rows.RANKING_HEADER, ranking, "lrlrrr"))
    if report.actual is not None:
        parts.append(
            f"### Accuracy: the estimate against the measured "
            f"{code(report.actual.base)} → {code(report.actual.head)}\n"
        )
        rows = _coded(estimate_rows.accuracy_rows(report), 0)
        parts.append(table(estimate_rows.ACCURACY_HEADER, rows, "lllrrrr"))
        elements = _coded(estimate_rows.element_accuracy_rows(report), 0, 1)
        if elements:
            parts.append("#### Elements: the figures the estimate got wrong\n")
            parts.append(table(estimate_rows.ELEMENT_ACCURACY_HEADER, elements, "llllrrrr"))
    bullets = _bullets(report.failures)
    for label in report.stage_labels():
        bullets += _bullets(estimate_rows.notes(report, label), "note ")
    return "\n".join(parts + (["\n".join(bullets) + "\n"] if bullets else []))
