"""JSON: the machine-readable contract (versioned by its ``schema`` field; see docs/json.md)."""

from __future__ import annotations

import heapq
import json
import re
from collections.abc import Collection, Iterable, Mapping
from operator import itemgetter
from typing import Any

from archmetrics import __version__
from archmetrics.changeset.accuracy import Accuracy
from archmetrics.changeset.gates import (
    UNMEASURED_GATE,
    UnmeasuredFailure,
    is_unit_gate,
    measured_values,
    parse_gate,
)
from archmetrics.changeset.model import ChangeReport, Summary
from archmetrics.complexity import FileMetrics, Totals
from archmetrics.complexity.thresholds import ThresholdFailure
from archmetrics.facts import ParseWarning
from archmetrics.reports import coupling_rows
from archmetrics.reports.model import (
    COMPARE_SCHEMA,
    DIFF_SCHEMA,
    ESTIMATE_SCHEMA,
    SCAN_SCHEMA,
    SERIES_SCHEMA,
    CompareReport,
    DiffReport,
    EstimateReport,
    ScanReport,
    SeriesReport,
)


def warning_dict(warning: ParseWarning) -> dict[str, Any]:
    return {
        "path": warning.path,
        "line": warning.line,
        "severity": str(warning.severity),
        "message": warning.message,
    }


def _file(metrics: FileMetrics) -> dict[str, Any]:
    return {
        "path": metrics.path,
        "language": metrics.language,
        "loc": metrics.loc,
        "sloc": metrics.sloc,
        "vg": metrics.vg,
        "parsed": metrics.parsed,
        "generated": metrics.generated,
        "functions": [
            {
                "name": f.name,
                "qualified_name": f.qualified_name,
                "line": f.line,
                "end_line": f.end_line,
                "loc": f.loc,
                "vg": f.vg,
            }
            for f in metrics.functions
        ],
        "warnings": [warning_dict(w) for w in metrics.warnings],
    }


def totals_dict(totals: Totals) -> dict[str, Any]:
    return {
        "files": totals.files,
        "functions": totals.functions,
        "loc": totals.loc,
        "sloc": totals.sloc,
        "vg": totals.vg,
        "warnings": totals.warnings,
        "unparsed": totals.unparsed,
    }


def scan_dict(report: ScanReport) -> dict[str, Any]:
    return {
        "schema": SCAN_SCHEMA,
        "root": report.root,
        "revision": report.revision,
        "files": [_file(f) for f in report.files],
        "totals": totals_dict(report.totals),
        "elements": coupling_rows.elements_json(report),
        "excluded": [x.to_dict() for x in report.excluded],
        "gates": [unit_gate(gate, report) for gate in report.gates],
        "notes": list(report.notes),
    }


def _units(failures: Iterable[ThresholdFailure], gate: str) -> list[dict[str, Any]]:
    return [
        {
            "name": f.unit.name,
            "path": f.unit.path,
            "line": f.unit.line,
            "values": {field: f.unit.values[field] for field in f.threshold.fields},
        }
        for f in failures
        if f.threshold.text == gate
    ]


def unit_gate(gate: str, report: ScanReport | DiffReport) -> dict[str, Any]:
    """A threshold's (a unit gate's) entry: whether it failed, every unit that failed it,
    and those a suppression comment exempts or the baseline knows (listed, not failing)."""
    failures = report.failures if isinstance(report, ScanReport) else report.offenders
    return {
        "gate": gate,
        "failed": any(f.threshold.text == gate for f in failures),
        "failures": _units(failures, gate),
        "suppressed": _units(report.suppressed, gate),
        "baselined": _units(report.baselined, gate),
    }


_UNPRINTABLE = re.compile(r"[\x7f-\x9f\u2028\u2029\ud800-\udfff]")

_DIGITS = frozenset("0123456789")


def short_exponent(text: str) -> bool:
    """Whether ``text`` holds a digit, ``e-``, and one digit alone (``[0-9]e-[0-9](?![0-9])``):
    where orjson's float spelling differs from json's, a one-digit negative exponent (1e-7 is
    json's 1e-07); json switches to exponents only from 1e16 up, which both spell alike.
    Found by looking at each ``e-`` (``str.find``): a regular expression starting with a
    character class tried every character of a scan's 6 MB of JSON (0.03 s)."""
    at = text.find("e-", 1)
    while at >= 0:
        if (
            text[at - 1] in _DIGITS
            and text[at + 2 : at + 3] in _DIGITS
            and text[at + 3 : at + 4] not in _DIGITS
        ):
            return True
        at = text.find("e-", at + 1)
    return False


def _indented(document: dict[str, Any]) -> str:
    """``json.dumps(document, indent=2, ensure_ascii=False)`` and a newline, byte for byte,
    written by orjson in C (json's indenting encoder is pure Python: a 28,000-element diff
    took seconds). What orjson cannot write as json would (a lone surrogate, an integer past
    64 bits, a float such as 1e-07) is left to json."""
    import orjson

    try:
        text = orjson.dumps(document, option=orjson.OPT_INDENT_2 | orjson.OPT_APPEND_NEWLINE)
    except TypeError:  # orjson.JSONEncodeError
        return json.dumps(document, indent=2, ensure_ascii=False) + "\n"
    written = text.decode()
    if short_exponent(written):
        return json.dumps(document, indent=2, ensure_ascii=False) + "\n"
    return written


