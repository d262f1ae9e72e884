"""descriptor.validator(): good payloads pass, bad ones raise InvalidMessage naming the field."""

from __future__ import annotations

import uuid
from collections.abc import Iterator
from typing import Any

import pytest

import robosoa
from robosoa.descriptor import ServiceDescriptor, loads

TEXT = """\
<service name="inventory" version="1.0.0">
  <pattern>request-response</pattern>
  <types>
    <struct name="Item">
      <field name="sku" type="string"/>
      <field name="count" type="int"/>
      <field name="weight" type="float" required="false"/>
      <field name="tags" type="list[string]" required="false"/>
    </struct>
  </types>
  <operation name="store">
    <param name="item" type="Item"/>
    <param name="urgent" type="bool" default="false"/>
    <param name="grid" type="list[list[float]]" required="false"/>
    <return name="ok" type="bool"/>
  </operation>
</service>
"""


@pytest.fixture(scope="module")
def descriptor() -> ServiceDescriptor:
    return loads(TEXT, source="inventory.xml")


GOOD: list[dict[str, Any]] = [
    {"item": {"sku": "a", "count": 1}},
    {"item": {"sku": "a", "count": 1, "weight": 2}, "urgent": True},
    {"item": {"sku": "a", "count": 1, "weight": 2.5, "tags": ["x", "y"]}, "grid": [[1, 2.5], []]},
    {"item": {"sku": "a", "count": 1, "tags": None}, "grid": None},
]

BAD: list[tuple[dict[str, Any], str]] = [
    ({}, "operation 'store' parameter 'item': missing required field"),
    ({"item": {"sku": "a"}}, "parameter 'item.count': missing required field"),
    ({"item": {"sku": 1, "count": 1}}, "parameter 'item.sku': expected string, got int"),
    ({"item": {"sku": "a", "count": True}}, "parameter 'item.count': expected int, got bool"),
    ({"item": {"sku": "a", "count": 1.5}}, "parameter 'item.count': expected int, got float"),
    ({"item": {"sku": "a", "count": 1, "colour": "red"}}, "'item.colour': unexpected field"),
    ({"item": {"sku": "a", "count": 1, "tags": ["x", 3]}}, "'item.tags[1]': expected string"),
    ({"item": {"sku": "a", "count": 1}, "grid": [[1.0], "row"]}, "'grid[1]': expected list"),
    ({"item": {"sku": "a", "count": 1}, "grid": [[1.0, "2"]]}, "'grid[0][1]': expected float"),
    ({"item": [1, 2]}, "parameter 'item': expected Item, got list"),
    ({"item": {"sku": "a", "count": 1}, "urgent": "yes"}, "'urgent': expected bool, got string"),
    ({"item": {"sku": "a", "count": 1}, "extra": 1}, "parameter 'extra': unexpected field"),
]


@pytest.mark.parametrize("payload", GOOD)
def test_good_payloads_pass(descriptor: ServiceDescriptor, payload: dict[str, Any]) -> None:
    descriptor.validator()("store", payload)


@pytest.mark.parametrize(("payload", "reason"), BAD)
def test_bad_payloads_name_the_field(
    descriptor: ServiceDescriptor, payload: dict[str, Any], reason: str
) -> None:
    with pytest.raises(robosoa.InvalidMessage) as caught:
        descriptor.validator()("store", payload)
    assert reason in str(caught.value)


def test_unknown_operation(descriptor: ServiceDescriptor) -> None:
    with pytest.raises(robosoa.InvalidMessage, match="has no operation 'fetch'"):
        descriptor.validator()("fetch", {})


def test_reply_validator_checks_returns(descriptor: ServiceDescriptor) -> None:
    check = descriptor.reply_validator()
    check("store", {"ok": True})
    with pytest.raises(robosoa.InvalidMessage, match="return 'ok': expected bool, got int"):
        check("store", {"ok": 1})


@pytest.fixture
def bus() -> Iterator[robosoa.Bus]:
    b = robosoa.connect(f"inproc://descriptor-{uuid.uuid4().hex[:8]}")
    yield b
    b.close()


def test_bus_rejects_what_the_validator_rejects(
    descriptor: ServiceDescriptor, bus: robosoa.Bus
) -> None:
    stored: list[dict[str, Any]] = []

    def store(**payload: Any) -> dict[str, Any]:
        stored.append(payload)
        return {"ok": True}

    bus.provide("inventory", {"store": store}, validator=descriptor.validator())
    assert bus.request("inventory", "store", {"item": {"sku": "a", "count": 2}}) == {"ok": True}
    with pytest.raises(robosoa.InvalidMessage, match=r"parameter 'item.count': expected int"):
        bus.request("inventory", "store", {"item": {"sku": "a", "count": "2"}})
    assert len(stored) == 1
