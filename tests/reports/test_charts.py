"""Charts of real series and comparisons: measured by the real pipeline on real git repositories,
rendered to PNG and SVG, decoded and read back."""

from __future__ import annotations

import threading
import xml.etree.ElementTree as ET
from io import BytesIO
from pathlib import Path
from xml.sax.saxutils import unescape

import pytest
from matplotlib.image import imread

from archmetrics.app.series import run_compare
from archmetrics.changeset.model import Summary
from archmetrics.reports.charts import (
    THESIS_FIGURES,
    ChartError,
    chart_kinds,
    chart_of,
    render_all,
    render_compare_chart,
    render_series_chart,
    series_name,
)
from archmetrics.reports.charts_data import COUPLING as COUPLING_MEASURES
from archmetrics.reports.charts_data import INTEGRATION, LOCATIONS
from archmetrics.reports.charts_draw import _figure
from archmetrics.reports.charts_layout import APPROACH_COLOURS, LOCATION_COLOURS
from archmetrics.reports.model import CompareReport, SeriesReport, Stage
from tests.reports.study_repos import (
    APPROACHES,
    STAGES,
    build_repo,
    build_study,
    p2p,
    player,
    series_request,
)

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
KINDS = (
    "coupling",
    "scaled_changes",
    "scaled_complexity",
    "cost",
    "coupling_total",
    "scaled_changes_total",
    "scaled_complexity_total",
    "cost_total",
)
BY_LOCATION = {"scaled_changes": "scaled_changes", "scaled_complexity": "scaled_delta_vg",
               "cost": "cost"}  # fmt: skip


@pytest.fixture(scope="module")
def study(tmp_path_factory: pytest.TempPathFactory) -> CompareReport:
    return build_study(tmp_path_factory.mktemp("study"))


@pytest.fixture(scope="module")
def pngs(study: CompareReport) -> dict[str, bytes]:
    return render_all(study, "png")


@pytest.fixture(scope="module")
def svgs(study: CompareReport) -> dict[str, bytes]:
    return render_all(study, "svg")


def svg_texts(svg: bytes) -> list[str]:
    """The SVG's texts: matplotlib draws glyphs as paths and writes each string in a comment."""
    builder = ET.TreeBuilder(insert_comments=True)
    parser = ET.XMLParser(target=builder)
    parser.feed(svg)
    root = parser.close()
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    comments = (e for e in root.iter() if not isinstance(e.tag, str))
    return [unescape(str(e.text)).strip() for e in comments]  # matplotlib escapes <, >, &


def decode_png(png: bytes) -> object:
    assert png.startswith(PNG_SIGNATURE)
    return imread(BytesIO(png), format="png")


def has_colour(image: object, hex_colour: str) -> bool:
    """Some pixel of the decoded RGBA image is (within rounding) the given colour."""
    import numpy as np

    rgb = np.array([int(hex_colour[i : i + 2], 16) / 255 for i in (1, 3, 5)])
    pixels = np.asarray(image)[..., :3]
    return bool((np.abs(pixels - rgb).max(axis=-1) < 2 / 255).any())


def test_the_kinds_and_the_thesis_figures_they_reproduce() -> None:
    assert chart_kinds() == KINDS
    assert set(THESIS_FIGURES) == set(KINDS)
    assert "7.1" in THESIS_FIGURES["coupling"] and "8.4" in THESIS_FIGURES["cost_total"]


def test_the_pipeline_measured_three_approaches_of_three_stages(study: CompareReport) -> None:
    assert [name for name, _ in study.series] == list(APPROACHES)
    assert all(tuple(s.label for s in series.stages) == STAGES for _, series in study.series)


@pytest.mark.parametrize("kind", KINDS)
def test_png_decodes_to_a_drawn_image_of_the_chart_size(
    kind: str, study: CompareReport, pngs: dict[str, bytes]
) -> None:
    import numpy as np

    image = np.asarray(decode_png(pngs[kind]))
    width, height = chart_of(study, kind).size
    assert image.shape == (round(height * 100), round(width * 100), 4)
    assert image[..., :3].std() > 0.05  # not blank
    if kind != "coupling":
        assert image.shape[:2] == (600, 1000)  # 10 x 6 in at 100 dpi
    colours = APPROACH_COLOURS[: len(APPROACHES)] if kind.endswith("_total") else (
        LOCATION_COLOURS[loc] for loc in LOCATIONS
    )  # fmt: skip
    for colour in colours:
        assert has_colour(image, colour), f"{kind}: no bar drawn in {colour}"


