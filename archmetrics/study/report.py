"""The study's report: per subject the approaches compared, and the findings checked."""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from archmetrics.reports import diff_rows
from archmetrics.reports.json_report import compare_dict
from archmetrics.reports.markdown_report import table
from archmetrics.reports.model import CompareReport
from archmetrics.study.findings import Outcome
from archmetrics.study.manifest import Manifest

STUDY_SCHEMA = "archmetrics.study/1"


@dataclass(frozen=True, slots=True)
class SubjectResult:
    subject: str
    manifests: tuple[Manifest, ...]
    compare: CompareReport


@dataclass(frozen=True, slots=True)
class StudyReport:
    subjects: tuple[SubjectResult, ...]
    outcomes: tuple[Outcome, ...]


def verdict_word(agrees: bool | None) -> str:
    return {True: "agrees", False: "DISAGREES", None: "not measured"}[agrees]


def findings_rows(report: StudyReport) -> list[list[str]]:
    return [
        [
            o.finding.id,
            f"{o.finding.claim} (p. {o.finding.pages})",
            o.finding.rule,
            o.verdict.measured,
            verdict_word(o.verdict.agrees),
        ]
        for o in report.outcomes
    ]


FINDINGS_HEADER = ("finding", "the thesis says", "tested as", "we measured", "verdict")


def render_json(report: StudyReport) -> str:
    document: dict[str, Any] = {
        "schema": STUDY_SCHEMA,
        "subjects": {
            r.subject: {
                "approaches": {
                    m.approach: {
                        "title": m.title,
                        "thesis_pages": m.thesis_pages,
                        "stages": list(m.stages),
                        "locations": {k: list(v) for k, v in m.locations},
                        "exclude": list(m.exclude),
                    }
                    for m in r.manifests
                },
                **compare_dict(r.compare),
            }
            for r in report.subjects
        },
        "findings": [
            {
                "id": o.finding.id,
                "subject": o.finding.subject,
                "claim": o.finding.claim,
                "pages": o.finding.pages,
                "rule": o.finding.rule,
                "measured": o.verdict.measured,
                "agrees": o.verdict.agrees,
            }
            for o in report.outcomes
        ],
    }
    for subject in document["subjects"].values():
        subject.pop("schema", None)
    return json.dumps(document, indent=2, ensure_ascii=False) + "\n"


def render_markdown(report: StudyReport, charts: dict[str, list[str]]) -> str:
    """report.md: findings first, then per subject the trend table and its charts."""
    agree = sum(o.verdict.agrees is True for o in report.outcomes)
    parts = [
        "# archmetrics: the thesis's study, replicated\n",
        f"{agree} of {len(report.outcomes)} stated findings agree with what we measured on the "
        "bundled subjects. Every number below comes from `archmetrics series` on a git "
        "repository built from `fixtures/study/` (a commit and tag per stage).\n",
        "## Findings\n",
        table(list(FINDINGS_HEADER), findings_rows(report)),
    ]
    for result in report.subjects:
        parts.append(f"## Subject `{result.subject}`\n")
        for m in result.manifests:
            parts.append(f"- **{m.approach}**: {m.title} (thesis pp. {m.thesis_pages})")
        parts.append("")
        rows = diff_rows.compare_rows(result.compare)
        parts.append(table(list(diff_rows.TREND_HEADER), rows, "lll" + "r" * 10))
        for image in charts.get(result.subject, []):
            parts.append(f"![{image}](charts/{image})\n")
    return "\n".join(parts)
