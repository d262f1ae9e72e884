"""Service descriptors: schema and semantic errors name file, line and field; good ones load."""

from __future__ import annotations

from pathlib import Path

import pytest

import robosoa
from robosoa.descriptor import (
    Actor,
    DescriptorError,
    Encoding,
    ImplementationForm,
    Language,
    OperatingSystem,
    Packaging,
    Pattern,
    Profile,
    ServiceDescriptor,
    TypeRef,
    load,
    loads,
)

EXAMPLE = Path(robosoa.__file__).parent / "data" / "examples" / "wdb.xml"

INVENTORY = """\
<?xml version="1.0"?>
<service name="inventory" version="2.1.0" format="1">
  <definition>Parts inventory.</definition>
  <pattern>request-response</pattern>
  <types>
    <struct name="Item">
      <definition>One stocked part.</definition>
      <field name="sku" type="string"/>
      <field name="count" type="int"/>
      <field name="tags" type="list[string]" required="false"/>
      <field name="bin" type="Bin" required="false"/>
    </struct>
    <struct name="Bin">
      <field name="row" type="int"/>
      <field name="shelf" type="int" default="1"/>
    </struct>
  </types>
  <operation name="lookup">
    <definition>Find parts.</definition>
    <param name="sku" type="string" definition="part number"/>
    <param name="limit" type="int" default="10"/>
    <return name="items" type="list[Item]"/>
    <return name="total" type="float"/>
  </operation>
  <operation name="reset"/>
  <participant actor="provider" packaging="provider-library" group="stores">
    <target language="python" os="linux"/>
    <implementation form="library" library="inventory_impl">
      <function operation="lookup" symbol="find_parts"/>
    </implementation>
    <codegen profile="unchecked"/>
  </participant>
  <participant actor="consumer" packaging="consumer-source"/>
</service>
"""


def problems(text: str, source: str = "svc.xml") -> list[str]:
    """The one-line problems of a descriptor expected to be invalid."""
    with pytest.raises(DescriptorError) as caught:
        loads(text, source=source)
    return [str(p) for p in caught.value.problems]


def service(body: str, pattern: str = "request-response") -> str:
    """A descriptor around ``body``: line 1 is <service>, line 2 <pattern>, body from line 3."""
    return f'<service name="svc" version="1.0.0">\n<pattern>{pattern}</pattern>\n{body}\n</service>'


def test_example_wdb_loads_to_dataclasses() -> None:
    d = load(EXAMPLE)
    assert (d.name, d.version, d.pattern) == ("wdb", "1.0.0", Pattern.REQUEST_RESPONSE)
    assert [op.name for op in d.operations] == ["query", "update"]
    query = d.operations[0]
    assert query.parameters[0].name == "request"
    assert query.parameters[0].type == TypeRef("string")
    assert query.returns[0].name == "result"
    provider = d.participant(Packaging.PROVIDER_EXECUTABLE)
    assert provider is not None and provider.implementation is not None
    assert provider.implementation.encoding is Encoding.TEXT
    assert provider.implementation.command("query") is not None
    assert provider.os is OperatingSystem.POSIX
    assert d.source == str(EXAMPLE)


def test_inventory_fields_types_and_participants() -> None:
    d = loads(INVENTORY, source="inventory.xml")
    assert isinstance(d, ServiceDescriptor)
    item = d.type("Item")
    assert item is not None and item.line == 6 and item.definition == "One stocked part."
    tags = item.fields[2]
    assert tags.type == TypeRef("list", TypeRef("string")) and not tags.required
    shelf = d.types[1].fields[1]
    assert shelf.default == "1" and not shelf.required
    lookup = d.operation("lookup")
    assert lookup is not None and lookup.line == 18
    assert [(p.name, p.required) for p in lookup.parameters] == [("sku", True), ("limit", False)]
    assert str(lookup.returns[0].type) == "list[Item]"
    provider = d.participants[0]
    assert provider.actor is Actor.PROVIDER and provider.group == "stores"
    assert provider.language is Language.PYTHON and provider.profile is Profile.UNCHECKED
    assert provider.implementation is not None
    assert provider.implementation.form is ImplementationForm.LIBRARY
    assert provider.implementation.symbol("lookup") == "find_parts"
    assert provider.implementation.symbol("reset") == "reset"
    consumer = d.participants[1]
    assert consumer.naming.package == "inventory_client"
    assert consumer.naming.class_name == "InventoryClient"
    assert provider.naming.module == "provider"


def test_not_well_formed_xml_names_the_line() -> None:
    found = problems('<service name="x" version="1.0.0">\n<pattern>\n</service>')
    assert len(found) == 1 and found[0].startswith("svc.xml:3: not well-formed XML")


@pytest.mark.parametrize(
    ("body", "expected"),
    [
        (
            '<operation name="q"><param name="x" type="int" required="yes"/></operation>',
            "svc.xml:3: operation 'q' parameter 'x' attribute 'required': 'yes' is not a valid",
        ),
        (
            '<operation name="q"><param name="x"/></operation>',
            "svc.xml:3: operation 'q' parameter 'x': The attribute 'type' is required",
        ),
        (
            '<operation name="q"><return name="r" type="int"/><param name="x" type="int"/>'
            "</operation>",
            "svc.xml:3: operation 'q' parameter 'x': This element is not expected",
        ),
        (
            '<operation name="q"/>\n<participant actor="robot" packaging="consumer-source"/>',
            "svc.xml:4: participant 'consumer-source' attribute 'actor': [facet 'enumeration']",
        ),
        (
            '<operation name="2bad"/>',
            "svc.xml:3: operation '2bad' attribute 'name': [facet 'pattern']",
        ),
    ],
)
def test_schema_errors_name_line_and_field(body: str, expected: str) -> None:
    assert any(p.startswith(expected) for p in problems(service(body))), problems(service(body))


