"""A planned stage applied to a base state: figures computed by hand (pure, no repository)."""

from __future__ import annotations

import pytest

from archmetrics.changeset import Location, LocationRules, Metrics, Status
from archmetrics.changeset.estimate import (
    BaseState,
    ElementState,
    apply_stage,
    apply_stages,
    rule_roles,
)
from archmetrics.changeset.plan import PlanError, PlannedElement, PlannedLink, PlannedStage
from archmetrics.coupling.rules import LinkKind, Role, Rule, RulePack, RuleSet

BASE = BaseState(
    (
        ElementState(
            "app/client.py",
            Location.BASE,
            Metrics(loc=10, sloc=12, vg=2, s_e=1),
            ("app/client.py",),
            frozenset({"os"}),
        ),
        ElementState(
            "lib/net",
            Location.FRAMEWORK,
            Metrics(loc=20, sloc=20, vg=4, s_a=0, d_e=1),
            ("lib/net.c", "lib/net.h"),
        ),
    )
)
RULES = LocationRules.from_mapping({"new": ["wdb/**"]})


def _rule(pack: str, rule_id: str, role: Role) -> Rule:
    return Rule(pack, rule_id, ("python",), ("x",), LinkKind.SOCKET, role)


ROLES = rule_roles(
    RuleSet(
        (
            RulePack("a", "a.toml", "", (_rule("a", "send", Role.INITIATE),)),
            RulePack(
                "b",
                "b.toml",
                "",
                (_rule("b", "send", Role.RECEIVE), _rule("b", "bind", Role.RECEIVE)),
            ),
        )
    )
)


def _stage(*elements: PlannedElement) -> PlannedStage:
    return PlannedStage("first", "architecture.x", elements)


def test_a_planned_change_goes_through_the_same_formulas_as_a_diff() -> None:
    client = PlannedElement(
        "app/client.py",
        "architecture.x.element[0]",
        added=5,
        modified=1,
        decisions_added=1,
        static_dependencies=("wdb/store.py", "os"),
        dynamic_links=(PlannedLink("a/send", 2, "lib/net.h", "k"),),
    )
    store = PlannedElement(
        "wdb/store.py", "architecture.x.element[1]", new=True, added=8, functions_added=2
    )
    report, after = apply_stage("p.toml", BASE, _stage(client, store), RULES, ROLES)
    base = report.location(Location.BASE)
    # λ 10 -> 15; Γ = 5 + 1 = 6; λ̂ = 1.5, Γ' = 9; Vg 2 -> 3, v̂g = 1.5, ΔVg' = 1.5; E = 6
    assert (base.loc_pre, base.loc_post, base.changes) == (10, 15, 6)
    assert base.scaled_changes == pytest.approx(9.0)
    assert base.scaled_delta_vg == pytest.approx(1.5)
    assert base.cost == pytest.approx(6.0)
    # s_e: "os" already a dependency (counted once, noted), the store is new: 1 -> 2
    assert base.delta_s_e == 1 and base.delta_d_e == 2
    assert any(n.startswith("plan_dependency_exists:") for n in base.notes)
    new = report.location(Location.NEW)  # located by the globs: wdb/** is new
    # λ_pre = 0: λ̂ undefined, Γ' = Γ = 8; Vg 0 -> 2, ΔVg' = ΔVg = 2; E = 4
    assert (new.loc_scale, new.scaled_changes, new.delta_vg, new.cost) == (None, 8.0, 2, 4.0)
    assert new.delta_s_a == 1  # the client now depends on it
    framework = report.location(Location.FRAMEWORK)
    assert framework.delta_d_a == 2 and framework.changes == 0  # a file names its element
    # total: λ 30 -> 43, Γ = 14, λ̂ = 43/30; Vg 6 -> 9, v̂g = 1.5, ΔVg' = 4.5
    assert report.total.cost == pytest.approx((43 / 30 * 14) / (9 / 6 * 3))
    statuses = {e.element: e.status for e in report.elements}
    assert statuses == {
        "app/client.py": Status.MODIFIED,
        "lib/net": Status.UNCHANGED,
        "wdb/store.py": Status.ADDED,
    }
    state = after.by_name()
    assert state["app/client.py"].metrics == Metrics(loc=15, sloc=17, vg=3, s_e=2, d_e=2)
    assert state["wdb/store.py"].dependents == frozenset({"app/client.py"})


def test_stages_apply_to_what_the_stage_before_left() -> None:
    first = PlannedElement("wdb/store.py", "s0", new=True, added=10, functions_added=1)
    second = PlannedElement("wdb/store.py", "s1", added=5, decisions_added=1)
    one, two = apply_stages(
        "p.toml", BASE, [_stage(first), PlannedStage("second", "s", (second,))], RULES, ROLES
    )
    assert one.location(Location.NEW).loc_post == 10
    new = two.location(Location.NEW)
    # λ 10 -> 15, λ̂ = 1.5, Γ' = 7.5; Vg 1 -> 2, v̂g = 2, ΔVg' = 2; E = 3.75
    assert (new.loc_pre, new.loc_post, new.vg_pre, new.vg_post) == (10, 15, 1, 2)
    assert new.cost == pytest.approx(3.75)


def test_dynamic_pre_zero_takes_d_before_as_zero_and_says_so() -> None:
    report, _ = apply_stage("p.toml", BASE, _stage(), RULES, ROLES, dynamic_pre_zero=True)
    framework = report.location(Location.FRAMEWORK)
    assert framework.delta_d_e == 1  # measured 1 after, taken as 0 before
    assert any(n.startswith("dynamic_pre_zero:") for n in framework.notes)


def test_a_bare_rule_id_is_ambiguous_when_packs_give_it_different_roles() -> None:
    link = PlannedLink("send", 1, None, "architecture.x.element[0].dynamic_links[0]")
    element = PlannedElement("app/client.py", "architecture.x.element[0]", dynamic_links=(link,))
    with pytest.raises(PlanError, match=r"dynamic_links\[0\]\.rule: rule 'send' is in several"):
        apply_stage("p.toml", BASE, _stage(element), RULES, ROLES)
    assert ROLES["bind"] is Role.RECEIVE and ROLES["a/send"] is Role.INITIATE


@pytest.mark.parametrize(
    ("element", "expected"),
    [
        (
            PlannedElement("app/client.py", "e", decisions_removed=3),
            "e.decisions_removed: removes more than the element's v_g = 2",
        ),
        (
            PlannedElement("app/client.py", "e", location=Location.NEW),
            "e.location: element 'app/client.py' is in base in the base, not new",
        ),
        (
            PlannedElement("wdb/x.py", "e", new=True, modified=1),
            "e.statements_modified: a new element has nothing to remove or modify",
        ),
        (
            PlannedElement("lib/net.c", "e", added=1),
            "e.name: unknown element 'lib/net.c': it is a file of element 'lib/net'",
        ),
        (
            PlannedElement("app/client.py", "e", static_dependencies=("app/client.py",)),
            "e.static_dependencies[0]: element 'app/client.py' cannot depend on itself",
        ),
    ],
)
def test_a_plan_that_contradicts_the_base_is_refused(
    element: PlannedElement, expected: str
) -> None:
    with pytest.raises(PlanError) as raised:
        apply_stage("p.toml", BASE, _stage(element), RULES, ROLES)
    assert str(raised.value) == f"p.toml: {expected}"
