"""The XML and YAML configuration readers (ROS launch, parameter and plugin files): every
element or mapping a table, with its line and its parent; hostile input is refused, never
expanded, fetched or run."""

from __future__ import annotations

import time

from hypothesis import given, settings
from hypothesis import strategies as st

from archmetrics.facts import ConfigTable, Severity
from archmetrics.parsers import LanguageTable, config_xml, config_yaml, parse_source

TABLE = LanguageTable.default(plugins=False)

LAUNCH_XML = """<?xml version="1.0"?>
<launch>
  <!-- a comment -->
  <node pkg="demo_nodes_cpp" exec="talker" name="my_talker" namespace="robot1">
    <remap from="chatter" to="/robot1/chat"/>
    <param name="rate" value="2.0"/>
  </node>
  <group>
    <node pkg="demo_nodes_cpp" exec="listener"/>
  </group>
  <x:tag xmlns:x="http://example.com/x">text here</x:tag>
</launch>
"""


def test_each_xml_element_is_a_table_with_its_attributes_line_and_parent() -> None:
    facts = config_xml.parse("talker.launch.xml", LAUNCH_XML)
    assert facts.parsed, facts.warnings
    assert list(facts.tables) == [
        ConfigTable(("launch",), 2, (), -1),
        ConfigTable(
            ("launch", "node"),
            4,
            (
                ("pkg", ("demo_nodes_cpp",)),
                ("exec", ("talker",)),
                ("name", ("my_talker",)),
                ("namespace", ("robot1",)),
            ),
            0,
        ),
        ConfigTable(
            ("launch", "node", "remap"), 5, (("from", ("chatter",)), ("to", ("/robot1/chat",))), 1
        ),
        ConfigTable(("launch", "node", "param"), 6, (("name", ("rate",)), ("value", ("2.0",))), 1),
        ConfigTable(("launch", "group"), 8, (), 0),
        ConfigTable(
            ("launch", "group", "node"),
            9,
            (("pkg", ("demo_nodes_cpp",)), ("exec", ("listener",))),
            4,
        ),
        ConfigTable(("launch", "tag"), 11, (("#text", ("text here",)),), 0),
    ]


def test_xml_entities_are_never_expanded_nor_fetched() -> None:
    laughs = "".join(f'<!ENTITY l{i} "{f"&l{i - 1};" * 10}">' for i in range(1, 10))
    bomb = f'<?xml version="1.0"?><!DOCTYPE b [<!ENTITY l0 "lol">{laughs}]><b a="&l9;">&l9;</b>'
    started = time.process_time()
    facts = config_xml.parse("bomb.xml", bomb)
    assert time.process_time() - started < 2
    assert not facts.parsed and "not valid XML" in facts.warnings[0].message
    external = (
        '<?xml version="1.0"?><!DOCTYPE x [<!ENTITY e SYSTEM "file:///etc/passwd">]><x>&e;</x>'
    )
    refused = config_xml.parse("x.xml", external)  # refused before anything is opened
    assert not refused.parsed and "declares an entity" in refused.warnings[0].message
    undeclared = config_xml.parse("u.xml", "<x>&e;</x>")  # no entity of any kind is read
    assert not undeclared.parsed and "not valid XML" in undeclared.warnings[0].message


def test_xml_too_deep_or_broken_is_not_measured() -> None:
    deep = config_xml.parse("deep.xml", "<a>" * 300 + "</a>" * 300)
    assert not deep.parsed and deep.warnings[0].severity is Severity.ERROR
    broken = config_xml.parse("b.xml", "<launch>\n<node>\n</launch>\n")
    assert not broken.parsed
    assert broken.warnings[0].line == 3


PARAMS = """controller_server:
  ros__parameters:
    controller_frequency: 20.0
    plugins: ["FollowPath"]
    FollowPath:
      plugin: "dwb_core::DWBLocalPlanner"
/**:
  ros__parameters:
    use_sim_time: true
launch:
  - node:
      pkg: demo_nodes_cpp
      exec: talker
      remap:
        - {from: chatter, to: chat}
"""


def test_each_yaml_mapping_is_a_table_with_its_scalars_line_and_parent() -> None:
    facts = config_yaml.parse("nav2_params.yaml", PARAMS)
    assert facts.parsed, facts.warnings
    assert list(facts.tables) == [
        ConfigTable((), 1, (), -1),
        ConfigTable(("controller_server",), 1, (), 0),  # a mapping's line: its key's
        ConfigTable(
            ("controller_server", "ros__parameters"),
            2,
            (("controller_frequency", ("20.0",)), ("plugins", ("FollowPath",))),
            1,
        ),
        ConfigTable(
            ("controller_server", "ros__parameters", "FollowPath"),
            5,
            (("plugin", ("dwb_core::DWBLocalPlanner",)),),
            2,
        ),
        ConfigTable(("/**",), 7, (), 0),
        ConfigTable(("/**", "ros__parameters"), 8, (("use_sim_time", ("true",)),), 4),
        ConfigTable(("launch",), 11, (), 0),  # in a sequence: where the mapping starts
        ConfigTable(
            ("launch", "node"), 11, (("pkg", ("demo_nodes_cpp",)), ("exec", ("talker",))), 6
        ),
        ConfigTable(
            ("launch", "node", "remap"), 15, (("from", ("chatter",)), ("to", ("chat",))), 7
        ),
    ]


def test_yaml_aliases_are_read_once_and_tags_never_constructed() -> None:
    rows = ["a: &a [lol, lol]"] + [
        f"{chr(98 + i)}: &{chr(98 + i)} [{', '.join([f'*{chr(97 + i)}'] * 9)}]" for i in range(8)
    ]
    started = time.process_time()
    facts = config_yaml.parse("laughs.yaml", "\n".join(rows) + "\n")
    assert time.process_time() - started < 2
    assert facts.parsed and len(facts.tables) == 1
    code = config_yaml.parse("x.yaml", '!!python/object/apply:os.system ["touch /tmp/owned"]\n')
    assert code.tables == ()  # composed, never constructed: no mapping, nothing ran


def test_yaml_broken_too_deep_or_too_large_is_not_measured() -> None:
    broken = config_yaml.parse("b.yaml", "a:\n  b: [1, 2\nc: 3\n")
    assert not broken.parsed and "not valid YAML" in broken.warnings[0].message
    deep = config_yaml.parse("d.yaml", "[" * 5000 + "]" * 5000)
    assert not deep.parsed
    large = config_yaml.parse("l.yaml", "a: " + "x" * (config_yaml.MAX_BYTES + 1))
    assert not large.parsed and "larger than" in large.warnings[0].message
    nested = "".join(f"{'  ' * i}k{i}:\n" for i in range(40)) + "  " * 40 + "v: 1\n"
    facts = config_yaml.parse("n.yaml", nested)
    assert facts.parsed and "deeper than" in facts.warnings[0].message


def test_the_registry_reads_both_formats_by_name() -> None:
    xml = parse_source("p.xml", b"<package><name>demo</name></package>", "xml", TABLE)
    assert xml.tables[1] == ConfigTable(("package", "name"), 1, (("#text", ("demo",)),), 0)
    yaml = parse_source("p.yaml", b"a: 1\n", "yaml", TABLE)
    assert yaml.tables == (ConfigTable((), 1, (("a", ("1",)),), -1),)


@settings(max_examples=200, deadline=None)
@given(st.text(max_size=300))
def test_any_text_is_read_or_refused_never_raised(text: str) -> None:
    for reader in (config_xml.parse, config_yaml.parse):
        facts = reader("f", text)
        assert facts.parsed or facts.warnings
