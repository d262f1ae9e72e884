"""Apply a planned stage to a measured base: element change sets from planned counts (pure).

The base (:class:`BaseState`) is measured from real code, so λ, Vg and coupling before are
the repository's; the plan supplies only the change. The element change sets built here go
through the same :func:`~archmetrics.changeset.compute.report_of` as a diff's, so Γ', ΔVg',
E and the coupling deltas use one set of formulas (cost.py). Choices the thesis leaves open
(how a planned decision maps onto ΔVg, ...) are in docs/estimate.md.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence

from archmetrics.changeset.compute import report_of, side_notes
from archmetrics.changeset.elements import Side
from archmetrics.changeset.locations import Location, LocationRules
from archmetrics.changeset.model import ChangeReport, ElementChange, Metrics, Status
from archmetrics.changeset.plan import PlannedElement, PlannedStage
from archmetrics.changeset.plan_check import Planner, rule_roles
from archmetrics.changeset.plan_state import BaseState, ElementState, base_state
from archmetrics.coupling.rules import Role

__all__ = [
    "ESTIMATE_NOTE",
    "BaseState",
    "ElementState",
    "apply_stage",
    "apply_stages",
    "base_state",
    "rule_roles",
]

ESTIMATE_NOTE = (
    "estimate_from_plan: Γ, λ_post, Vg_post and the coupling after are planned, not measured"
    " (docs/estimate.md)"
)


def apply_stage(
    source: str,
    state: BaseState,
    stage: PlannedStage,
    rules: LocationRules,
    roles: Mapping[str, Role | None],
    *,
    dynamic_pre_zero: bool = False,
) -> tuple[ChangeReport, BaseState]:
    """The change report a planned stage estimates, and the state it leaves for the next."""
    planner = Planner(source, state, stage, rules, roles)
    notes: list[tuple[Location, str]] = []
    deps = {e.name: set(e.dependencies) for e in state.elements}
    dependents = {e.name: set(e.dependents) for e in state.elements}
    d_a: dict[str, int] = {}
    for planned in stage.elements:
        deps.setdefault(planned.name, set())
        dependents.setdefault(planned.name, set())
    for planned in stage.elements:
        for i, name in enumerate(planned.static_dependencies):
            key = f"{planned.key}.static_dependencies[{i}]"
            target = planner.dependency(planned, name, key)
            if target in deps[planned.name]:
                notes.append(
                    (
                        planner.locations[planned.name],
                        f"plan_dependency_exists: {planned.name!r} already depends on {target!r}"
                        f" ({key}); counted once",
                    )
                )
            deps[planned.name].add(target)
            if target in dependents:
                dependents[target].add(planned.name)
        for link in planned.dynamic_links:
            receiver = planner.link_target(link)
            if receiver is not None and receiver != planned.name:
                d_a[receiver] = d_a.get(receiver, 0) + link.count
    planned_by_name = {p.name: p for p in stage.elements}
    names = sorted({*planner.existing, *planned_by_name})
    changes, states = [], []
    for name in names:
        before = planner.existing.get(name)
        change, after = _element(
            name,
            before,
            planned_by_name.get(name),
            planner.locations[name],
            deps[name],
            dependents[name],
            d_a.get(name, 0),
            dynamic_pre_zero,
        )
        changes.append(change)
        states.append(after)
    common = [*side_notes((Side("pre", {}, dynamic_pre_zero), Side("post", {}))), ESTIMATE_NOTE]
    report = report_of(changes, state.excluded, common, notes)
    return report, BaseState(tuple(states), state.excluded)


def _element(
    name: str,
    before: ElementState | None,
    planned: PlannedElement | None,
    location: Location,
    deps: Iterable[str],
    dependents: Iterable[str],
    d_a_gained: int,
    dynamic_pre_zero: bool,
) -> tuple[ElementChange, ElementState]:
    """One element's change set and the state it is left in."""
    deps, dependents = frozenset(deps), frozenset(dependents)
    pre = before.metrics if before else None
    base = pre or Metrics()
    gained = planned or _NOTHING
    post = Metrics(
        loc=base.loc + gained.delta_loc,
        sloc=base.sloc + gained.delta_loc,  # informative only: moves as λ does
        vg=base.vg + gained.delta_vg,
        s_a=base.s_a + len(dependents) - len(before.dependents if before else ()),
        s_e=base.s_e + len(deps) - len(before.dependencies if before else ()),
        d_a=base.d_a + d_a_gained,
        d_e=base.d_e + sum(link.count for link in gained.dynamic_links),
    )
    changes = gained.added + gained.removed + gained.modified
    status = Status.ADDED if pre is None else Status.MODIFIED if changes else Status.UNCHANGED
    shown_pre = pre._replace(d_a=0, d_e=0) if pre and dynamic_pre_zero else pre
    files = before.files if before else ()
    change = ElementChange(
        name,
        location,
        files,
        status,
        shown_pre,
        post,
        gained.added,
        gained.removed,
        gained.modified,
    )
    return change, ElementState(name, location, post, files, deps, dependents)


_NOTHING = PlannedElement(name="", key="")


def apply_stages(
    source: str,
    state: BaseState,
    stages: Sequence[PlannedStage],
    rules: LocationRules,
    roles: Mapping[str, Role | None],
    *,
    dynamic_pre_zero: bool = False,
) -> list[ChangeReport]:
    """Each planned stage applied to what the one before left (the first to ``state``)."""
    reports = []
    for stage in stages:
        report, state = apply_stage(
            source, state, stage, rules, roles, dynamic_pre_zero=dynamic_pre_zero
        )
        reports.append(report)
    return reports
