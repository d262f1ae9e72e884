"""`archmetrics replicate` end to end: the bundled subjects become repositories, are measured
through the real CLI, and the report, findings and charts are written."""

from __future__ import annotations

import json
import subprocess
from importlib import resources
from pathlib import Path
from typing import Any

import pytest
from jsonschema import Draft202012Validator

from archmetrics.app.replicate import ReplicateRequest, run_replicate, settings_for, subjects_root
from archmetrics.cli import main
from archmetrics.cli.study import findings_summary
from archmetrics.study.causes import load_causes
from archmetrics.study.findings import FINDINGS, summary
from archmetrics.study.headline import NAMES
from archmetrics.study.manifest import VARIANTS, ManifestError, find_manifests, load_manifest
from archmetrics.study.report import StudyReport, outcome, verdict_word


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, Path]:
    """The report folder and the repositories replicate built (kept with --keep-repos)."""
    out = tmp_path_factory.mktemp("study")
    repos = tmp_path_factory.mktemp("repos") / "r"
    code = main(["replicate", "--out", str(out), "--keep-repos", str(repos), "--quiet"])
    assert code == 0
    return out, repos


@pytest.fixture(scope="module")
def study(built: tuple[Path, Path]) -> Path:
    return built[0]


@pytest.fixture(scope="module")
def report(study: Path) -> Any:
    return json.loads((study / "report.json").read_text())


def _total(report: Any, subject: str, approach: str, stage: str, location: str) -> Any:
    subjects = report["variants"]["idiomatic"]["subjects"]
    stages = subjects[subject]["series"][approach]["stages"]
    return next(s for s in stages if s["label"] == stage)["locations"][location]


def test_every_subject_approach_and_stage_is_measured(report: Any) -> None:
    assert report["schema"] == "archmetrics.study/2"
    subjects = report["variants"]["idiomatic"]["subjects"]
    approaches = {s: sorted(v["series"]) for s, v in subjects.items()}
    assert approaches == {
        "wdb": ["p2p", "player", "soa"],
        "pragmatics": ["p2p", "player", "soa"],
        "legacy": ["soa"],
    }
    for subject in [*subjects.values(), *report["variants"]["as-described"]["subjects"].values()]:
        for series in subject["series"].values():
            assert [s["label"] for s in series["stages"]] == ["baseline", "first", "second"]
            baseline = series["stages"][0]
            assert baseline["base"] == "EMPTY" and baseline["locations"]["total"]["loc_pre"] == 0


def test_every_finding_has_a_verdict_from_measured_numbers(report: Any) -> None:
    assert [f["id"] for f in report["findings"]] == [f.id for f in FINDINGS]
    for finding in report["findings"]:
        assert {"id", "claim", "pages", "rule"} <= set(finding)
        assert sorted(finding["variants"]) == ["as-described", "idiomatic"]
        idiomatic = finding["variants"]["idiomatic"]
        assert idiomatic["agrees"] in (True, False)
        assert any(ch.isdigit() for ch in idiomatic["measured"])
        for variant in finding["variants"].values():
            assert set(variant) == {"agrees", "measured", "cause"}


def test_every_disagreement_names_a_recorded_cause_and_none_is_stale(report: Any) -> None:
    causes = load_causes()
    for finding in report["findings"]:
        for name, variant in finding["variants"].items():
            recorded = (finding["id"], name) in causes
            if variant["agrees"] is False:
                assert recorded, f"{finding['id']} ({name}) disagrees with no cause recorded"
                assert variant["cause"].startswith(causes[finding["id"], name].kind)
            else:
                assert not recorded, f"a cause is recorded for {finding['id']} ({name})"


