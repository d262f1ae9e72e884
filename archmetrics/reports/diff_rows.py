"""The rows every diff format shows, so the table, Markdown and CSV never disagree."""

from __future__ import annotations

from collections.abc import Iterable

from archmetrics.changeset.model import ElementChange, Metrics, Summary
from archmetrics.reports.model import LOCATION_COLUMNS, CompareReport, DiffReport, SeriesReport

# (field, label as in the thesis, equation)
SUMMARY_ROWS: tuple[tuple[str, str, str], ...] = (
    ("delta_s_a", "Δs_a", "6.1"),
    ("delta_s_e", "Δs_e", "6.4"),
    ("delta_d_a", "Δd_a", "6.7"),
    ("delta_d_e", "Δd_e", "6.9"),
    ("loc_pre", "λ_pre", "6.19"),
    ("loc_post", "λ_post", "6.19"),
    ("loc_scale", "λ̂", "6.20"),
    ("added", "Γ_A", "6.16"),
    ("removed", "Γ_R", "6.17"),
    ("modified", "Γ_M", "6.18"),
    ("changes", "Γ", "6.15"),
    ("scaled_changes", "Γ'", "6.25"),
    ("vg_pre", "Vg_pre", "6.31"),
    ("vg_post", "Vg_post", "6.31"),
    ("vg_scale", "v̂g", "6.33"),
    ("delta_vg", "ΔVg", "6.30"),
    ("scaled_delta_vg", "ΔVg'", "6.35"),
    ("cost", "E", "6.37"),
)

ELEMENT_HEADER = (
    "element",
    "location",
    "status",
    "λ pre",
    "λ post",
    "v_g pre",
    "v_g post",
    "Γ_A",
    "Γ_R",
    "Γ_M",
    "s_a",
    "s_e",
    "d_a",
    "d_e",
)


def number(value: object) -> str:
    """A summary value as shown: integers plain, ratios to 2 places, undefined as n/a."""
    if value is None:
        return "n/a"
    if isinstance(value, float):
        return f"{value:.2f}"
    return str(value)


def summary_rows(report: DiffReport) -> list[list[str]]:
    summaries = report.summaries()
    return [
        [label, eq, *(number(getattr(summaries[c], field)) for c in LOCATION_COLUMNS)]
        for field, label, eq in SUMMARY_ROWS
    ]


def _pair(pre: Metrics | None, post: Metrics | None, field: str) -> str:
    """``3`` when unchanged, ``2→3`` when it changed, ``-`` for a side that does not exist."""
    before = number(getattr(pre, field)) if pre else "-"
    after = number(getattr(post, field)) if post else "-"
    return after if before == after else f"{before}→{after}"


def element_row(e: ElementChange) -> list[str]:
    def value(m: Metrics | None, field: str) -> str:
        return number(getattr(m, field)) if m else "-"

    return [
        e.element,
        e.location.value,
        e.status.value,
        value(e.pre, "loc"),
        value(e.post, "loc"),
        value(e.pre, "vg"),
        value(e.post, "vg"),
        str(e.added),
        str(e.removed),
        str(e.modified),
        *(_pair(e.pre, e.post, f) for f in ("s_a", "s_e", "d_a", "d_e")),
    ]


LINK_HEADER = ("element", "change", "role", "endpoint", "sites")
_ROLE_WORDS = {"initiate": "initiates", "receive": "receives", "use": "uses"}


def link_rows(changed: list[ElementChange]) -> list[list[str]]:
    """Per changed element, the link sites added (+) and removed (-), by role and endpoint
    (``?``: not known statically), with how many sites each is."""
    rows: list[list[str]] = []
    for e in changed:
        for sign, changes in (("+", e.links_added), ("-", e.links_removed)):
            rows += [
                [e.element, sign, _ROLE_WORDS.get(role, role), key or "?", str(count)]
                for role, key, count in changes
            ]
    return rows


def notes(report: DiffReport) -> list[str]:
    """Every note once, prefixed with the locations it applies to."""
    where: dict[str, list[str]] = {}
    summaries: dict[str, Summary] = report.summaries()
    for column in LOCATION_COLUMNS:
        for note in summaries[column].notes:
            where.setdefault(note, []).append(column)
    return [f"[{', '.join(cols)}] {note}" for note, cols in where.items()]


# The per-location summary across stages: the thesis's per-stage figures in one table.
TREND_FIELDS: tuple[tuple[str, str], ...] = (
    ("delta_s_a", "Δs_a"),
    ("delta_s_e", "Δs_e"),
    ("delta_d_a", "Δd_a"),
    ("delta_d_e", "Δd_e"),
    ("loc_post", "λ_post"),
    ("changes", "Γ"),
    ("scaled_changes", "Γ'"),
    ("delta_vg", "ΔVg"),
    ("scaled_delta_vg", "ΔVg'"),
    ("cost", "E"),
)
TREND_HEADER = ("approach", "stage", "location", *(label for _, label in TREND_FIELDS))


def trend_rows(series: SeriesReport, approach: str = "") -> list[list[str]]:
    """One row per location (and total) per stage."""
    rows = []
    for location in LOCATION_COLUMNS:
        for stage in series.stages:
            summary = stage.report.summaries()[location]
            values = (number(getattr(summary, field)) for field, _ in TREND_FIELDS)
            rows.append([approach, stage.label, location, *values])
    return rows


def compare_rows(compare: CompareReport) -> list[list[str]]:
    """Rows of every series, grouped by location, then approach, then stage."""
    per_series = {name: trend_rows(series, name) for name, series in compare.series}
    rows: list[list[str]] = []
    for location in LOCATION_COLUMNS:
        for series_rows in per_series.values():
            rows.extend(r for r in series_rows if r[2] == location)
    return rows


def unmatched_glob(glob: str) -> str:
    """The warning for a location or exclude glob that matched no file."""
    return (
        f"the glob {glob!r} matched no file archmetrics measures, before or after"
        " (a typo, or quotes kept around it?)"
    )


def unparsed_line(report: DiffReport) -> list[str]:
    """A line naming the touched files that could not be parsed, when there are any."""
    count = report.change.total.unparsed
    if not count:
        return []
    return [
        f"{count} changed file(s) could not be parsed (a syntax error?) and are left out of"
        " every number (listed as excluded, not_parsed); gate on them: unparsed(total) > 0"
    ]


def most_changed_first(changes: Iterable[ElementChange]) -> list[ElementChange]:
    """Most changed statements first, then the largest complexity change, then by name:
    the order every report lists changed elements in."""

    def key(change: ElementChange) -> tuple[int, int, str]:
        delta_vg = (change.post.vg if change.post else 0) - (change.pre.vg if change.pre else 0)
        return (-(change.added + change.removed + change.modified), -abs(delta_vg), change.element)

    return sorted(changes, key=key)


def verdict(report: DiffReport) -> str:
    """The run in one line: the change's size and cost, and whether its gates hold."""
    total = report.change.total
    failed = len(report.failed)
    said = (
        f"{failed} gate failure(s)"
        if failed
        else ("all gates hold" if report.gates else "no gates configured")
    )
    return (
        f"Γ = {total.changes} statements changed, ΔVg = {total.delta_vg}, E = "
        f"{number(total.cost)}: {said}"
    )
