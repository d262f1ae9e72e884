"""The content-based router: rule validation, transforms and routing on a live bus."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import robosoa
from robosoa.expr import ExprError, Expression
from robosoa.router import Router, RuleError
from tests.robosoa.util import eventually

pytestmark = pytest.mark.timeout(60)

RULES = """
[[rules]]
name = "fast-goal"
operation = "set_goal"
when = "priority >= 5 and mode == 'auto'"
stop = true

  [[rules.to]]
  kind = "request"
  service = "SVC-backend"
  operation = "goto"
    [rules.to.fields]
    x = "goal.x"
    y = "goal.y"
    speed = "min(speed * 2, 3)"
    source = "'pragmatics'"
    urgent = true

  [[rules.to]]
  kind = "publish"
  topic = "SVC-status"
  copy = true
  rename = { priority = "level" }
  drop = ["goal"]

[[rules]]
name = "slow-goal"
operation = "set_goal"

  [[rules.to]]
  kind = "send"
  service = "SVC-backend"
  operation = "queue"
  fields = { goal = "goal", op = "_operation" }

[[rules]]
name = "pose-relay"
topic = "SVC-pose"
when = "valid"

  [[rules.to]]
  kind = "emit"
  topic = "SVC-moved"
  fields = { dist = "abs(dx) + abs(dy)" }
"""


def test_route_is_pure_and_follows_rule_order() -> None:
    router = Router.from_data({"rules": [
        {"name": "a", "operation": "op", "when": "n > 1", "to": [
            {"kind": "publish", "topic": "t", "fields": {"m": "n * 10", "k": 7}}]},
        {"name": "b", "to": [{"kind": "emit", "topic": "e", "copy": True}]},
    ]})
    [first, second] = router.route("op", "", {"n": 2})
    assert (first.rule, first.payload) == ("a", {"m": 20, "k": 7})
    assert (second.rule, second.kind, second.payload) == ("b", "emit", {"n": 2})
    assert [o.rule for o in router.route("op", "", {"n": 0})] == ["b"]
    assert [o.rule for o in router.route("op", "", {})] == ["b"]  # missing field: no match


@pytest.mark.parametrize(("data", "message"), [
    ({"rules": [{"to": [], "bogus": 1}]}, "rules[0]: unknown key 'bogus'"),
    ({"rules": [{"to": [{"kind": "teleport"}]}]}, "rules[0].to[0].kind"),
    ({"rules": [{"to": [{"kind": "request", "service": "s"}]}]}, "to[0].operation: required"),
    ({"rules": [{"when": "__import__('os')", "to": []}]}, "rules[0].when"),
    ({"rules": [{"to": [{"kind": "emit", "topic": "t", "fields": {"x": "a.__class__"}}]}]},
     "fields.x"),
    ({"rules": "nope"}, "expected a list of rules"),
])
def test_bad_rules_are_refused_naming_the_key(data: object, message: str) -> None:
    with pytest.raises(RuleError, match=message.replace("[", r"\[").replace("]", r"\]")):
        Router.from_data(data)


@pytest.mark.parametrize("text", ["open('x')", "x.__dict__", "lambda: 1", "[i for i in x]",
                                  "x ** 2", "f(x)", "a[b]", "(yield)", "{1, 2}"])
def test_expressions_refuse_everything_outside_the_whitelist(text: str) -> None:
    with pytest.raises(ExprError):
        Expression(text)


def test_expression_values() -> None:
    scope = {"a": 3, "p": {"q": [1, 2]}, "s": "Ab"}
    assert Expression("a * 2 + p.q[1]").evaluate(scope) == 8
    assert Expression("lower(s) if a in [1, 3] else null").evaluate(scope) == "ab"
    assert Expression("not (a > 2 or missing)").evaluate(scope) is False
    with pytest.raises(ExprError, match="no field"):
        Expression("missing + 1").evaluate(scope)
    with pytest.raises(ExprError, match="exceeds"):
        Expression("s * 100000000").evaluate(scope)
    with pytest.raises(ExprError, match="ZeroDivisionError"):
        Expression("a / 0").evaluate(scope)


def test_router_service_remaps_messages_on_the_bus(url: str, name: str,
                                                   tmp_path: Path) -> None:
    rules = tmp_path / "rules.toml"
    rules.write_text(RULES.replace("SVC", name), encoding="utf-8")
    router = Router.from_file(rules)
    goto: list[dict[str, object]] = []
    queued: list[dict[str, object]] = []
    with robosoa.connect(url) as bus, router.attach(bus, name + "-pragmatics"):
        bus.provide(name + "-backend", {
            "goto": lambda **kw: goto.append(kw) or {"accepted": True},
            "queue": lambda **kw: queued.append(kw)})
        status: list[robosoa.Message] = []
        moved: list[robosoa.Message] = []
        bus.subscribe(name + "-status", status.append)
        bus.on(name + "-moved", moved.append)
        reply = bus.request(name + "-pragmatics", "set_goal", {
            "priority": 7, "mode": "auto", "speed": 1, "goal": {"x": 1.0, "y": 2.0}})
        assert reply["routed"][0]["reply"] == {"accepted": True}
        assert goto == [{"x": 1.0, "y": 2.0, "speed": 2, "source": "pragmatics",
                         "urgent": True}]
        eventually(lambda: status)
        assert status[0].payload == {"level": 7, "mode": "auto", "speed": 1}
        bus.request(name + "-pragmatics", "set_goal", {"priority": 1, "goal": {"x": 0}})
        eventually(lambda: queued)
        assert queued == [{"goal": {"x": 0}, "op": "set_goal"}]
        with pytest.raises(robosoa.InvalidMessage, match="unknown operation"):
            bus.request(name + "-pragmatics", "self_destruct", {})
        eventually(lambda: bus.publish(name + "-pose", {"valid": True, "dx": -1, "dy": 2})
                   or moved)
        assert moved[0].payload == {"dist": 3}


def test_rules_load_from_json(tmp_path: Path) -> None:
    path = tmp_path / "r.json"
    path.write_text(json.dumps([{"operation": "x", "to": [
        {"kind": "emit", "topic": "t"}]}]), encoding="utf-8")
    assert Router.from_file(path).rules[0].operation == "x"
    path.write_text("{not json", encoding="utf-8")
    with pytest.raises(RuleError, match=r"r\.json"):
        Router.from_file(path)
