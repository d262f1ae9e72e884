"""The thesis's stated findings, each as a check on what we measured (never a hard-coded answer).

Every check reads the compared series of one subject and says whether our measurement agrees
with the thesis's words, and what it measured. The tolerances ("about", "near") are stated in
each rule and in docs/study.md, so a reader can disagree with them on the record.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass

from archmetrics.changeset.locations import Location
from archmetrics.changeset.model import Summary
from archmetrics.changeset.scope import scope_summary
from archmetrics.reports.model import CompareReport, DiffReport, SeriesReport

LATER = ("first", "second")  # the stages after the baseline


@dataclass(frozen=True, slots=True)
class Verdict:
    agrees: bool | None  # None: we could not measure it (an approach or stage is missing)
    measured: str


@dataclass(frozen=True, slots=True)
class Finding:
    id: str
    subject: str
    claim: str  # the thesis's words, condensed
    pages: str
    rule: str  # how we test it
    check: Callable[[Mapping[str, SeriesReport]], Verdict]


INTEGRATION = "integration"  # base + framework: the code an approach makes the integrator write


def integration_summary(report: DiffReport) -> Summary:
    """The chapter-6 summary over base and framework together.

    The new capability is the same code in every approach of a subject (the study's control),
    so claims about what an approach costs are tested on the code around it: the client
    (base) and what the approach supplies or requires (framework).
    """
    return scope_summary(report.change, (Location.BASE, Location.FRAMEWORK))


def summary(series: SeriesReport, stage: str, location: str = INTEGRATION) -> Summary:
    for s in series.stages:
        if s.label == stage:
            if location == INTEGRATION:
                return integration_summary(s.report)
            return s.report.summaries()[location]
    raise KeyError(stage)


def _fmt(value: float | None) -> str:
    return "n/a" if value is None else f"{value:g}" if isinstance(value, int) else f"{value:.2f}"


def _series(
    approaches: Sequence[str],
) -> Callable[..., Callable[[Mapping[str, SeriesReport]], Verdict]]:
    """Wrap a check so a missing approach or stage gives 'not measured' instead of an error."""

    def wrap(body: Callable[..., Verdict]) -> Callable[[Mapping[str, SeriesReport]], Verdict]:
        def check(found: Mapping[str, SeriesReport]) -> Verdict:
            try:
                return body(*(found[a] for a in approaches))
            except KeyError as missing:
                return Verdict(None, f"not measured: no {missing} in this study")

        return check

    return wrap


@_series(["soa"])
def _wdb_soa_coupling(soa: SeriesReport) -> Verdict:
    deltas = {
        stage: tuple(
            getattr(summary(soa, stage), f)
            for f in ("delta_s_a", "delta_s_e", "delta_d_a", "delta_d_e")
        )
        for stage in LATER
    }
    text = "; ".join(f"{st}: Δs_a, Δs_e, Δd_a, Δd_e = {d}" for st, d in deltas.items())
    return Verdict(all(v == 0 for d in deltas.values() for v in d), text)


@_series(["soa"])
def _wdb_soa_zero_cost(soa: SeriesReport) -> Verdict:
    """A high cost at the baseline (p. 120), zero in client and provider afterwards (p. 122)."""
    initial = summary(soa, "baseline").cost
    parts, ok = [f"baseline: E = {_fmt(initial)}"], initial > 0
    for stage in LATER:
        for loc in ("base", "framework"):
            s = summary(soa, stage, loc)
            ok = ok and s.delta_vg == 0 and s.cost == 0
            parts.append(f"{stage} {loc}: Γ = {s.changes}, ΔVg = {s.delta_vg}, E = {_fmt(s.cost)}")
    return Verdict(ok, "; ".join(parts))


@_series(["player"])
def _wdb_player_coupling(player: SeriesReport) -> Verdict:
    got = {st: (summary(player, st).delta_s_e, summary(player, st).delta_d_e) for st in LATER}
    text = "; ".join(f"{st}: Δs_e = {se}, Δd_e = {de}" for st, (se, de) in got.items())
    return Verdict(all(v == (1, 2) for v in got.values()), text)


@_series(["player"])
def _wdb_player_growth(player: SeriesReport) -> Verdict:
    got = {st: summary(player, st) for st in LATER}
    ok = all(30 <= s.changes <= 40 and 4.5 <= s.scaled_delta_vg <= 7.5 for s in got.values())
    text = "; ".join(
        f"{st}: Γ = {s.changes}, ΔVg' = {_fmt(s.scaled_delta_vg)}" for st, s in got.items()
    )
    return Verdict(ok, text)


@_series(["p2p"])
def _wdb_p2p_coupling(p2p: SeriesReport) -> Verdict:
    got = {st: summary(p2p, st).delta_d_e for st in LATER}
    return Verdict(
        all(v == 3 for v in got.values()), "; ".join(f"{st}: Δd_e = {v}" for st, v in got.items())
    )


def _largest(
    approach: str, field: str, stages: Sequence[str], found: Mapping[str, SeriesReport]
) -> tuple[bool, str]:
    ok, parts = True, []
    for stage in stages:
        values = {name: getattr(summary(s, stage), field) for name, s in found.items()}
        top = max(values.values(), key=lambda v: v if v is not None else float("-inf"))
        ok = ok and values[approach] == top
        parts.append(f"{stage} {field}: " + ", ".join(f"{n} {_fmt(v)}" for n, v in values.items()))
    return ok, "; ".join(parts)


def _wdb_p2p_grows_most(found: Mapping[str, SeriesReport]) -> Verdict:
    if "p2p" not in found or len(found) < 2:
        return Verdict(None, "not measured: needs p2p and another approach")
    size_ok, size = _largest("p2p", "scaled_changes", LATER, found)
    vg_ok, vg = _largest("p2p", "scaled_delta_vg", LATER, found)
    return Verdict(size_ok and vg_ok, f"{size}; {vg}")


def _prag_soa_largest_de(found: Mapping[str, SeriesReport]) -> Verdict:
    """ "Relatively large for both integration phases" (p. 132): above zero, and not below every
    other approach, at the first and the second stage."""
    if "soa" not in found or len(found) < 2:
        return Verdict(None, "not measured: needs soa and another approach")
    ok, parts = True, []
    for stage in LATER:
        values = {name: summary(s, stage).delta_d_e for name, s in found.items()}
        others = [v for name, v in values.items() if name != "soa"]
        ok = ok and values["soa"] > 0 and values["soa"] >= min(others)
        parts.append(f"{stage} Δd_e: " + ", ".join(f"{n} {v}" for n, v in values.items()))
    return Verdict(ok, "; ".join(parts))


def _costs(series: SeriesReport) -> dict[str, float]:
    return {s.label: summary(series, s.label).cost for s in series.stages}


def _costs_text(e: Mapping[str, float]) -> str:
    return ", ".join(f"E({k}) = {_fmt(v)}" for k, v in e.items())


# One tolerance for every unquantified word of the thesis about E: "relatively constant"
# (p. 133) and "near constant" (p. 142) mean within NEAR of each other; "large jump" (p. 135),
# "drop sharply" (p. 135) and "increases significantly" (p. 135) mean a change beyond it.
# docs/study.md, "How the thresholds were chosen", says what was known of the results when
# each threshold was chosen and what the verdicts would be under the readings they replace.
NEAR = 1.25


def near(a: float, b: float) -> bool:
    """Whether two values of E are near constant: the larger within NEAR of the smaller."""
    low, high = sorted((a, b))
    return high <= NEAR * low


@_series(["soa"])
def _prag_soa_constant_cost(soa: SeriesReport) -> Verdict:
    """Significant at the baseline, never rising beyond near constant afterwards (p. 142), and
    "relatively constant" over the message additions (p. 133)."""
    e = _costs(soa)
    ok = (
        min(e.values()) > 0 and e["first"] <= NEAR * e["baseline"] and near(e["first"], e["second"])
    )
    return Verdict(ok, _costs_text(e))


@_series(["player"])
def _prag_player_jump(player: SeriesReport) -> Verdict:
    e = _costs(player)
    ok = e["first"] > NEAR * e["baseline"] and NEAR * e["second"] < e["first"]
    return Verdict(ok, _costs_text(e))


def _prag_p2p_high_rising(found: Mapping[str, SeriesReport]) -> Verdict:
    if "p2p" not in found or len(found) < 2:
        return Verdict(None, "not measured: needs p2p and another approach")
    e = _costs(found["p2p"])
    highest, text = _largest("p2p", "cost", ("second",), found)
    ok = e["second"] > NEAR * e["first"] and highest
    return Verdict(ok, _costs_text(e) + f"; {text}")


@_series(["soa"])
def _legacy_soa_cost(soa: SeriesReport) -> Verdict:
    """ "The initial complexity change cost is large": no later stage above the baseline; "but
    decreases or stabilizes at a near constant value": the second stage falls below the first
    or stays near it (p. 142)."""
    e = _costs(soa)
    initial_large = e["baseline"] > 0 and max(e["first"], e["second"]) <= e["baseline"]
    settles = e["second"] <= e["first"] or near(e["first"], e["second"])
    return Verdict(initial_large and settles, _costs_text(e))


FINDINGS: tuple[Finding, ...] = (
    Finding(
        "wdb-soa-coupling",
        "wdb",
        "SOA: the coupling does not change",
        "119",
        "Δs_a = Δs_e = Δd_a = Δd_e = 0 in base + framework at the first and second stages",
        _wdb_soa_coupling,
    ),
    Finding(
        "wdb-soa-cost",
        "wdb",
        "SOA: a high cost for the baseline, then a zero complexity change cost (the added lines"
        " are sequential)",
        "120, 122",
        "E(baseline) > 0 in base + framework; ΔVg = 0 and E = 0 in base and in framework at the"
        " first and second stages",
        _wdb_soa_zero_cost,
    ),
    Finding(
        "wdb-player-coupling",
        "wdb",
        "Player: each added message gives +1 static and +2 dynamic efferent coupling",
        "119-120",
        "Δs_e = 1 and Δd_e = 2 in base + framework at the first and second stages",
        _wdb_player_coupling,
    ),
    Finding(
        "wdb-player-growth",
        "wdb",
        "Player: the code grows by 30 to 40 lines a stage with a scaled complexity of around 6",
        "122",
        "30 ≤ Γ ≤ 40 and 4.5 ≤ ΔVg' ≤ 7.5 in base + framework at the first and second stages",
        _wdb_player_growth,
    ),
    Finding(
        "wdb-p2p-coupling",
        "wdb",
        "P2P: each new message adds an accept, send and recv: a constant +3 dynamic efferent",
        "120",
        "Δd_e = 3 in base + framework at the first and second stages",
        _wdb_p2p_coupling,
    ),
    Finding(
        "wdb-p2p-growth",
        "wdb",
        "P2P: size and complexity grow significantly with each integration",
        "122-123",
        "P2P's Γ' and ΔVg' in base + framework are the largest of the approaches (ties allowed)"
        " at the first and second stages",
        _wdb_p2p_grows_most,
    ),
    Finding(
        "prag-soa-coupling",
        "pragmatics",
        "SOA: the dynamic efferent coupling is relatively large for both integration phases",
        "132",
        "SOA's Δd_e in base + framework is > 0 and not below every other approach's, at the"
        " first and second stages",
        _prag_soa_largest_de,
    ),
    Finding(
        "prag-soa-cost",
        "pragmatics",
        "SOA: significant complexity, and E relatively constant over the stages; like the"
        " other SOA integrations, large at first, then decreasing or stable",
        "133, 142",
        "in base + framework, E > 0 at every stage, E(first) ≤ 1.25·E(baseline), and E(first)"
        " and E(second) within 1.25x of each other",
        _prag_soa_constant_cost,
    ),
    Finding(
        "prag-player-cost",
        "pragmatics",
        "Player: a large jump in E at the first stage, then a sharp drop",
        "133-135",
        "in base + framework, E(first) > 1.25·E(baseline) and 1.25·E(second) < E(first)",
        _prag_player_jump,
    ),
    Finding(
        "prag-p2p-cost",
        "pragmatics",
        "P2P: E is high and increases significantly after the second message is added",
        "135",
        "in base + framework, E(second) > 1.25·E(first), and P2P's E(second) is the largest"
        " of the approaches",
        _prag_p2p_high_rising,
    ),
    Finding(
        "legacy-soa-cost",
        "legacy",
        "SOA: the initial E is large but decreases or stabilizes at a near constant value",
        "142",
        "in base + framework, E(baseline) > 0 and no later stage above it; E(second) ≤ E(first)"
        " or within 1.25x of it",
        _legacy_soa_cost,
    ),
)


@dataclass(frozen=True, slots=True)
class Outcome:
    finding: Finding
    verdict: Verdict


def check_findings(subjects: Mapping[str, CompareReport]) -> tuple[Outcome, ...]:
    """Every finding whose subject was measured, with its verdict."""
    outcomes = []
    for finding in FINDINGS:
        report = subjects.get(finding.subject)
        if report is None:
            outcomes.append(Outcome(finding, Verdict(None, "not measured: subject not in study")))
            continue
        outcomes.append(Outcome(finding, finding.check(dict(report.series))))
    return tuple(outcomes)
