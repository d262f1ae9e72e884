"""The state a plan applies to: every element of a tree with its metrics and static edges.

Measured from the base revision (:func:`base_state`), or as a planned stage leaves it.
"""

from __future__ import annotations

from dataclasses import dataclass

from archmetrics.changeset.locations import Location
from archmetrics.changeset.model import ChangeReport, ExcludedFile, Metrics
from archmetrics.coupling.model import CouplingReport


@dataclass(frozen=True, slots=True)
class ElementState:
    """An element as a stage leaves it: its location, metrics M and static coupling edges."""

    name: str
    location: Location
    metrics: Metrics
    files: tuple[str, ...] = ()
    dependencies: frozenset[str] = frozenset()  # counted: target elements, external names
    dependents: frozenset[str] = frozenset()  # the elements behind s_a


@dataclass(frozen=True, slots=True)
class BaseState:
    """Every element of a tree (measured, or as a planned stage leaves it), by name."""

    elements: tuple[ElementState, ...]
    excluded: tuple[ExcludedFile, ...] = ()

    def by_name(self) -> dict[str, ElementState]:
        return {e.name: e for e in self.elements}


def base_state(change: ChangeReport, coupling: CouplingReport | None) -> BaseState:
    """The state of the tree a change report measured after (its ``post`` side), with each
    element's counted dependencies and dependents from the coupling layer's report."""
    edges = {c.element.name: c for c in coupling.elements} if coupling else {}
    states = []
    for element in change.elements:
        if element.post is None:
            continue
        found = edges.get(element.element)
        dependencies = frozenset(
            d.target_element or d.name for d in (found.dependencies if found else ()) if d.counted
        )
        dependents = frozenset(found.dependents if found else ())
        states.append(
            ElementState(
                element.element,
                element.location,
                element.post,
                element.files,
                dependencies,
                dependents,
            )
        )
    return BaseState(tuple(states), change.excluded)