@pytest.mark.parametrize("kind", KINDS)
def test_svg_is_xml_with_title_stages_and_legend(kind: str, svgs: dict[str, bytes]) -> None:
    texts = svg_texts(svgs[kind])
    title = next(t for t in texts if t.endswith(": SOA, Player, P2P"))
    assert title
    for stage in STAGES:  # a tick label, or part of a panel title ("SOA · first")
        assert any(t == stage or t.endswith(f" · {stage}") for t in texts)
    legend = list(APPROACHES) if kind.endswith("_total") else list(LOCATIONS)
    assert texts[-len(legend) :] == legend  # the legend is drawn last
    if kind in ("coupling", "scaled_changes", "scaled_complexity", "cost"):
        assert set(APPROACHES) <= {t.split(" · ")[0] for t in texts}  # one panel per approach


def test_svg_and_png_carry_the_plain_title(svgs: dict[str, bytes], pngs: dict[str, bytes]) -> None:
    title = ET.fromstring(svgs["scaled_complexity"]).find("{http://www.w3.org/2000/svg}title")
    expected = "Scaled complexity change ΔVg' by location: SOA, Player, P2P"
    assert title is not None and title.text == expected
    assert expected.encode() in pngs["scaled_complexity"]  # an iTXt chunk, UTF-8


def test_axis_labels_carry_the_thesis_symbols(
    study: CompareReport, svgs: dict[str, bytes]
) -> None:
    assert r"$\Gamma'$  scaled code size change" in svg_texts(svgs["scaled_changes"])
    assert r"$\Delta V_g'$  scaled complexity change" in svg_texts(svgs["scaled_complexity"])
    assert r"$E_{tot}$  complexity change cost" in svg_texts(svgs["cost_total"])
    scoped = render_compare_chart(study, "cost_total", "svg", INTEGRATION)
    assert r"$E_{B+F}$  complexity change cost" in svg_texts(scoped)
    coupling = svg_texts(svgs["coupling"])
    assert {r"$\Delta s_a$", r"$\Delta s_e$", r"$\Delta d_a$", r"$\Delta d_e$"} <= set(coupling)


def test_bars_are_the_measured_values(study: CompareReport) -> None:
    for kind, field in BY_LOCATION.items():
        chart = chart_of(study, kind)
        for (name, series), panel in zip(study.series, chart.panels, strict=True):
            assert panel.title == name
            for bars in panel.bars:
                measured = [getattr(s.report.summaries()[bars.label], field) for s in series.stages]
                assert [v.number for v in bars.values] == pytest.approx(measured)
    p2p = chart_of(study, "coupling_total").panels[3].bars[2]  # Δd_e,tot of P2P
    assert [v.number for v in p2p.values] == [s.report.change.total.delta_d_e
                                              for s in study.series[2][1].stages]  # fmt: skip


def test_baseline_conventions_are_marked_and_footnoted(svgs: dict[str, bytes]) -> None:
    texts = svg_texts(svgs["scaled_changes"])
    assert any(t.startswith("† λ̂ undefined: λ_pre = 0") for t in texts)
    assert any(t.endswith("†") for t in texts)  # a baseline bar's value label


def test_output_is_deterministic(study: CompareReport, svgs: dict[str, bytes]) -> None:
    assert render_compare_chart(study, "cost", "svg") == svgs["cost"]
    assert render_compare_chart(study, "cost", "png") == render_compare_chart(study, "cost")


def test_concurrent_renders_give_the_same_bytes(
    study: CompareReport, svgs: dict[str, bytes]
) -> None:
    results: dict[str, bytes] = {}

    def render(kind: str) -> None:
        results[kind] = render_compare_chart(study, kind, "svg")

    threads = [threading.Thread(target=render, args=(k,)) for k in ("cost", "cost_total")]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=120)
    assert results == {"cost": svgs["cost"], "cost_total": svgs["cost_total"]}


def test_a_series_is_a_comparison_of_one(study: CompareReport) -> None:
    series = study.series[1][1]
    alone = CompareReport(((series_name(series), series),))
    assert series_name(series) == "player"
    svg = render_series_chart(series, "scaled_complexity", "svg")
    assert svg == render_compare_chart(alone, "scaled_complexity", "svg")
    texts = svg_texts(svg)
    assert any(t.endswith("by location: player") for t in texts)
    assert decode_png(render_series_chart(series, "coupling")) is not None


