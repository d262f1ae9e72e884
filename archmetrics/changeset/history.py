"""A history of change sets: each commit measured against its first parent, and what the
whole range says per element (pure).

A :class:`CommitStep` holds what ``diff --base C^ --head C`` reports of one commit: its
summaries per location and in total, and the elements whose change set is not empty or
whose metrics moved. Its record (:func:`step_record`, :func:`step_from_record`) is what the
facts cache keeps per commit; the cache is not trusted, so reading a record checks every
field and gives None for anything this module did not write.

Per element over the range (docs/metrics.md, "History"): Γ'_e = λ̂(L)·Γ_e and
ΔVg'_e = v̂g(L)·ΔVg_e with the scale factors of the element's location in that commit (eqs.
6.21, 6.34), summed over the commits; the element's cumulative E is ΣΓ'_e / ΣΔVg'_e, 0 when
ΣΔVg'_e = 0 (eqs. 6.36-6.38, read per element).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from archmetrics.changeset.locations import Location
from archmetrics.changeset.model import (
    SUMMARY_FIELDS,
    ChangeReport,
    ElementChange,
    JsonValue,
    Metrics,
    Status,
    Summary,
)

STEP_RECORD = "history-step/1"
LOCATION_KEYS = ("base", "new", "framework", "total")
_FLOATS = frozenset({"loc_scale", "scaled_changes", "vg_scale", "scaled_delta_vg", "cost"})
_OPTIONAL = frozenset({"loc_scale", "vg_scale"})


@dataclass(frozen=True, slots=True)
class CommitStep:
    """One commit against its first parent: ``summaries`` keyed base, new, framework,
    total; ``elements``: the change sets that are not empty or whose metrics moved, by
    name (their ``files`` kept, their file changes not)."""

    summaries: Mapping[str, Summary]
    elements: tuple[ElementChange, ...]


def commit_step(change: ChangeReport) -> CommitStep:
    """What a history keeps of one commit's change report."""
    summaries = {loc.value: summary for loc, summary in change.locations}
    summaries["total"] = change.total
    moved = tuple(
        e._replace(file_changes=())
        for e in change.computed
        if e.status is not Status.UNCHANGED or e.pre != e.post
    )
    return CommitStep(summaries, moved)


def step_record(step: CommitStep) -> dict[str, JsonValue]:
    return {
        "schema": STEP_RECORD,
        "locations": {key: step.summaries[key].to_dict() for key in LOCATION_KEYS},
        "elements": [e.to_dict() for e in step.elements],
    }


def step_from_record(record: object) -> CommitStep | None:
    """The step ``record`` holds, or None when it is not one :func:`step_record` wrote."""
    try:
        if not isinstance(record, dict) or record.get("schema") != STEP_RECORD:
            return None
        locations = _mapping(record["locations"])
        summaries = {key: summary_from_dict(_mapping(locations[key])) for key in LOCATION_KEYS}
        elements = tuple(_element(_mapping(e)) for e in _sequence(record["elements"]))
    except (KeyError, TypeError, ValueError):
        return None
    return CommitStep(summaries, elements)


def _mapping(value: object) -> Mapping[str, object]:
    if not isinstance(value, dict):
        raise TypeError("a mapping was expected")
    return value


def _sequence(value: object) -> Sequence[object]:
    if not isinstance(value, list):
        raise TypeError("a list was expected")
    return value


def _int(value: object) -> int:
    if not isinstance(value, int) or isinstance(value, bool):
        raise TypeError("an integer was expected")
    return value


def _float(value: object) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise TypeError("a number was expected")
    return float(value)


_SUMMARY_KEYS = (*SUMMARY_FIELDS, "unparsed")  # what Summary.to_dict writes


