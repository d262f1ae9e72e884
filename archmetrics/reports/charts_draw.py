"""A :class:`Chart` drawn with matplotlib's object-oriented API into PNG or SVG bytes.

Figure + FigureCanvasAgg only, never pyplot's global figures. The few settings that matplotlib
reads from its global rcParams while saving (the SVG id salt that makes SVG bytes reproducible,
fonts) are applied in an ``rc_context`` held under a lock, so concurrent renders cannot see each
other's settings; separate processes share nothing.
"""

from __future__ import annotations

import re
import textwrap
import threading
from dataclasses import dataclass
from io import BytesIO
from typing import TYPE_CHECKING, Any

from matplotlib import rc_context
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.layout_engine import ConstrainedLayoutEngine
from matplotlib.patches import Patch
from matplotlib.ticker import MaxNLocator

from archmetrics.reports.charts_data import CONVENTION_NAMES, Value, note_code
from archmetrics.reports.charts_layout import Chart, Panel

if TYPE_CHECKING:
    from matplotlib.typing import RcKeyType  # matplotlib >= 3.9 (typing only)

DPI = 100
FORMATS = ("png", "svg")
MARKS = ("†", "‡", "§", "¶", "#", "*", "**", "°")  # one per convention code (charts_data)
_RC: dict[RcKeyType, Any] = {
    "svg.hashsalt": "archmetrics",  # SVG ids from a fixed salt, not a random uuid
    "svg.fonttype": "path",  # glyphs as paths: the SVG looks the same without our fonts
    "font.family": ["DejaVu Sans"],  # shipped with matplotlib: same glyphs everywhere
    "mathtext.fontset": "dejavusans",
}
_METADATA: dict[str, dict[str, str | None]] = {
    "png": {"Software": "archmetrics (matplotlib)"},
    "svg": {"Date": None, "Creator": "archmetrics (matplotlib)"},
}
_TEX = {
    r"\Gamma": "Γ",
    r"\Delta ": "Δ",
    r"\Delta": "Δ",
    r"\times": "×",
    "V_g": "Vg",
    r"\hat{\lambda}": "λ̂",
}
_LOCK = threading.Lock()
_FOOT_LINE = 0.16  # inches per footnote line at 8 pt
_MARGIN = 0.1  # inches between the drawing and the image's edge
_WRAP = 150  # characters per footnote line at 10 in


class Footnotes:
    """A mark per convention code the values rest on, and the gaps' reasons, in order met."""

    def __init__(self, chart: Chart) -> None:
        self.marks: dict[str, str] = {}  # code -> mark
        self.notes: dict[str, str] = {}  # code -> its first note
        self.gaps: dict[str, None] = {}
        for panel in chart.panels:
            for bars in panel.bars:
                for value in bars.values:
                    self._collect(value)

    def _collect(self, value: Value) -> None:
        if value.number is None:
            self.gaps.setdefault(value.gap, None)
        for note in value.conventions:
            code = note_code(note)
            if code not in self.marks:
                self.marks[code] = MARKS[len(self.marks) % len(MARKS)]
                self.notes[code] = note

    def of(self, value: Value) -> str:
        return "".join(dict.fromkeys(self.marks[note_code(n)] for n in value.conventions))

    def lines(self) -> list[str]:
        """The footnote text, wrapped."""
        texts = [f"{self.marks[code]} {footnote(note)}" for code, note in self.notes.items()]
        if self.gaps:
            texts.append("n/a  undefined, not drawn (not zero): " + "; ".join(self.gaps))
        return [line for text in texts for line in textwrap.wrap(text, _WRAP)]


def footnote(note: str) -> str:
    """A note ("<code>: <text>") as the footnote "<what the mark means>: <text>"."""
    code, _, text = note.partition(":")
    return f"{CONVENTION_NAMES.get(code.strip(), code.strip())}: {text.strip()}"


def number(value: float, places: int | None = None) -> str:
    """A bar label with ``places`` decimals (:func:`places`); without, integers plain, else one
    decimal from 10 up, two below."""
    if places is not None:
        return f"{value:.{places}f}"
    if value.is_integer():
        return str(int(value))
    return f"{value:.1f}" if abs(value) >= 10 else f"{value:.2f}"


