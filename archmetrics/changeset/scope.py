"""S over several locations taken together: a scope (base + framework, the code an approach
makes the integrator write), summed the way S(L) sums one location's change sets."""

from __future__ import annotations

from collections.abc import Collection

from archmetrics.changeset.cost import Sums, location_summary
from archmetrics.changeset.locations import Location
from archmetrics.changeset.model import ChangeReport, Metrics, Summary

# the notes location_summary makes itself from the sums (cost.py); the others are carried
_RECOMPUTED = ("location_empty", "loc_scale", "vg_scale", "cost_")


def scope_summary(report: ChangeReport, locations: Collection[Location]) -> Summary:
    """S of the element change sets in ``locations``, as if they were one location: coupling
    deltas, Γ, λ and Vg summed over them (eqs. 6.2, 6.5, 6.7, 6.9, 6.16-6.18, 6.31), scales and
    E from those sums. The notes of the locations that are not about the sums come along
    (coupling not measured, dynamic coupling taken as 0 before, ...)."""
    chosen = [e for e in report.elements if e.location in locations]
    sums = Sums(
        pre=sum((e.pre or Metrics() for e in chosen), Metrics()),
        post=sum((e.post or Metrics() for e in chosen), Metrics()),
        added=sum(e.added for e in chosen),
        removed=sum(e.removed for e in chosen),
        modified=sum(e.modified for e in chosen),
    )
    carried = dict.fromkeys(
        note
        for location, summary in report.locations
        if location in locations
        for note in summary.notes
        if not note.startswith(_RECOMPUTED)
    )
    return location_summary(sums, tuple(carried))
