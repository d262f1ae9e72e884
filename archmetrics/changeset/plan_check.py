"""Check a planned stage against the state it applies to, and resolve what it names (pure).

Every element, dependency, link target and rule the plan names is looked up in the base (or
among the stage's new elements); anything it cannot mean is a :class:`PlanError` naming the
plan's file and key. changeset/estimate.py then counts.
"""

from __future__ import annotations

from collections.abc import Mapping

from archmetrics.changeset.locations import Location, LocationRules
from archmetrics.changeset.plan import PlanError, PlannedElement, PlannedLink, PlannedStage
from archmetrics.changeset.plan_state import BaseState
from archmetrics.coupling.rules import Role, RuleSet


def rule_roles(rules: RuleSet) -> dict[str, Role | None]:
    """Rule name -> its role, by qualified id (``zeromq/py-send``) and by bare id (``send``):
    a bare id that packs give different roles maps to None (ambiguous: name the pack); one
    they agree on means the same counts whichever pack it is."""
    roles: dict[str, Role | None] = {}
    bare: dict[str, set[Role]] = {}
    for rule in rules.rules:
        roles[rule.qualified_id] = rule.role
        bare.setdefault(rule.id, set()).add(rule.role)
    for name, found in bare.items():
        if name not in roles:
            roles[name] = next(iter(found)) if len(found) == 1 else None
    return roles


class Planner:
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
            owner = self.file_owner.get(planned.name)
            hint = (
                f"it is a file of element {owner!r}"
                if owner
                else "not in the base (`new = true` plans a new one)"
            )
            raise self.fail(f"{planned.key}.name", f"unknown element {planned.name!r}: {hint}")
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
