"""The rows every history format shows, so the table, Markdown, CSV and DataFrame agree:
one row per commit (its total), the costliest commits, the integration-cost hotspots per
element, and one element's own trend."""

from __future__ import annotations

from collections.abc import Iterable
from datetime import UTC, datetime

from archmetrics.changeset.history import ElementTotals, element_share, element_totals
from archmetrics.changeset.model import Summary
from archmetrics.reports.diff_rows import TREND_FIELDS, number
from archmetrics.reports.model import LOCATION_COLUMNS, HistoryEntry, HistoryReport

# per commit: what a reader compares across a history (the trend fields of a series)
COMMIT_FIELDS: tuple[tuple[str, str], ...] = (
    ("added", "Γ_A"),
    ("removed", "Γ_R"),
    ("modified", "Γ_M"),
    ("scaled_changes", "Γ'"),
    ("scaled_delta_vg", "ΔVg'"),
    ("cost", "E"),
    ("delta_s_e", "Δs_e"),
    ("delta_d_e", "Δd_e"),
    ("delta_d_a", "Δd_a"),
)
COMMIT_HEADER = ("commit", "date", "subject", *(label for _, label in COMMIT_FIELDS))
HOTSPOT_HEADER = ("element", "location", "commits", "ΣΓ'", "ΣΔVg'", "E")
TREND_HEADER = ("commit", "date", "status", "Γ", "λ", "v_g", "s_a", "s_e", "d_a", "d_e")
# the long table (CSV, DataFrame): a row per commit and location, the trend fields and v_g
TABLE_FIELDS = (*(f for f, _ in TREND_FIELDS), "added", "removed", "modified", "vg_post")


def date(entry: HistoryEntry) -> str:
    """The commit's date, ISO 8601 in UTC (what the JSON writes)."""
    return datetime.fromtimestamp(entry.time, UTC).strftime("%Y-%m-%dT%H:%M:%SZ")


def short(commit: str) -> str:
    return commit[:12]


def _cells(summary: Summary) -> list[str]:
    return [number(getattr(summary, f)) for f, _ in COMMIT_FIELDS]


def commit_rows(entries: Iterable[HistoryEntry]) -> list[list[str]]:
    """One row per commit: its total."""
    return [
        [short(e.commit), date(e)[:10], e.subject, *_cells(e.step.summaries["total"])]
        for e in entries
    ]


def costliest(report: HistoryReport, top: int) -> list[HistoryEntry]:
    """The ``top`` commits with the highest total E (the thesis's complexity change cost),
    ties by Γ' then history order; commits that changed nothing measured are left out."""
    changed = [e for e in report.entries if e.step.summaries["total"].changes]
    ranked = sorted(
        enumerate(changed),
        key=lambda item: (
            -item[1].step.summaries["total"].cost,
            -item[1].step.summaries["total"].scaled_changes,
            item[0],
        ),
    )
    return [entry for _, entry in ranked[:top]]


def hotspots(report: HistoryReport, top: int | None = None) -> tuple[ElementTotals, ...]:
    found = element_totals(e.step for e in report.entries)
    return found if top is None else found[:top]


def hotspot_rows(found: Iterable[ElementTotals]) -> list[list[str]]:
    return [
        [h.element, h.location, str(h.commits), number(h.scaled_changes),
         number(h.scaled_delta_vg), number(h.cost)]
        for h in found
    ]  # fmt: skip


def trend_rows(report: HistoryReport, element: str) -> list[list[str]]:
    """``element``'s own trend: a row per commit whose change set of it is not empty or
    whose metrics of it moved (after the commit: λ, v_g and coupling)."""
    rows = []
    for entry in report.entries:
        for change in entry.step.elements:
            if change.element != element:
                continue
            changes, _, _, _ = element_share(entry.step, change)
            after = change.post
            metrics = [number(v) for v in after] if after else ["-"] * 7
            loc, _sloc, vg, *coupling = metrics
            rows.append([short(entry.commit), date(entry)[:10], change.status.value,
                         str(changes), loc, vg, *coupling])  # fmt: skip
    return rows


def long_rows(report: HistoryReport) -> list[tuple[str | int | float | None, ...]]:
    """A row per commit and location: commit, date, subject, location, then
    :data:`TABLE_FIELDS` as numbers."""
    rows: list[tuple[str | int | float | None, ...]] = []
    for entry in report.entries:
        for location in LOCATION_COLUMNS:
            summary = entry.step.summaries[location]
            values = tuple(getattr(summary, f) for f in TABLE_FIELDS)
            rows.append((entry.commit, date(entry), entry.subject, location, *values))
    return rows
