"""Apply a planned stage to a measured base: element change sets from planned counts (pure).

The base (:class:`BaseState`) is measured from real code, so λ, Vg and coupling before are
the repository's; the plan supplies only the change. The element change sets built here go
through the same :func:`~archmetrics.changeset.compute.report_of` as a diff's, so Γ', ΔVg',
E and the coupling deltas use one set of formulas (cost.py). Choices the thesis leaves open
(how a planned decision maps onto ΔVg, ...) are in docs/estimate.md.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace

from archmetrics.changeset.compute import report_of, side_notes
from archmetrics.changeset.elements import Side
from archmetrics.changeset.locations import Location, LocationRules
from archmetrics.changeset.model import ChangeReport, ElementChange, ExcludedFile, Metrics, Status
from archmetrics.changeset.plan import PlanError, PlannedElement, PlannedLink, PlannedStage
from archmetrics.coupling.model import CouplingReport
from archmetrics.coupling.rules import Role, RuleSet

ESTIMATE_NOTE = (
    "estimate_from_plan: Γ, λ_post, Vg_post and the coupling after are planned, not measured"
    " (docs/estimate.md)"
)


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


def rule_roles(rules: RuleSet) -> dict[str, Role | None]:
    """Rule name -> its role, by qualified id (``zeromq/py-send``) and by bare id when only
    one pack has it (a bare id in two packs maps to None: ambiguous)."""
    roles: dict[str, Role | None] = {}
    bare: dict[str, set[Role]] = {}
    for rule in rules.rules:
        roles[rule.qualified_id] = rule.role
        bare.setdefault(rule.id, set()).add(rule.role)
    for name, found in bare.items():
        if name not in roles:
            roles[name] = next(iter(found)) if len(found) == 1 else None
    return roles


class _Planner:
    """One stage applied to a state: checks every planned element against it, then counts."""

    def __init__(
        self,
        source: str,
        state: BaseState,
        stage: PlannedStage,
        rules: LocationRules,
        roles: Mapping[str, Role | None],
    ) -> None:
        self.source, self.state, self.stage, self.roles = source, state, stage, roles
        self.existing = state.by_name()
        self.file_owner = {f: e.name for e in state.elements for f in e.files}
        self.locations: dict[str, Location] = {n: e.location for n, e in self.existing.items()}
        for planned in stage.elements:
            self.locations.setdefault(
                planned.name, planned.location or rules.location_of(planned.name)
            )
            self._check(planned)

    def fail(self, key: str, problem: str) -> PlanError:
        return PlanError(self.source, key, problem)

    def _check(self, planned: PlannedElement) -> None:
        found = self.existing.get(planned.name)
        if planned.new:
            if found is not None:
                raise self.fail(
                    f"{planned.key}.name",
                    f"element {planned.name!r} already exists in the base (drop `new = true`)",
                )
            for key, value in (
                ("statements_removed", planned.removed),
                ("statements_modified", planned.modified),
                ("decisions_removed", planned.decisions_removed),
                ("functions_removed", planned.functions_removed),
            ):
                if value:
                    raise self.fail(
                        f"{planned.key}.{key}", "a new element has nothing to remove or modify"
                    )
            return
        if found is None:
            raise self.fail(
                f"{planned.key}.name",
                f"unknown element {planned.name!r}: not in the base (`new = true` plans a new one)",
            )
        if planned.location is not None and planned.location is not found.location:
            raise self.fail(
                f"{planned.key}.location",
                f"element {planned.name!r} is in {found.location.value} in the base,"
                f" not {planned.location.value}",
            )
        if planned.removed + planned.modified > found.metrics.loc:
            raise self.fail(
                f"{planned.key}.statements_removed",
                f"removes and modifies {planned.removed + planned.modified} statements"
                f" of an element of λ = {found.metrics.loc}",
            )
        if found.metrics.vg + planned.delta_vg < 0:
            raise self.fail(
                f"{planned.key}.decisions_removed",
                f"removes more than the element's v_g = {found.metrics.vg}",
            )

    def target(self, name: str, key: str) -> str:
        """The element a dependency or link names: an element, or a file of one."""
        if name in self.locations:
            return name
        owner = self.file_owner.get(name)
        if owner is None:
            raise self.fail(
                key, f"unknown element {name!r}: neither in the base nor new in this stage"
            )
        return owner

    def dependency(self, planned: PlannedElement, name: str, key: str) -> str:
        """An element (or a file of one) is an internal dependency; anything else external."""
        if name in self.locations or name in self.file_owner:
            found = self.target(name, key)
            if found == planned.name:
                raise self.fail(key, f"element {planned.name!r} cannot depend on itself")
            return found
        return name

    def link_target(self, link: PlannedLink) -> str | None:
        if link.rule not in self.roles:
            raise self.fail(
                f"{link.key}.rule",
                f"unknown rule {link.rule!r} (`archmetrics rules` lists those in force)",
            )
        role = self.roles[link.rule]
        if role is None:
            raise self.fail(
                f"{link.key}.rule", f"rule {link.rule!r} is in several packs: name it as pack/rule"
            )
        if link.to is None:
            return None
        if role is not Role.INITIATE:
            raise self.fail(
                f"{link.key}.to",
                f"rule {link.rule!r} has role {role.value}: only an initiating rule's sites"
                " count in another element's d_a",
            )
        return self.target(link.to, f"{link.key}.to")


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
    planner = _Planner(source, state, stage, rules, roles)
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
    shown_pre = replace(pre, d_a=0, d_e=0) if pre and dynamic_pre_zero else pre
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