def places(chart: Chart) -> int:
    """One precision for every label of a chart: none when every value is a whole number
    (counts), else two decimals below 10, one below 100, none above."""
    numbers = _numbers(chart)
    if all(n.is_integer() for n in numbers):
        return 0
    largest = max(abs(n) for n in numbers)
    return 2 if largest < 10 else 1 if largest < 100 else 0


@dataclass(frozen=True, slots=True)
class _Labels:
    """How a chart's value labels are written: its precision, and whether they stand upright
    (horizontal when the widest fits over its bar, else turned a quarter)."""

    places: int
    rotation: int
    notes: Footnotes

    def text(self, value: Value) -> str:
        """The value and its convention marks; n/a for none; a zero's marks only (no "0" on
        an empty bar)."""
        if value.number is None:
            return "n/a"
        if value.number == 0:
            return self.notes.of(value)
        return number(value.number, self.places) + self.notes.of(value)


_LABEL_SIZE = 8  # points
_CHAR_WIDTH = 0.6  # of the font size: a digit's width, about


def _labels(chart: Chart, notes: Footnotes) -> _Labels:
    decimals = places(chart)
    probe = _Labels(decimals, 0, notes)
    widest = max(
        (len(probe.text(v)) for p in chart.panels for b in p.bars for v in b.values), default=0
    )
    cols = chart.shape[1]
    panel_points = chart.size[0] * 72 * 0.75 / cols  # a panel's share of the figure's width
    bar_points = min(
        panel_points / max(len(p.groups), 1) * 0.8 / max(len(p.bars), 1) for p in chart.panels
    )
    fits = widest * _LABEL_SIZE * _CHAR_WIDTH <= bar_points
    return _Labels(decimals, 0 if fits else 90, notes)


def _numbers(chart: Chart) -> list[float]:
    return [
        v.number for p in chart.panels for b in p.bars for v in b.values if v.number is not None
    ]


def _limits(chart: Chart) -> tuple[float, float]:
    """Shared y limits with room for the rotated value labels above (and below) the bars."""
    numbers = _numbers(chart)
    low, high = min([0.0, *numbers]), max([0.0, *numbers])
    span = (high - low) or 1.0
    room = 0.45 if chart.shape[0] > 1 else 0.3
    return low - (room * span if low < 0 else 0.05 * span), high + room * span


def _label(ax: Any, x: float, value: Value, labels: _Labels) -> None:
    """The value (or n/a) and its convention marks just past the bar's end."""
    y = value.number if value.number is not None else 0.0
    text = labels.text(value)
    if not text:
        return
    below = y < 0
    ax.annotate(
        text,
        (x, y),
        xytext=(0, -2 if below else 2),
        textcoords="offset points",
        rotation=labels.rotation,
        ha="center",
        va="top" if below else "bottom",
        fontsize=_LABEL_SIZE,
        color="0.35" if value.number is None else "0.1",
        style="italic" if value.number is None else "normal",
    )


def _panel(ax: Any, panel: Panel, labels: _Labels) -> None:
    width = 0.8 / max(len(panel.bars), 1)
    for i, bars in enumerate(panel.bars):
        offset = (i - (len(panel.bars) - 1) / 2) * width
        xs = [g + offset for g in range(len(panel.groups))]
        drawn = [
            (x, v.number) for x, v in zip(xs, bars.values, strict=True) if v.number is not None
        ]
        if drawn:
            at, heights = zip(*drawn, strict=True)
            ax.bar(at, heights, width, color=bars.colour, edgecolor="0.15", linewidth=0.5)
        for x, value in zip(xs, bars.values, strict=True):
            _label(ax, x, value, labels)
    ax.set_xticks(range(len(panel.groups)), panel.groups, fontsize=10)
    ax.set_xlim(-0.5, len(panel.groups) - 0.5)
    ax.axhline(0, color="0.15", linewidth=0.8)
    ax.grid(axis="y", color="0.85", linewidth=0.6)
    ax.set_axisbelow(True)
    ax.tick_params(axis="y", labelsize=9)
    for side in ("top", "right"):
        ax.spines[side].set_visible(False)
    if panel.title:
        ax.set_title(panel.title, fontsize=11)