def test_measured_shapes(report: Any) -> None:
    # WDB on the bus: after the baseline the client and the glue do not change their coupling
    for stage in ("first", "second"):
        for location in ("base", "framework"):
            s = _total(report, "wdb", "soa", stage, location)
            assert (s["delta_s_a"], s["delta_s_e"], s["delta_d_a"], s["delta_d_e"]) == (0, 0, 0, 0)
            assert s["delta_vg"] == 0 and s["cost"] == 0
    # the P2P baseline is built from socket calls: dynamic efferent coupling appears
    assert _total(report, "wdb", "p2p", "baseline", "framework")["delta_d_e"] >= 3
    # the legacy driver never changes: the new location is untouched after the baseline
    for stage in ("first", "second"):
        assert _total(report, "legacy", "soa", stage, "new")["changes"] == 0


def test_the_report_holds_to_its_schema(report: Any) -> None:
    """report.json against archmetrics/schemas/study-2.schema.json, as the package ships it;
    a report missing a verdict, with a verdict that is not one, or a stage without its total
    is refused."""
    text = (resources.files("archmetrics") / "schemas" / "study-2.schema.json").read_text()
    schema = json.loads(text)
    Draft202012Validator.check_schema(schema)
    validator = Draft202012Validator(schema)
    validator.validate(report)
    assert set(report["variants"]) == {"as-described", "idiomatic"}
    broken = [json.loads(json.dumps(report)) for _ in range(3)]
    del broken[0]["findings"][0]["variants"]["idiomatic"]["agrees"]
    broken[1]["findings"][0]["variants"]["idiomatic"]["agrees"] = "maybe"
    stages = broken[2]["variants"]["idiomatic"]["subjects"]["wdb"]["series"]["soa"]["stages"]
    del stages[0]["locations"]["total"]
    for document in broken:
        assert not validator.is_valid(document)