def dumps(document: dict[str, Any]) -> str:
    """The document as JSON text. ``json`` escapes C0 controls itself; DEL, C1 controls, line
    separators and lone surrogates are escaped here too (``\\u0085``), so the text is valid
    UTF-8 and safe to print (docs/security.md)."""
    text = _indented(document)
    if text.isascii() and "\x7f" not in text:  # nothing to escape (both checks in C, fast)
        return text
    return _UNPRINTABLE.sub(lambda found: f"\\u{ord(found.group()):04x}", text)


def render_scan(report: ScanReport) -> str:
    return dumps(scan_dict(report))


def diff_dict(report: DiffReport) -> dict[str, Any]:
    failed = {f.gate.text for f in report.failures}
    summaries = report.summaries()
    return {
        "schema": DIFF_SCHEMA,
        "base": report.base,
        "head": report.head,
        "locations": {name: s.to_dict() for name, s in summaries.items()},
        "elements": element_records(report.change),
        "excluded": [x.to_dict() for x in report.change.excluded],
        "warnings": [warning_dict(w) for w in report.warnings],
        "gates": [_gate_record(g, report, failed, summaries) for g in report.gates],
        "base_commit": report.commits[0],
        "head_commit": report.commits[1],
        "tool": {"name": "archmetrics", "version": __version__},
        "unmeasured": [
            {"path": path, "reason": why}
            for failure in report.failures
            if isinstance(failure, UnmeasuredFailure)
            for path, why in failure.files
        ],
    }


def _gate_record(
    gate: str, report: DiffReport, failed: Collection[str], summaries: Mapping[str, Summary]
) -> dict[str, Any]:
    """A diff gate's entry: a unit gate's units, a location gate's measured values, the
    implicit unmeasured(head) gate's count of files left unmeasured."""
    if is_unit_gate(gate):
        return {**unit_gate(gate, report), "values": {}}
    if gate == UNMEASURED_GATE:
        left = sum(len(f.files) for f in report.failures if isinstance(f, UnmeasuredFailure))
        return {"gate": gate, "failed": gate in failed, "values": {"unmeasured(head)": left}}
    return {"gate": gate, "failed": gate in failed, "values": gate_values(gate, summaries)}


def gate_values(text: str, summaries: Mapping[str, Summary]) -> dict[str, float | None]:
    """What each condition of the gate ``text`` measured (``FIELD(LOCATION)``: value)."""
    return measured_values(parse_gate(text), summaries)


def element_records(change: ChangeReport) -> list[dict[str, Any]]:
    """Every element's record, sorted by name: the unchanged elements a report keeps as
    columns written from them (``PlainElements.records``), without making their change
    sets (in a large tree with one file changed, nearly all of them)."""
    if not change.plain:
        return [e.to_dict() for e in change.elements]
    made = [(e.element, e.to_dict()) for e in change.computed]
    kept = zip(change.plain.names, change.plain.records(), strict=True)
    return [record for _, record in heapq.merge(made, kept, key=itemgetter(0))]


def render_diff(report: DiffReport) -> str:
    return dumps(diff_dict(report))


def series_dict(report: SeriesReport) -> dict[str, Any]:
    stages = []
    for stage in report.stages:
        document = diff_dict(stage.report)
        del document["schema"]
        stages.append({"label": stage.label, **document})
    return {"schema": SERIES_SCHEMA, "repo": report.repo, "stages": stages}


def render_series(report: SeriesReport) -> str:
    return dumps(series_dict(report))


def compare_dict(report: CompareReport) -> dict[str, Any]:
    series = {}
    for name, one in report.series:
        document = series_dict(one)
        del document["schema"]
        series[name] = document
    return {"schema": COMPARE_SCHEMA, "series": series}


def render_compare(report: CompareReport) -> str:
    return dumps(compare_dict(report))


def estimate_dict(report: EstimateReport) -> dict[str, Any]:
    """Each architecture's stages as the diff JSON has them, and the ranking; ``estimate``
    is always true: these are planned or sketched figures, not the integration measured."""
    architectures = {}
    for architecture in report.architectures:
        document = series_dict(architecture.series)
        architectures[architecture.name] = {
            "kind": architecture.kind,
            "description": architecture.description,
            "stages": document["stages"],
        }
    failed = {(f.architecture, f.stage, f.failure.gate.text) for f in report.failures}
    return {
        "schema": ESTIMATE_SCHEMA,
        "estimate": True,
        "plan": report.plan,
        "base": report.base,
        "architectures": architectures,
        "ranking": [
            {
                "stage": r.stage,
                "rank": r.rank,
                "architecture": r.architecture,
                "cost": r.cost,
                "scaled_changes": r.scaled_changes,
                "scaled_delta_vg": r.scaled_delta_vg,
            }
            for r in report.ranking()
        ],
        "failures": [{"architecture": a, "stage": s, "gate": g} for a, s, g in sorted(failed)],
    }


def _figures(place: Accuracy) -> dict[str, Any]:
    return {
        f.figure: {
            "estimated": f.estimated,
            "actual": f.actual,
            "error": f.error,
            "relative": f.relative,
        }
        for f in place.figures
    }


def accuracy_dict(report: EstimateReport) -> dict[str, Any]:
    """--actual: the measured change, and per architecture every figure's error."""
    assert report.actual is not None
    actual = diff_dict(report.actual)
    del actual["schema"]
    accuracy = {
        name: {
            "locations": {place.name: _figures(place) for place in found.locations},
            "elements": [
                {"element": e.name, "location": e.location, "figures": _figures(e)}
                for e in found.elements
            ],
        }
        for name, found in report.accuracy
    }
    return {"actual": actual, "accuracy": accuracy}


def render_estimate(report: EstimateReport) -> str:
    document = estimate_dict(report)
    if report.actual is not None:
        document.update(accuracy_dict(report))
    return dumps(document)
