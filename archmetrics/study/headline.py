"""The study's headline: which architecture integrated at the lowest complexity change cost
E, stage by stage, for each subject and variant (E over base + framework, the code an
approach makes the integrator write: the scope the findings are judged in)."""

from __future__ import annotations

from dataclasses import dataclass

from archmetrics.study.findings import FINDINGS, summary
from archmetrics.study.report import StudyReport

NAMES = {"soa": "SOA", "player": "Player", "p2p": "P2P"}


@dataclass(frozen=True, slots=True)
class Cheapest:
    """The approaches with the lowest E at one stage (several when they tie), and that E."""

    approaches: tuple[str, ...]
    cost: float
    compared: int  # how many approaches were measured at this stage

    def __str__(self) -> str:
        names = "=".join(NAMES.get(a, a) for a in self.approaches)
        return f"{names} {self.cost:.2f}" + ("" if self.compared > 1 else " (only)")


@dataclass(frozen=True, slots=True)
class HeadlineRow:
    subject: str
    stage: str
    cheapest: tuple[Cheapest | None, ...]  # one per variant, in the report's order


def headline(report: StudyReport) -> list[HeadlineRow]:
    """For every subject and stage (in the report's order), each variant's cheapest approach."""
    found: dict[tuple[str, str], list[Cheapest | None]] = {}
    for number, variant in enumerate(report.variants):
        for result in variant.subjects:
            costs: dict[str, dict[str, float]] = {}
            for approach, series in result.compare.series:
                for label in (s.label for s in series.stages):
                    costs.setdefault(label, {})[approach] = summary(series, label).cost
            for label, by_approach in costs.items():
                row = found.setdefault((result.subject, label), [None] * len(report.variants))
                row[number] = _cheapest(by_approach)
    order = {subject: n for n, subject in enumerate(dict.fromkeys(f.subject for f in FINDINGS))}
    rows = [HeadlineRow(subject, stage, tuple(row)) for (subject, stage), row in found.items()]
    return sorted(rows, key=lambda r: order.get(r.subject, len(order)))  # the thesis's order


def _cheapest(costs: dict[str, float]) -> Cheapest | None:
    if not costs:
        return None
    lowest = min(round(cost, 2) for cost in costs.values())
    tied = tuple(sorted(a for a, cost in costs.items() if round(cost, 2) == lowest))
    return Cheapest(tied, lowest, len(costs))
