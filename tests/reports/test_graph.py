"""The element graph rendered as dot, Mermaid and JSON, from a real measured tree."""

from __future__ import annotations

import json
import shutil
import subprocess

import pydot
import pytest

from archmetrics.coupling import EdgeKind, ElementGraph, GraphEdge, group_elements
from archmetrics.reports.graph import SCHEMA, GraphFormat, render
from tests.coupling.trees import measure


@pytest.fixture(scope="module")
def graph() -> ElementGraph:
    return measure(
        {
            "nav/publisher.py": "import robosoa\nfrom nav import util\n\ndef go(bus):\n"
            "    bus.publish('pose', {})\n    bus.publish('pose', {})\n",
            "nav/subscriber.py": (
                "import robosoa\n\ndef go(bus, cb):\n    bus.subscribe('pose', cb)\n"
            ),
            "nav/util.py": "",
            "drv/motor.c": '#include "motor.h"\nint m;\n',
            "drv/motor.h": "int m;\n",
        }
    ).graph


def test_dot_has_boxes_solid_static_and_dashed_dynamic_edges(graph: ElementGraph) -> None:
    dot = render(graph, "dot")
    assert dot.startswith("digraph coupling {")
    assert '"drv/motor" [label="drv/motor (motor.c, motor.h)"];' in dot
    assert '"nav/publisher.py" -> "nav/util.py" [label="nav.util", style=solid];' in dot
    assert '"nav/publisher.py" -> "nav/subscriber.py" [label="topic:pose x2", style=dashed];' in dot


def test_a_dot_parser_reads_back_every_node_and_edge(graph: ElementGraph) -> None:
    [parsed] = pydot.graph_from_dot_data(render(graph, "dot"))
    names = {node.get_name().strip('"') for node in parsed.get_nodes()} - {"node", "edge"}
    assert names == {n.name for n in graph.nodes}
    edges = {
        (e.get_source().strip('"'), e.get_destination().strip('"')) for e in parsed.get_edges()
    }
    assert edges == {(e.source, e.target) for e in graph.edges}


@pytest.mark.skipif(shutil.which("dot") is None, reason="Graphviz is not installed")
def test_graphviz_accepts_the_dot(graph: ElementGraph) -> None:
    done = subprocess.run(["dot", "-Tsvg"], input=render(graph, "dot"), capture_output=True,
                          text=True, timeout=30)  # fmt: skip
    assert done.returncode == 0, done.stderr


def test_mermaid_uses_ids_and_quoted_labels(graph: ElementGraph) -> None:
    mermaid = render(graph, GraphFormat.MERMAID).splitlines()
    assert mermaid[0] == "flowchart LR"
    nodes = [line.strip().split("[", 1) for line in mermaid if line.endswith('"]')]
    ids = {label[1:-2]: node_id for node_id, label in nodes}
    pub, sub, util = ids["nav/publisher.py"], ids["nav/subscriber.py"], ids["nav/util.py"]
    assert f'  {pub} -.->|"topic:pose x2"| {sub}' in mermaid
    assert f'  {pub} -->|"nav.util"| {util}' in mermaid


def test_json_is_versioned_and_round_trips_the_graph(graph: ElementGraph) -> None:
    document = json.loads(render(graph, "json"))
    assert document["schema"] == SCHEMA
    assert [n["name"] for n in document["nodes"]] == [n.name for n in graph.nodes]
    edges = [GraphEdge(e["source"], e["target"], EdgeKind(e["kind"]), e["label"], e["weight"])
             for e in document["edges"]]  # fmt: skip
    assert tuple(edges) == graph.edges
    assert {"source": "nav/publisher.py", "target": "nav/subscriber.py", "kind": "dynamic",
            "label": "topic:pose", "weight": 2, "role": None} in document["edges"]  # fmt: skip
    assert document["view"] == "elements"


def test_labels_with_quotes_are_escaped() -> None:
    nodes = group_elements(['we"ird.py', "b.py"])
    graph = ElementGraph(nodes, (GraphEdge('we"ird.py', "b.py", EdgeKind.DYNAMIC, 'topic:"x"'),))
    assert '"we\\"ird.py" -> "b.py" [label="topic:\\"x\\"", style=dashed];' in render(graph, "dot")
    assert "#quot;" in render(graph, "mermaid") and '"x"' not in render(graph, "mermaid")


def test_an_unknown_format_is_refused(graph: ElementGraph) -> None:
    with pytest.raises(ValueError, match="svg"):
        render(graph, "svg")