@pytest.fixture(scope="module")
def uneven(tmp_path_factory: pytest.TempPathFactory) -> CompareReport:
    """Player in three stages, the last removing an operation; P2P stopped after two."""
    folder = tmp_path_factory.mktemp("uneven")
    repo = build_repo(folder / "player", player)
    repo.commit("shrink", tag="shrunk", files=player(["query"]))
    build_repo(folder / "p2p", p2p)
    return run_compare(
        [
            ("Player", series_request(folder / "player", ("baseline", "first", "shrunk"), STAGES)),
            ("P2P", series_request(folder / "p2p", STAGES[:2])),
        ]
    )


def test_undefined_values_are_gaps_not_zeros(uneven: CompareReport) -> None:
    chart = chart_of(uneven, "cost_total")
    p2p = chart.panels[0].bars[1]
    assert [v.number is None for v in p2p.values] == [False, False, True]
    assert p2p.values[2].gap == "P2P has no stage 'second'"
    texts = svg_texts(render_compare_chart(uneven, "cost_total", "svg"))
    assert "n/a" in texts
    assert any("n/a  undefined, not drawn (not zero): P2P has no stage 'second'" in t
               for t in texts)  # fmt: skip
    image = decode_png(render_compare_chart(uneven, "cost_total", "png"))
    assert has_colour(image, APPROACH_COLOURS[1])  # P2P's defined stages are still drawn


def test_negative_cost_is_drawn_below_zero_and_footnoted(uneven: CompareReport) -> None:
    player_second = uneven.series[0][1].stages[2].report.change.total
    assert player_second.scaled_delta_vg < 0 < player_second.scaled_changes
    chart = chart_of(uneven, "cost_total")
    value = chart.panels[0].bars[0].values[2]
    assert value.number is not None and value.number < 0
    assert value.number == pytest.approx(player_second.cost)
    texts = svg_texts(render_compare_chart(uneven, "cost_total", "svg"))
    assert any(" E < 0: ΔVg' < 0 so E < 0" in t for t in texts)


def test_unknown_kind_format_or_empty_report_is_refused(study: CompareReport) -> None:
    with pytest.raises(ChartError, match="unknown chart kind 'pie'"):
        render_compare_chart(study, "pie")
    with pytest.raises(ChartError, match="unknown chart format 'gif'"):
        render_compare_chart(study, "cost", "gif")
    with pytest.raises(ChartError, match="no stages"):
        render_compare_chart(CompareReport(()), "cost")
    with pytest.raises(ChartError, match="no stages"):
        render_series_chart(SeriesReport("x", ()), "cost")


def test_render_all_names_a_file_per_kind(tmp_path: Path, pngs: dict[str, bytes]) -> None:
    assert tuple(pngs) == KINDS
    for stem, data in pngs.items():
        (tmp_path / f"{stem}.png").write_bytes(data)
    assert sorted(p.stem for p in tmp_path.iterdir()) == sorted(KINDS)


def test_names_are_shown_as_typed_not_as_mathtext(study: CompareReport) -> None:
    renamed = CompareReport((("cost $x$ 1", study.series[0][1]), ("$", study.series[1][1])))
    texts = svg_texts(render_compare_chart(renamed, "cost_total", "svg"))
    assert texts[-2:] == ["cost $x$ 1", "$"]  # the legend: escaped, so drawn literally
    title = "Complexity change cost across stages, total of base, new and framework: cost $x$ 1, $"
    assert title in texts
    assert decode_png(render_compare_chart(renamed, "scaled_changes")) is not None


def _value_labels(study: CompareReport, kind: str) -> list[tuple[str, float]]:
    """Each value label's text and rotation, as drawn."""
    figure = _figure(chart_of(study, kind))
    return [(t.get_text(), t.get_rotation()) for ax in figure.axes for t in ax.texts]


def test_value_labels_share_one_precision_and_an_empty_bar_shows_no_zero(
    study: CompareReport,
) -> None:
    labels = [text for text, _ in _value_labels(study, "cost")]
    numbers = [text.rstrip("†‡§*¶") for text in labels if text and text != "n/a"]
    decimals = {len(n.split(".")[1]) if "." in n else 0 for n in numbers if n}
    assert len(decimals) == 1 and decimals != {0}  # E: 2.00 beside 4.24, not 2 beside 4.24
    assert not any(text.rstrip("†‡§*¶") in {"0", "0.0", "0.00"} for text in labels)
    counts = [text.rstrip("†‡§*¶") for text, _ in _value_labels(study, "coupling")]
    assert all("." not in n for n in counts if n and n != "n/a")  # counts stay whole


