"""Reading a plan: every key checked, errors naming the file and the key; the shipped JSON
Schema (archmetrics/schemas/plan-1.schema.json) accepts what the reader accepts and refuses
what it refuses, where a schema can say it."""

from __future__ import annotations

import json
import textwrap
import tomllib
from importlib import resources
from typing import Any

import pytest
from jsonschema import Draft202012Validator

from archmetrics.changeset.locations import Location
from archmetrics.changeset.plan import PlanError, PlannedLink, SketchKind
from archmetrics.changeset.plan_read import read_plan

GOOD = """\
schema = "archmetrics.plan/1"
title = "WDB update"

[architecture.soa]
description = "over the bus"
[[architecture.soa.element]]
name = "wdb/wdb_update.py"
new = true
location = "new"
statements_added = 30
decisions_added = 5
functions_added = 3
static_dependencies = ["wdb/wdb_store.py", "sys"]
dynamic_links = [{ rule = "robosoa/provide" }, { rule = "send", count = 2, to = "a.py" }]

[architecture.p2p]
[[architecture.p2p.stage]]
label = "first"
sketch = { revision = "p2p-first" }
[[architecture.p2p.stage]]
label = "second"
sketch = { patch = "p2p-second.patch" }

[architecture.empty]
element = []
"""


def _validator() -> Draft202012Validator:
    text = (resources.files("archmetrics") / "schemas" / "plan-1.schema.json").read_text("utf-8")
    schema = json.loads(text)
    Draft202012Validator.check_schema(schema)
    return Draft202012Validator(schema)


def _read(text: str) -> Any:
    return read_plan(textwrap.dedent(text).encode(), "p.toml")


def test_a_plan_reads_into_frozen_values_with_their_keys() -> None:
    plan = _read(GOOD)
    assert plan.title == "WDB update" and [a.name for a in plan.architectures] == [
        "soa",
        "p2p",
        "empty",
    ]
    soa = plan.architectures[0]
    (stage,) = soa.stages
    assert stage.label == "estimate" and stage.sketch is None
    (element,) = stage.elements
    assert element.key == "architecture.soa.element[0]"
    assert (element.new, element.location, element.added, element.delta_vg) == (
        True,
        Location.NEW,
        30,
        8,
    )
    assert element.delta_loc == 30
    assert element.dynamic_links[1] == PlannedLink(
        "send", 2, "a.py", "architecture.soa.element[0].dynamic_links[1]"
    )
    p2p = plan.architectures[1]
    assert [(s.label, s.sketch.kind if s.sketch else None) for s in p2p.stages] == [
        ("first", SketchKind.REVISION),
        ("second", SketchKind.PATCH),
    ]
    assert plan.architectures[2].stages[0].elements == ()
    assert _validator().is_valid(tomllib.loads(GOOD))


BAD = [
    ("x = 1\n", "x: unknown key"),
    ("", "architecture: missing"),
    ('schema = "archmetrics.plan/9"\n[architecture.a]\nelement = []\n', "schema: must be"),
    ("[architecture.a]\n", "architecture.a: needs exactly one of element, sketch or stage"),
    (
        '[architecture.a]\nelement = []\nsketch = { revision = "x" }\n',
        "architecture.a: needs exactly one of",
    ),
    ('[architecture."a b"]\nelement = []\n', "architecture.a b: an architecture's name is"),
    ("[[architecture.a.element]]\nnew = true\n", "architecture.a.element[0].name: missing"),
    (
        '[[architecture.a.element]]\nname = "x"\nstatements_added = 1.5\n',
        "architecture.a.element[0].statements_added: must be an integer >= 0",
    ),
    (
        '[[architecture.a.element]]\nname = "x"\ndecisions_added = 10000001\n',
        "architecture.a.element[0].decisions_added: must be an integer >= 0 and <= 10000000",
    ),
    (
        '[[architecture.a.element]]\nname = "x"\nnew = "yes"\n',
        "architecture.a.element[0].new: must be true or false",
    ),
    (
        '[[architecture.a.element]]\nname = "x"\nstatic_dependencies = "y"\n',
        "architecture.a.element[0].static_dependencies: must be an array",
    ),
    (
        '[[architecture.a.element]]\nname = "x"\ndynamic_links = [{ to = "y" }]\n',
        "architecture.a.element[0].dynamic_links[0].rule: missing",
    ),
    (
        '[[architecture.a.element]]\nname = "x\\u001b[31m"\n',
        "architecture.a.element[0].name: must be at most 512 printable characters",
    ),
    (
        '[architecture.a]\nsketch = { revision = "x", patch = "y" }\n',
        "architecture.a.sketch: needs exactly one of revision, patch or stubs",
    ),
    ('[architecture.a]\nsketch = { branch = "x" }\n', "architecture.a.sketch.branch: unknown key"),
    ("[[architecture.a.stage]]\nelement = []\n", "architecture.a.stage[0].label: missing"),
    (
        '[[architecture.a.stage]]\nlabel = "one"\nelement = []\n'
        '[[architecture.a.stage]]\nlabel = "one"\nelement = []\n',
        "architecture.a.stage[1].label: stage 'one' given twice",
    ),
]


@pytest.mark.parametrize(("text", "expected"), BAD)
def test_a_bad_plan_names_the_file_and_the_key(text: str, expected: str) -> None:
    with pytest.raises(PlanError) as raised:
        _read(text)
    assert str(raised.value).startswith("p.toml: ")
    assert expected in str(raised.value)
    assert "\n" not in str(raised.value)


# a JSON Schema cannot say that two array items differ in one property (stage labels)
SCHEMA_CAN_SAY = [(text, expected) for text, expected in BAD if "given twice" not in expected]


@pytest.mark.parametrize(("text", "expected"), SCHEMA_CAN_SAY)
def test_the_schema_refuses_what_the_reader_refuses(text: str, expected: str) -> None:
    assert not _validator().is_valid(tomllib.loads(text))


def test_text_that_is_not_toml_or_not_utf8_or_too_large_is_refused_whole() -> None:
    for data, expected in (
        (b"[architecture\n", "p.toml: not valid TOML"),
        (b"title = '\xff'\n", "p.toml: not UTF-8 text"),
        (b"#" * 1_000_001, "p.toml: a plan may hold at most 1000000 bytes"),
    ):
        with pytest.raises(PlanError, match=expected):
            read_plan(data, "p.toml")