def summary_from_dict(data: Mapping[str, object]) -> Summary:
    """The :class:`Summary` whose ``to_dict`` gives ``data`` (every field checked)."""
    if set(data) != set(_SUMMARY_KEYS):
        raise ValueError("a summary's fields differ")
    values: dict[str, object] = {}
    for name in _SUMMARY_KEYS:
        value = data[name]
        if name == "notes":
            values[name] = tuple(str(_text(n)) for n in _sequence(value))
        elif name in _OPTIONAL and value is None:
            values[name] = None
        elif name in _FLOATS:
            values[name] = _float(value)
        else:
            values[name] = _int(value)
    return Summary(**values)  # type: ignore[arg-type]


def _text(value: object) -> str:
    if not isinstance(value, str):
        raise TypeError("a text was expected")
    return value


def _metrics(value: object) -> Metrics | None:
    if value is None:
        return None
    data = _mapping(value)
    if set(data) != set(Metrics._fields):
        raise ValueError("an element's metrics differ")
    return Metrics(*(_int(data[name]) for name in Metrics._fields))


def _element(data: Mapping[str, object]) -> ElementChange:
    return ElementChange(
        element=_text(data["element"]),
        location=Location(_text(data["location"])),
        files=tuple(_text(f) for f in _sequence(data["files"])),
        status=Status(_text(data["status"])),
        pre=_metrics(data["pre"]),
        post=_metrics(data["post"]),
        added=_int(data["added"]),
        removed=_int(data["removed"]),
        modified=_int(data["modified"]),
    )


def _cost(scaled_changes: float, delta_vg: float, scaled_delta_vg: float) -> float:
    """E_e = ΣΓ'_e / ΣΔVg'_e, and 0 when the element's complexity is where it started
    (ΣΔVg_e = 0: eq. 6.38's case; the scaled sum is then only the scales' rounding)."""
    if delta_vg == 0 or scaled_delta_vg == 0:
        return 0.0
    return scaled_changes / scaled_delta_vg


@dataclass(frozen=True, slots=True)
class ElementTotals:
    """One element over a range: the commits that changed it (Γ_e > 0), ΣΓ'_e, ΣΔVg'_e and
    its cumulative E; ``location`` as of its last change."""

    element: str
    location: str
    commits: int
    scaled_changes: float
    scaled_delta_vg: float
    cost: float


def element_share(step: CommitStep, element: ElementChange) -> tuple[int, float, int, float]:
    """Γ_e, Γ'_e, ΔVg_e and ΔVg'_e of ``element`` in ``step``: its changes and complexity
    change, the scaled ones by its location's λ̂ and v̂g (an undefined scale is taken as 1,
    as for S(L))."""
    summary = step.summaries[element.location.value]
    changes = element.added + element.removed + element.modified
    delta_vg = (element.post.vg if element.post else 0) - (element.pre.vg if element.pre else 0)
    loc_scale = 1.0 if summary.loc_scale is None else summary.loc_scale
    vg_scale = 1.0 if summary.vg_scale is None else summary.vg_scale
    return changes, loc_scale * changes, delta_vg, vg_scale * delta_vg + 0.0


def element_totals(steps: Iterable[CommitStep]) -> tuple[ElementTotals, ...]:
    """Every element that changed over ``steps``, costliest first: by ΣΓ'_e (the size of
    the work) then by name."""
    found: dict[str, list[float]] = {}
    where: dict[str, str] = {}
    for step in steps:
        for element in step.elements:
            changes, scaled, delta_vg, scaled_vg = element_share(step, element)
            if not changes:
                continue
            totals = found.setdefault(element.element, [0, 0.0, 0, 0.0])
            totals[0] += 1
            totals[1] += scaled
            totals[2] += delta_vg
            totals[3] += scaled_vg
            where[element.element] = element.location.value
    rows = [
        ElementTotals(name, where[name], int(t[0]), t[1], t[3] + 0.0, _cost(t[1], t[2], t[3]))
        for name, t in found.items()
    ]
    rows.sort(key=lambda r: (-r.scaled_changes, r.element))
    return tuple(rows)
