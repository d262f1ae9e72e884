"""The study's report: per variant and subject the approaches compared, and the findings checked
on both variants side by side, each disagreement with its recorded cause."""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from archmetrics.changeset.model import Metrics
from archmetrics.reports import diff_rows
from archmetrics.reports.json_report import compare_dict
from archmetrics.reports.markdown_report import table
from archmetrics.reports.model import CompareReport
from archmetrics.study.causes import Cause
from archmetrics.study.findings import FINDINGS, Finding, Outcome
from archmetrics.study.manifest import VARIANTS, Manifest

STUDY_SCHEMA = "archmetrics.study/2"


@dataclass(frozen=True, slots=True)
class SubjectResult:
    subject: str
    manifests: tuple[Manifest, ...]
    compare: CompareReport


@dataclass(frozen=True, slots=True)
class VariantResult:
    variant: str  # "as-described" or "idiomatic"
    subjects: tuple[SubjectResult, ...]
    outcomes: tuple[Outcome, ...]  # one per finding, in FINDINGS order


@dataclass(frozen=True, slots=True)
class StudyReport:
    variants: tuple[VariantResult, ...]  # in VARIANTS order


def verdict_word(agrees: bool | None) -> str:
    return {True: "agrees", False: "DISAGREES", None: "not measured"}[agrees]


def outcome(report: StudyReport, variant: str, finding: Finding) -> Outcome:
    result = next(v for v in report.variants if v.variant == variant)
    return next(o for o in result.outcomes if o.finding.id == finding.id)


def cause_text(o: Outcome, variant: str, causes: Mapping[tuple[str, str], Cause]) -> str:
    """The recorded cause beside a disagreement; nothing beside an agreement or no verdict."""
    if o.verdict.agrees is True:
        return ""
    if o.verdict.agrees is None:
        return ""  # "measured" says why nothing was measured
    cause = causes.get((o.finding.id, variant))
    return cause.describe() if cause else "not yet analysed (no cause recorded)"


def why_they_differ(
    report: StudyReport, finding: Finding, causes: Mapping[tuple[str, str], Cause]
) -> str:
    """Where the variants' verdicts differ, the cause on the side that disagrees."""
    verdicts = {v: outcome(report, v, finding).verdict.agrees for v in VARIANTS}
    if None in verdicts.values():
        return "only one variant measured"
    if len(set(verdicts.values())) == 1:
        return "same verdict"
    side = next(v for v, agrees in verdicts.items() if agrees is False)
    cause = causes.get((finding.id, side))
    return f"{side} disagrees: " + (cause.describe() if cause else "no cause recorded")


FINDINGS_HEADER = ("finding", "thesis says (page)", "as described", "idiomatic", "why they differ")


def findings_rows(report: StudyReport, causes: Mapping[tuple[str, str], Cause]) -> list[list[str]]:
    return [
        [
            f.id,
            f"{f.claim} (p. {f.pages})",
            *(verdict_word(outcome(report, v, f).verdict.agrees) for v in VARIANTS),
            why_they_differ(report, f, causes),
        ]
        for f in FINDINGS
    ]


def agreements(report: StudyReport) -> dict[str, int]:
    return {v.variant: sum(o.verdict.agrees is True for o in v.outcomes) for v in report.variants}


def _subjects_dict(result: VariantResult) -> dict[str, Any]:
    subjects: dict[str, Any] = {}
    for r in result.subjects:
        subjects[r.subject] = {
            "approaches": {
                m.approach: {
                    "title": m.title,
                    "thesis_pages": m.thesis_pages,
                    "stages": list(m.stages),
                    "follows": {
                        f.stage: {"sentence": f.sentence, "page": f.page} for f in m.follows
                    },
                    "locations": {k: list(v) for k, v in m.locations},
                    "exclude": list(m.exclude),
                }
                for m in r.manifests
            },
            **compare_dict(r.compare),
        }
        subjects[r.subject].pop("schema", None)
    return subjects


def render_json(report: StudyReport, causes: Mapping[tuple[str, str], Cause]) -> str:
    document: dict[str, Any] = {
        "schema": STUDY_SCHEMA,
        "variants": {v.variant: {"subjects": _subjects_dict(v)} for v in report.variants},
        "findings": [
            {
                "id": f.id,
                "subject": f.subject,
                "claim": f.claim,
                "pages": f.pages,
                "rule": f.rule,
                "variants": {
                    v: {
                        "agrees": (o := outcome(report, v, f)).verdict.agrees,
                        "measured": o.verdict.measured,
                        "cause": cause_text(o, v, causes),
                    }
                    for v in VARIANTS
                },
                "why_they_differ": why_they_differ(report, f, causes),
            }
            for f in FINDINGS
        ],
    }
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def _measured_rows(report: StudyReport, causes: Mapping[tuple[str, str], Cause]) -> list[list[str]]:
    rows = []
    for f in FINDINGS:
        for v in VARIANTS:
            o = outcome(report, v, f)
            rows.append(
                [
                    f.id,
                    v,
                    f.rule,
                    o.verdict.measured,
                    verdict_word(o.verdict.agrees),
                    cause_text(o, v, causes),
                ]
            )
    return rows