def test_value_labels_stand_upright_where_they_fit(study: CompareReport) -> None:
    crowded = {rotation for _, rotation in _value_labels(study, "cost")}
    alone = CompareReport(((series_name(study.series[0][1]), study.series[0][1]),))
    roomy = _figure(chart_of(alone, "cost_total"))
    upright = {t.get_rotation() for ax in roomy.axes for t in ax.texts}
    assert crowded == {90.0}  # nine bars a panel: turned a quarter, as before
    assert upright == {0.0}
    assert [ax.get_title() for ax in roomy.axes if ax.get_visible()] == [""]  # named once


def test_stages_named_otherwise_show_the_revision_they_measured(study: CompareReport) -> None:
    # `series v1 v2 --labels one,two`: the x axis says both, the label over its revision
    name, series = study.series[0]
    renamed = SeriesReport(
        series.repo,
        tuple(Stage(f"stage {i}", s.report) for i, s in enumerate(series.stages)),
    )
    chart = chart_of(CompareReport(((name, renamed),)), "cost")
    heads = [s.report.head for s in series.stages]
    assert chart.panels[0].groups == tuple(f"stage {i}\n({head})" for i, head in enumerate(heads))
    # stages named by their revisions (the study's tags) say it once
    assert chart_of(study, "cost").panels[0].groups == tuple(heads)


def _scoped(base: Summary, framework: Summary, field: str) -> float | None:
    """``field`` over base and framework together, from the two locations' summaries by the
    thesis's equations: coupling and Γ add up; λ̂ and v̂g are ratios of the summed sizes
    (6.16-6.18, 6.31); E = Γ'/ΔVg' (6.36), 0 when ΔVg' = 0 (6.38)."""
    if field.startswith("delta_") and field != "delta_vg":
        return float(getattr(base, field) + getattr(framework, field))
    changes = base.changes + framework.changes
    loc_pre, loc_post = base.loc_pre + framework.loc_pre, base.loc_post + framework.loc_post
    vg_pre, vg_post = base.vg_pre + framework.vg_pre, base.vg_post + framework.vg_post
    scaled = changes * (loc_post / loc_pre if loc_pre else 1.0)
    delta_vg = (vg_post - vg_pre) * (vg_post / vg_pre if vg_pre else 1.0)
    return {"scaled_changes": scaled, "scaled_delta_vg": delta_vg,
            "cost": scaled / delta_vg if delta_vg else 0.0}[field]  # fmt: skip


@pytest.mark.parametrize("kind", [k for k in KINDS if k.endswith("_total")])
def test_summary_charts_draw_base_plus_framework_when_asked_and_say_so(
    study: CompareReport, kind: str
) -> None:
    scoped, total = chart_of(study, kind, INTEGRATION), chart_of(study, kind)
    assert ", base + framework: " in scoped.title and "new" not in scoped.title
    assert ", total of base, new and framework: " in total.title  # the thesis's total
    fields = {
        "coupling_total": [m.field for m in COUPLING_MEASURES],
        "scaled_changes_total": ["scaled_changes"],
        "scaled_complexity_total": ["scaled_delta_vg"],
        "cost_total": ["cost"],
    }[kind]
    differs = False
    for field, panel, whole in zip(fields, scoped.panels, total.panels, strict=True):
        for (_, series), bars, all_bars in zip(study.series, panel.bars, whole.bars, strict=True):
            for stage, value, all_value in zip(series.stages, bars.values, all_bars.values,
                                               strict=True):  # fmt: skip
                summaries = stage.report.summaries()
                expected = _scoped(summaries["base"], summaries["framework"], field)
                assert value.number == pytest.approx(expected), (kind, field, stage.label)
                assert all_value.number == pytest.approx(getattr(summaries["total"], field))
                differs |= value.number != all_value.number
    assert differs  # the study's new location changes: the two scopes are not the same chart


def test_clip_paths_are_named_by_order_of_use_not_by_matplotlibs_hash() -> None:
    """matplotlib names a clip path by a hash of its transform's repr, whose last float
    digits two renders of one chart could differ in (the suite met it): two SVGs that
    differ only there read the same."""
    from archmetrics.reports.charts_draw import _numbered_clips

    def svg(first: str, second: str) -> bytes:
        return (
            f'<g clip-path="url(#{first})"/><g clip-path="url(#{second})"/>'
            f'<g clip-path="url(#{first})"/><defs><clipPath id="{first}"><rect/></clipPath>'
            f'<clipPath id="{second}"><rect/></clipPath></defs>'
        ).encode()

    one = _numbered_clips(svg("pa2a0d10565", "p0325ac77b5"))
    assert one == _numbered_clips(svg("pcbc7db0b36", "p26b6255de6"))
    assert one.count(b"url(#clip0)") == 2 and b'clipPath id="clip1"' in one