def test_schema_error_on_service_attributes_and_pattern() -> None:
    text = (
        '<service name="svc" version="1.0">\n<pattern>chatty</pattern>\n'
        '<operation name="q"/>\n</service>'
    )
    found = problems(text)
    assert found[0].startswith("svc.xml:1: service attribute 'version':")
    assert found[1].startswith("svc.xml:2: pattern: [facet 'enumeration'] The value 'chatty'")


@pytest.mark.parametrize(
    ("body", "pattern", "expected"),
    [
        (
            '<operation name="query">\n<param name="x" type="flot"/></operation>',
            "request-response",
            "svc.xml:4: operation 'query' parameter 'x': unknown type 'flot'",
        ),
        (
            '<operation name="q">\n<return name="r" type="list[Row]"/></operation>',
            "request-response",
            "svc.xml:4: operation 'q' return 'r': unknown type 'Row'",
        ),
        (
            '<operation name="q"/>\n<operation name="q"/>',
            "request-response",
            "svc.xml:4: operation 'q': duplicate (first at line 3)",
        ),
        (
            '<operation name="q"><param name="a" type="int"/>\n<param name="a" type="int"/>'
            "</operation>",
            "request-response",
            "svc.xml:4: operation 'q' parameter or return 'a': duplicate (first at line 3)",
        ),
        (
            '<operation name="tick">\n<return name="n" type="int"/></operation>',
            "one-way",
            "svc.xml:4: operation 'tick' return 'n': pattern 'one-way' has no replies",
        ),
        (
            '<operation name="q">\n<param name="n" type="int" default="ten"/></operation>',
            "request-response",
            "svc.xml:4: operation 'q' parameter 'n': default 'ten' is not a valid int",
        ),
        (
            '<operation name="q">\n<param name="n" type="int" required="true" default="1"/>'
            "</operation>",
            "request-response",
            "svc.xml:4: operation 'q' parameter 'n': a required value cannot have a default",
        ),
        (
            '<operation name="q">\n<param name="lambda" type="int"/></operation>',
            "request-response",
            "svc.xml:4: operation 'q' parameter 'lambda': 'lambda' is a reserved word",
        ),
        (
            '<types>\n<struct name="Node"><field name="next" type="list[Node]"/></struct></types>'
            '<operation name="q"/>',
            "request-response",
            "svc.xml:4: type 'Node': recursive type",
        ),
    ],
)
def test_semantic_errors_name_line_and_field(body: str, pattern: str, expected: str) -> None:
    found = problems(service(body, pattern))
    assert any(p.startswith(expected) for p in found), found


@pytest.mark.parametrize(
    ("participant", "expected"),
    [
        (
            '<participant actor="consumer" packaging="provider-executable">'
            '<implementation form="executable"><command>prog</command></implementation>'
            "</participant>",
            "participant 'provider-executable': packaging is for a provider",
        ),
        (
            '<participant actor="provider" packaging="provider-executable">\n'
            '<implementation form="executable"><command operation="q">prog</command>'
            "</implementation></participant>",
            "participant 'provider-executable' implementation: no command for operation 'r'",
        ),
        (
            '<participant actor="provider" packaging="provider-executable">\n'
            '<implementation form="library" library="m"/></participant>',
            "implementation: form 'library' does not fit packaging 'provider-executable'",
        ),
        (
            '<participant actor="provider" packaging="provider-library">\n'
            '<implementation form="library" library="m">'
            '<function operation="nope" symbol="f"/></implementation></participant>',
            "participant 'provider-library' implementation: unknown operation 'nope'",
        ),
        (
            '<participant actor="provider" packaging="provider-library">\n'
            '<target language="c"/><implementation form="library" library="./x.so"/>'
            "</participant>",
            "operation 'q' 'items': type 'list[int]' cannot cross a C call",
        ),
        (
            '<participant actor="provider" packaging="provider-executable">\n'
            '<implementation form="executable" encoding="text"><command>p</command>'
            "</implementation></participant>",
            "encoding 'text' needs operation 'q' to take one string",
        ),
        (
            '<participant actor="consumer" packaging="consumer-no-source"/>',
            "participant 'consumer-no-source': needs an <implementation>",
        ),
    ],
)
def test_participant_mismatches(participant: str, expected: str) -> None:
    body = (
        '<operation name="q"><param name="items" type="list[int]"/></operation>\n'
        '<operation name="r"/>\n' + participant
    )
    found = problems(service(body))
    assert any(expected in p and p.startswith("svc.xml:") for p in found), found


def test_pattern_forbids_packaging() -> None:
    body = (
        '<operation name="reading"><param name="v" type="float"/></operation>\n'
        '<participant actor="provider" packaging="provider-executable">'
        '<implementation form="executable"><command>p</command></implementation></participant>'
    )
    found = problems(service(body, "publish-subscribe"))
    assert found == [
        "svc.xml:4: participant 'provider-executable': pattern 'publish-subscribe' supports "
        "provider-library and consumer-source only"
    ]


def test_load_missing_file_is_a_descriptor_error(tmp_path: Path) -> None:
    with pytest.raises(DescriptorError, match="cannot read"):
        load(tmp_path / "absent.xml")


def test_load_reports_the_path_given(tmp_path: Path) -> None:
    path = tmp_path / "wdb.xml"
    path.write_text(service('<operation name="q">\n<param name="x" type="flot"/></operation>'))
    with pytest.raises(DescriptorError) as caught:
        load(path)
    assert str(caught.value) == f"{path}:4: operation 'q' parameter 'x': unknown type 'flot'"