def _axes(fig: Figure, chart: Chart, notes: Footnotes) -> None:
    """The panel grid on one shared y axis; x labels on the bottom row only."""
    rows, cols = chart.shape
    axes = list(fig.subplots(rows, cols, sharey=True, squeeze=False).flat)
    labels = _labels(chart, notes)
    for ax, panel in zip(axes, chart.panels, strict=False):
        _panel(ax, panel, labels)
        if len(chart.panels) == 1:
            ax.set_title("")  # the one repository is named in the chart's title already
    for ax in axes[len(chart.panels) :]:
        ax.set_visible(False)
    for ax in axes[(rows - 1) * cols :]:
        ax.set_xlabel(chart.xlabel, fontsize=10)
    axes[0].set_ylim(*_limits(chart))
    if all(n.is_integer() for n in _numbers(chart)):
        axes[0].yaxis.set_major_locator(MaxNLocator(integer=True))


def _legend(fig: Figure, chart: Chart) -> None:
    handles = [
        Patch(facecolor=b.colour, edgecolor="0.15", linewidth=0.5, label=b.label)
        for b in chart.panels[0].bars
    ]
    fig.legend(
        handles=handles,
        loc="outside right upper",
        borderaxespad=_MARGIN * DPI / 10,  # in font sizes: clear of the image's edge
        title=chart.legend_title,
        fontsize=10,
        frameon=False,
    )


def _figure(chart: Chart) -> Figure:
    """Title, panels, legend at the right, footnotes at the bottom (room kept for them)."""
    notes = Footnotes(chart)
    lines = notes.lines()
    foot = (len(lines) * _FOOT_LINE + 0.08) / chart.size[1] if lines else 0.0
    fig = Figure(figsize=chart.size, dpi=DPI)
    # a margin all round, so the title and the legend never touch the image's edge
    inset = (_MARGIN / chart.size[0], _MARGIN / chart.size[1])
    rect = (inset[0], foot + inset[1], 1 - 2 * inset[0], 1 - foot - 2 * inset[1])
    layout = ConstrainedLayoutEngine(rect=rect)
    fig.set_layout_engine(layout)
    FigureCanvasAgg(fig)
    _axes(fig, chart, notes)
    fig.supylabel(chart.ylabel, fontsize=11)
    fig.suptitle(chart.title, fontsize=13, fontweight="bold")
    _legend(fig, chart)
    if lines:
        fig.text(0.01, 0.01, "\n".join(lines), ha="left", va="bottom", fontsize=8, color="0.2")
    return fig


def plain(text: str) -> str:
    """Mathtext made plain for metadata: ``$\\Gamma'_{tot}$`` -> ``Γ'_tot``."""
    for tex, char in _TEX.items():
        text = text.replace(tex, char)
    return re.sub(r"[${}]|\\[,! ]", "", text).replace("\\", "")


def render(chart: Chart, fmt: str) -> bytes:
    """The chart as PNG or SVG bytes; the same chart always gives the same bytes."""
    if fmt not in FORMATS:
        raise ValueError(f"unknown chart format {fmt!r}: expected one of {', '.join(FORMATS)}")
    with _LOCK, rc_context(_RC):
        buffer = BytesIO()
        metadata = {**_METADATA[fmt], "Title": plain(chart.title)}
        _figure(chart).savefig(buffer, format=fmt, dpi=DPI, metadata=metadata)
    data = buffer.getvalue()
    return _numbered_clips(data) if fmt == "svg" else data


_CLIP_ID = re.compile(rb'(?<=clipPath id=")p[0-9a-f]{10}(?=")|(?<=url\(#)p[0-9a-f]{10}(?=\))')


def _numbered_clips(svg: bytes) -> bytes:
    """The SVG with its clip paths named by their order of first use (``clip0`` ...).
    matplotlib names a clip path by a hash of its transform's full repr, which the layout's
    last float digits can change between two renders of one chart in one process: the test
    suite met it once in a few runs, with every drawn coordinate the same."""
    names: dict[bytes, bytes] = {}

    def named(found: re.Match[bytes]) -> bytes:
        return names.setdefault(found.group(), b"clip%d" % len(names))

    return _CLIP_ID.sub(named, svg)