APPENDIX_HEADER = (
    "approach",
    "stage",
    "element",
    "location",
    "status",
    "λ_pre",
    "λ_post",
    "added",
    "removed",
    "modified",
    "v_g pre",
    "v_g post",
    "s_a",
    "s_e",
    "d_a",
    "d_e",
)


def appendix_rows(compare: CompareReport) -> list[list[str]]:
    """Every element of every approach and stage (the thesis's appendices C-I): its change set,
    its size and complexity before and after, and its coupling after (before, if removed).
    Elements that are empty and unchanged are left out."""
    rows = []
    for approach, series in compare.series:
        for stage in series.stages:
            for e in stage.report.change.elements:
                pre, post = e.pre or Metrics(), e.post or Metrics()
                if e.status.value == "unchanged" and post.loc == 0:
                    continue
                coupling = post if e.post is not None else pre
                rows.append(
                    [
                        approach,
                        stage.label,
                        e.element,
                        e.location.value,
                        e.status.value,
                        *map(
                            str,
                            (
                                pre.loc,
                                post.loc,
                                e.added,
                                e.removed,
                                e.modified,
                                pre.vg,
                                post.vg,
                                coupling.s_a,
                                coupling.s_e,
                                coupling.d_a,
                                coupling.d_e,
                            ),
                        ),
                    ]
                )
    return rows


def render_markdown(
    report: StudyReport, causes: Mapping[tuple[str, str], Cause], charts: dict[str, list[str]]
) -> str:
    """report.md: the findings on both variants, then per variant and subject the trend table
    and its charts (``charts`` maps "<variant>/<subject>" to the chart files)."""
    counts = agreements(report)
    parts = [
        "# archmetrics: the thesis's study, replicated\n",
        "Of the 11 stated findings, "
        + " and ".join(f"{counts.get(v, 0)} agree on the {v} subjects" for v in VARIANTS)
        + ". *As described*: subjects whose every stage follows a sentence of the thesis about "
        "the code it measured; *idiomatic*: the same integrations written the way each framework "
        "is usually written. Every number comes from `archmetrics series` on a git repository "
        "built from `fixtures/study/` (a commit and tag per stage).\n",
        "## Findings\n",
        table(list(FINDINGS_HEADER), findings_rows(report, causes)),
        "## What was measured, and why a finding disagrees\n",
        table(
            ["finding", "variant", "tested as", "we measured", "verdict", "cause"],
            _measured_rows(report, causes),
        ),
    ]
    for result in report.variants:
        for r in result.subjects:
            parts.append(f"## Subject `{r.subject}`, {result.variant}\n")
            for m in r.manifests:
                parts.append(f"- **{m.approach}**: {m.title} (thesis pp. {m.thesis_pages})")
                for f in m.follows:
                    parts.append(f'  - {f.stage} follows p. {f.page}: "{f.sentence}"')
            parts.append("")
            rows = diff_rows.compare_rows(r.compare)
            parts.append(table(list(diff_rows.TREND_HEADER), rows, "lll" + "r" * 10))
            images = charts.get(f"{result.variant}/{r.subject}", [])
            if images:
                parts.append(
                    "Charts: by location, and the summaries (`*_total`) over base + framework,"
                    " the scope the findings are judged on.\n"
                )
            for image in images:
                parts.append(f"![{image}](charts/{image})\n")
    parts.append("## Appendix: every element, stage by stage\n")
    parts.append(
        "The thesis's appendices C-I, per variant, subject, approach and stage: each element's "
        "change set (statements added, removed, modified), logical lines λ and McCabe v_g "
        "before and after, and its coupling after the stage. The location rows above sum "
        "these; report.json has the same under each stage's `elements`.\n"
    )
    for result in report.variants:
        for r in result.subjects:
            parts.append(f"### `{r.subject}`, {result.variant}\n")
            parts.append(table(list(APPENDIX_HEADER), appendix_rows(r.compare), "l" * 5 + "r" * 11))
    return "\n".join(parts)
