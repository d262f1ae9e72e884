"""A diff's function and file gates, and what else its gates read beyond the sums.

``vg(function) > 15`` among a diff's gates checks every function the change touches
(``loc(file) > 1000`` every file it touches), as a scan checks every function of the tree;
location gates (``cost(new) > 20``) check the change's summary. Both kinds are written in the
same places (``--fail-on``, the configuration's ``gates``); the word in the parentheses tells
them apart: ``function`` and ``file`` are units, everything else a location.
"""

from __future__ import annotations

from dataclasses import replace
from typing import TYPE_CHECKING

from archmetrics.changeset.locations import Location, LocationRules
from archmetrics.changeset.model import ChangeReport
from archmetrics.changeset.touched import touched
from archmetrics.complexity.thresholds import FIELDS, Unit

if TYPE_CHECKING:
    from archmetrics.app.tree import Side


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


def for_gates(
    change: ChangeReport, pre: Side, post: Side, rules: LocationRules, units: bool
) -> ChangeReport:
    """``change`` with what gates and warnings read beyond its sums: the location and
    exclude globs that matched no file of either side, the touched files and functions
    (``units``: a unit gate asks for them) and, per location, the touched files that cannot
    be parsed after the change."""
    if rules.rules or rules.exclude:
        paths = (row.path for side in (pre, post) for row in side.state.rows)
        change = replace(change, unmatched=rules.unmatched(paths))
    if units:
        change = replace(change, touched=touched(change, post.known))
    broken = _unparsed(pre, post, rules)
    return change.with_unparsed(broken) if broken else change


def _unparsed(pre: Side, post: Side, rules: LocationRules) -> dict[Location, int]:
    """Per location, the files the change touched (new or changed) that cannot be parsed
    after it and no exclude glob leaves out."""
    found: dict[Location, int] = {}
    for row in post.state.rows:
        if row.parsed or rules.is_excluded(row.path) is not None:
            continue
        before = pre.by_path.get(row.path)
        if before is None or (before.blob, before.language) != (row.blob, row.language):
            location = rules.location_of(row.path)
            found[location] = found.get(location, 0) + 1
    return found
