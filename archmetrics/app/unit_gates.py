"""A diff's function and file gates: ``vg(function) > 15`` among a diff's gates checks every
function the change touches (``loc(file) > 1000`` every file it touches), as a scan checks
every function of the tree; location gates (``cost(new) > 20``) check the change's summary.

Both kinds are written in the same places (``--fail-on``, the configuration's ``gates``); the
word in the parentheses tells them apart: ``function`` and ``file`` are units, everything
else a location.
"""

from __future__ import annotations

from collections.abc import Iterable

from archmetrics.changeset.gates import Gate, is_unit_gate, parse_gate
from archmetrics.changeset.model import ChangeReport
from archmetrics.complexity.thresholds import FIELDS, Threshold, Unit, parse_threshold


def split_gates(texts: Iterable[str]) -> tuple[tuple[Gate, ...], tuple[Threshold, ...]]:
    """Location gates and unit gates, each parsed (a bad one fails here, before any work)."""
    gates, thresholds = [], []
    for text in texts:
        if is_unit_gate(text):
            thresholds.append(parse_threshold(text))
        else:
            gates.append(parse_gate(text))
    return tuple(gates), tuple(thresholds)


def touched_units(change: ChangeReport) -> dict[str, list[Unit]]:
    """The functions and files the change touched, after it, as threshold units."""
    functions = [
        Unit(f.qualified_name, t.file.path, f.line, {"vg": f.vg, "loc": f.loc}, f.suppressed)
        for t in change.touched
        for f in t.functions
    ]
    files = []
    for t in change.touched:
        file = t.file
        numbers = {"vg": file.vg, "loc": file.loc, "sloc": file.sloc,
                   "functions": len(file.functions), "warnings": len(file.warnings)}  # fmt: skip
        files.append(Unit(file.path, file.path, None, {f: numbers[f] for f in FIELDS["file"]}))
    return {"function": functions, "file": files}
