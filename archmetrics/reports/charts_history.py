"""A history's chart: E, Γ' and Vg over the commits, one line per location, as PNG or SVG
bytes (matplotlib's object-oriented API, as charts_draw.py draws the study's figures)."""

from __future__ import annotations

from io import BytesIO

from archmetrics.reports.history_rows import short
from archmetrics.reports.model import LOCATION_COLUMNS, HistoryReport

FORMATS = ("png", "svg")
# (summary field, panel title): the complexity change cost, the size of each change, and the
# complexity after it, the three series an architect reads together
PANELS = (
    ("cost", "E (eq. 6.37) per commit"),
    ("scaled_changes", "Γ' (eq. 6.25) per commit"),
    ("vg_post", "Vg after each commit (eq. 6.31)"),
)


def render_history_chart(report: HistoryReport, fmt: str = "png") -> bytes:
    """Three panels over the commits, oldest on the left; the same report always gives the
    same bytes."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown chart format {fmt!r}: expected one of {', '.join(FORMATS)}")
    if not report.entries:
        raise ValueError("nothing to chart: the history has no commits")
    from matplotlib import rc_context
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    from archmetrics.reports.charts_draw import _LOCK, _METADATA, _RC, DPI

    entries = report.entries
    x = list(range(len(entries)))
    with _LOCK, rc_context(_RC):
        figure = Figure(figsize=(10, 8), layout="constrained")
        FigureCanvasAgg(figure)
        axes = figure.subplots(len(PANELS), 1, sharex=True)
        for ax, (field, title) in zip(axes, PANELS, strict=True):
            for location in LOCATION_COLUMNS:
                values = [getattr(e.step.summaries[location], field) for e in entries]
                if any(values):
                    ax.plot(x, values, label=location, linewidth=1)
            ax.set_title(title, fontsize=10, loc="left")
            ax.grid(True, linewidth=0.3)
        axes[0].legend(fontsize=8, loc="upper right")
        ticks = x[:: max(1, len(x) // 8)]
        axes[-1].set_xticks(ticks, [short(entries[i].commit)[:8] for i in ticks], fontsize=7)
        axes[-1].set_xlabel(f"commits of {report.range}, oldest first ({len(entries)})")
        buffer = BytesIO()
        metadata = {**_METADATA[fmt], "Title": f"archmetrics history of {report.range}"}
        figure.savefig(buffer, format=fmt, dpi=DPI, metadata=metadata)
    return buffer.getvalue()