def test_report_and_charts_are_written(study: Path) -> None:
    markdown = (study / "report.md").read_text()
    assert "## Findings" in markdown and "## Subject `wdb`, idiomatic" in markdown
    charts = sorted((study / "charts" / "idiomatic").iterdir())
    for subject in ("wdb", "pragmatics", "legacy"):
        for kind in ("coupling", "scaled_changes", "scaled_complexity", "cost"):
            for fmt in ("png", "svg"):
                chart = study / "charts" / "idiomatic" / f"{subject}-{kind}.{fmt}"
                assert chart in charts and chart.stat().st_size > 5000
        assert f"charts/idiomatic/{subject}-cost.png" in markdown
    png = (study / "charts" / "idiomatic" / "wdb-cost.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"


def _base_plus_framework_cost(report: Any, subject: str, approach: str, stage: str) -> float:
    """E over base and framework together, from report.json's two location summaries by the
    thesis's equations (λ̂, v̂g from the summed sizes; E = Γ'/ΔVg', 0 when ΔVg' = 0)."""
    sides = [_total(report, subject, approach, stage, loc) for loc in ("base", "framework")]

    def summed(field: str) -> int:
        return sum(int(side[field]) for side in sides)

    changes, loc_pre, loc_post = summed("changes"), summed("loc_pre"), summed("loc_post")
    vg_pre, vg_post = summed("vg_pre"), summed("vg_post")
    scaled = changes * (loc_post / loc_pre if loc_pre else 1.0)
    delta_vg = (vg_post - vg_pre) * (vg_post / vg_pre if vg_pre else 1.0)
    return scaled / delta_vg if delta_vg else 0.0


def test_the_summary_charts_draw_the_findings_scope(study: Path, report: Any) -> None:
    """The ``*_total`` charts add up base + framework (where the findings are judged), say so,
    and show the values report.json's locations give for that scope."""
    from tests.reports.test_charts import svg_texts

    charts = study / "charts" / "idiomatic"
    for kind in ("coupling_total", "scaled_changes_total", "scaled_complexity_total", "cost_total"):
        texts = svg_texts((charts / f"pragmatics-{kind}.svg").read_bytes())
        assert any(", base + framework: p2p, player, soa" in t for t in texts), kind
        assert not any("new" in t for t in texts), kind  # the new location is not in them
    texts = svg_texts((charts / "pragmatics-cost_total.svg").read_bytes())
    labels = {t.rstrip("†‡§¶*#°") for t in texts}
    for approach in ("soa", "player", "p2p"):
        for stage in ("first", "second"):
            expected = _base_plus_framework_cost(report, "pragmatics", approach, stage)
            assert f"{expected:.2f}" in labels, (approach, stage, expected)


def test_the_repositories_have_a_tag_per_stage(built: tuple[Path, Path]) -> None:
    repo = built[1] / "idiomatic" / "wdb" / "soa"
    done = subprocess.run(["git", "-C", str(repo), "tag"], capture_output=True, text=True)
    assert sorted(done.stdout.split()) == ["baseline", "first", "second"]


def test_manifests_load_and_become_settings() -> None:
    manifests = find_manifests(subjects_root())
    assert sum(m.variant == "idiomatic" for m in manifests) == 7
    described = sorted((m.subject, m.approach) for m in manifests if m.variant == "as-described")
    assert described == sorted((m.subject, m.approach) for m in manifests
                               if m.variant == "idiomatic")  # fmt: skip
    assert all(len(m.follows) == len(m.stages) for m in manifests if m.variant == "as-described")
    wdb_soa = next(m for m in manifests if (m.subject, m.approach) == ("wdb", "soa"))
    settings = settings_for(wdb_soa)
    assert settings.locations.new == ("wdb/**",) and not settings.include_generated


HEAD = 'subject = "s"\napproach = "a"\nvariant = "idiomatic"\ntitle = "t"\n'


@pytest.mark.parametrize(
    ("text", "message"),
    [
        (f'{HEAD}stages = ["baseline"]\n', "has no folder"),
        ('approach = "a"\ntitle = "t"\nstages = []\n', "'subject' must be a non-empty string"),
        (f'{HEAD}stages = "x"\n', "stages: expected a list"),
        (f"{HEAD}stages = []\n[exclude]\ngenerated = 1\n", "exclude.generated: expected true"),
        ('subject = "s"\napproach = "a"\ntitle = "t"\nstages = []\n', "'variant' must be a"),
        (f"{HEAD.replace('idiomatic', 'literal')}stages = []\n", "variant must be one of"),
        (f'{HEAD.replace("idiomatic", "as-described")}stages = ["s"]\n', "stage.s: an as-desc"),
        (f'{HEAD}stages = ["s"]\n[stage.s]\nfollows = "x"\npage = "9"\n', "stage.s: 'page'"),
        (f'{HEAD}stages = ["s"]\n[stage.s]\npage = 9\n', "stage.s: 'follows' must be"),
        (f'{HEAD}stages = []\n[stage.t]\nfollows = "x"\npage = 9\n', "stage.t: no such stage"),
    ],
)
def test_bad_manifests_are_named(tmp_path: Path, text: str, message: str) -> None:
    (tmp_path / "manifest.toml").write_text(text)
    (tmp_path / "s").mkdir()
    with pytest.raises(ManifestError, match=message) as error:
        load_manifest(tmp_path)
    assert "manifest.toml" in str(error.value)


def test_an_unknown_subject_is_a_one_line_error(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["replicate", "--subject", "wdb", "--subject", "foo"]) == 2
    err = capsys.readouterr().err.strip()
    assert (
        err
        == "archmetrics: error: no study subject 'foo'; the subjects are: legacy, pragmatics, wdb"
    )


def test_the_appendix_lists_every_element_and_sums_to_the_locations(
    study: Path, report: Any
) -> None:
    """report.md's appendix (the thesis's appendices C-I): the framework elements of one stage
    add up to the framework location's change count and v_g in report.json."""
    markdown = (study / "report.md").read_text()
    appendix = markdown[markdown.index("## Appendix: every element") :]
    section = appendix[appendix.index("### `wdb`, idiomatic") :]
    section = section.split("\n### ")[0]
    rows = [
        [cell.strip() for cell in line.strip("|").split("|")]
        for line in section.splitlines()
        if line.startswith("| p2p | first |")
    ]
    framework = [row for row in rows if row[3] == "framework"]
    assert [row[2] for row in framework] == ["server/wdb-server"]  # element: the file, no suffix
    expected = _total(report, "wdb", "p2p", "first", "framework")
    assert sum(int(row[7]) + int(row[8]) + int(row[9]) for row in framework) == expected["changes"]
    assert sum(int(row[11]) - int(row[10]) for row in framework) == expected["delta_vg"]


@pytest.fixture(scope="module")
def wdb() -> StudyReport:
    """The study of the World Database subject alone, as a report value."""
    return run_replicate(ReplicateRequest(subjects_root(), ("wdb",)))


def test_the_terminal_summary_fits_100_columns_and_ends_with_the_headline(
    wdb: StudyReport,
) -> None:
    """Each finding with its two verdicts, the cheapest architecture stage by stage, and
    where the full report is, in lines of at most 100 characters."""
    text = findings_summary(wdb, load_causes(), Path("out"))
    lines = text.splitlines()
    assert max(len(line) for line in lines) <= 100, max(lines, key=len)
    for finding in FINDINGS:
        [line] = [x for x in lines if x.startswith(f"{finding.id} ")]
        words = [verdict_word(outcome(wdb, v, finding).verdict.agrees) for v in VARIANTS]
        assert [line[21:34].strip(), line[35:48].strip()] == words, line
    assert lines[-2:] == [
        "Full report (why each verdict differs, every figure): out/report.md",
        "and out/report.json; charts in out/charts",
    ]
    rows = [x.split(None, 2) for x in lines if x.startswith("  wdb ")]
    assert [r[1] for r in rows] == ["baseline", "first", "second"]
    for _, stage, cells in rows:
        for cell, result in zip(cells.split(" / "), wdb.variants, strict=True):
            costs = {a: summary(s, stage).cost for a, s in result.subjects[0].compare.series}
            named, cost = cell.rsplit(" ", 1)
            lowest = min(round(c, 2) for c in costs.values())
            assert float(cost) == lowest, (stage, cell, costs)
            tied = sorted(NAMES[a] for a, c in costs.items() if round(c, 2) == lowest)
            assert named.split("=") == tied, (stage, cell, costs)


def test_the_figures_docs_ci_quotes_are_the_study_s(report: Any) -> None:
    """docs/ci.md ("Choosing gates") explains E with the study's own numbers: each quoted
    figure is on the page and is what replicate measures."""
    page = (Path(__file__).resolve().parents[2] / "docs" / "ci.md").read_text("utf-8")
    page = " ".join(page.split())  # the page wraps its lines anywhere
    new = {stage: _total(report, "wdb", "soa", stage, "new") for stage in ("first", "second")}
    quoted = [
        (new["first"]["scaled_changes"], "Γ' = 27.44"),
        (new["first"]["scaled_delta_vg"], "ΔVg' = 14.76"),
        (new["first"]["cost"], "E = 1.86"),
        (new["second"]["scaled_changes"], "Γ' = 22.25"),
        (new["second"]["scaled_delta_vg"], "ΔVg' = 3.29"),
        (new["second"]["cost"], "E = 6.76"),
    ]
    assert new["second"]["delta_vg"] == 3
    totals = {a: _total(report, "wdb", a, "first", "total") for a in ("soa", "player", "p2p")}
    quoted += [(totals[a]["cost"], f"{e} ({name})")
               for a, e, name in (("soa", "2.22", "SOA"), ("player", "2.31", "Player"),
                                  ("p2p", "3.32", "P2P"))]  # fmt: skip
    quoted += [(totals[a]["scaled_changes"], f) for a, f in (("soa", "26.27"),
               ("player", "35.17"), ("p2p", "174.38"))]  # fmt: skip
    for value, text in quoted:
        assert text in page, text
        assert f"{value:.2f}" in text, (value, text)
    for location in ("base", "framework"):
        first = _total(report, "wdb", "soa", "first", location)
        assert (first["changes"], first["delta_vg"], first["cost"]) == (1, 0, 0.0)
