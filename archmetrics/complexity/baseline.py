"""A baseline: the offenders a code base already has, so that thresholds and function gates
fail only on new offenders and on offenders that got worse (``archmetrics baseline``;
``--baseline FILE`` on ``scan`` and ``diff``).

An offender is one unit that failed a threshold when the baseline was written: its kind
(function, file, element, total), its file and its name (a function's qualified name, a
file's path, an element's name), and its numbers. A failure now is *known* when the baseline
holds an offender of the same kind, file and name whose numbers were no better: for each
field the threshold reads, the value now lies no further past the limit than it did. Lines
are not compared, so a function that moved in its file is still known; a function renamed
or moved to another file is new. Two offenders with one name in one file (C++ overloads)
are matched worst with worst, in order.

The file is JSON (``archmetrics.baseline/1``, archmetrics/schemas/baseline-1.schema.json).
It comes from the repository, so it is read as untrusted input: anything but that shape is
a one-line :class:`BaselineError`.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass

from archmetrics.complexity.thresholds import OPERATORS, ThresholdFailure, past_limit

SCHEMA = "archmetrics.baseline/1"
MAX_BASELINE_BYTES = 64 << 20
"""A baseline file larger than this (64 MiB) is refused rather than read."""


class BaselineError(ValueError):
    """A baseline file that cannot be read; the message names the file and what is wrong."""


@dataclass(frozen=True, slots=True)
class Offender:
    kind: str  # function | file | element | total
    path: str | None
    name: str
    values: Mapping[str, float]

    @property
    def key(self) -> tuple[str, str | None, str]:
        return self.kind, self.path, self.name


def _no_worse(failure: ThresholdFailure, known: Offender) -> bool:
    """Whether ``failure``'s unit lies no further past each limit than ``known`` did."""
    for group in failure.threshold.groups:
        for condition in group:
            if condition.op not in OPERATORS or condition.field not in known.values:
                return False
            now = past_limit(condition.op, failure.unit.values[condition.field], condition.limit)
            then = past_limit(condition.op, known.values[condition.field], condition.limit)
            if now > then:
                return False
    return True


@dataclass(frozen=True, slots=True)
class Baseline:
    offenders: tuple[Offender, ...]
    source: str = ""

    def known(self, failures: Sequence[ThresholdFailure]) -> frozenset[int]:
        """The indexes of ``failures`` this baseline knows (no worse than recorded)."""
        recorded: dict[tuple[str, str | None, str], list[Offender]] = {}
        for offender in self.offenders:
            recorded.setdefault(offender.key, []).append(offender)
        found: set[int] = set()
        by_key: dict[tuple[str, str | None, str], list[int]] = {}
        for index, failure in enumerate(failures):
            by_key.setdefault(_key(failure), []).append(index)
        for key, indexes in by_key.items():
            if key not in recorded:
                continue
            fields = failures[indexes[0]].threshold.fields
            then = sorted(recorded[key], key=lambda o: [-o.values.get(f, 0) for f in fields])
            now = sorted(indexes, key=lambda i: [-failures[i].unit.values[f] for f in fields])
            found.update(i for i, o in zip(now, then, strict=False) if _no_worse(failures[i], o))
        return frozenset(found)


def _key(failure: ThresholdFailure) -> tuple[str, str | None, str]:
    return failure.threshold.unit, failure.unit.path, failure.unit.name


def baseline_of(failures: Iterable[ThresholdFailure]) -> Baseline:
    """The offenders of ``failures``, each unit once with all its numbers."""
    seen: dict[tuple[str, str | None, str, int | None], Offender] = {}
    for failure in failures:
        unit = failure.unit
        identity = (*_key(failure), unit.line)
        seen.setdefault(identity, Offender(failure.threshold.unit, unit.path, unit.name,
                                           dict(unit.values)))  # fmt: skip
    return Baseline(tuple(seen.values()))


def baseline_document(baseline: Baseline, thresholds: Sequence[str], version: str) -> str:
    """The baseline as the JSON text ``archmetrics baseline`` writes (sorted: stable diffs)."""
    offenders = sorted(baseline.offenders, key=lambda o: (o.kind, o.path or "", o.name))
    document = {
        "schema": SCHEMA,
        "tool": {"name": "archmetrics", "version": version},
        "thresholds": list(thresholds),
        "offenders": [
            {"kind": o.kind, "path": o.path, "name": o.name, "values": dict(o.values)}
            for o in offenders
        ],
    }
    return json.dumps(document, indent=2, ensure_ascii=True) + "\n"


def read_baseline(data: bytes, source: str) -> Baseline:
    """The baseline in ``data`` (the file at ``source``), checked field by field."""
    if len(data) > MAX_BASELINE_BYTES:
        raise BaselineError(f"{source}: larger than {MAX_BASELINE_BYTES} bytes; not read")
    try:
        document = json.loads(data)
    except (ValueError, RecursionError) as error:
        raise BaselineError(f"{source}: not JSON: {error}") from None
    if not isinstance(document, dict) or document.get("schema") != SCHEMA:
        raise BaselineError(f"{source}: not an {SCHEMA} document (archmetrics baseline)")
    entries = document.get("offenders")
    if not isinstance(entries, list):
        raise BaselineError(f"{source}: offenders: expected a list")
    return Baseline(tuple(_offender(entry, f"{source}: offenders[{i}]")
                          for i, entry in enumerate(entries)), source)  # fmt: skip


def _offender(entry: object, where: str) -> Offender:
    if not isinstance(entry, dict):
        raise BaselineError(f"{where}: expected an object")
    kind, path, name, values = (entry.get(k) for k in ("kind", "path", "name", "values"))
    if kind not in ("function", "file", "element", "total"):
        raise BaselineError(f"{where}: kind: expected function, file, element or total")
    if not isinstance(name, str) or not (path is None or isinstance(path, str)):
        raise BaselineError(f"{where}: name and path: expected text (path may be null)")
    if not isinstance(values, dict) or not all(
        isinstance(k, str) and isinstance(v, int | float) and not isinstance(v, bool)
        for k, v in values.items()
    ):
        raise BaselineError(f"{where}: values: expected numbers by field")
    return Offender(kind, path, name, values)
