"""The element graph as Graphviz dot, Mermaid or JSON: pure functions returning text.

Static edges are solid and labelled with the dependency (``common.h``, ``pkg.mod``); dynamic
edges are dashed and labelled with their endpoint (``topic:pose``), with ``x2`` when more
than one link site makes the edge. JSON is versioned: ``"schema": "archmetrics.graph/1"``.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from enum import StrEnum
from pathlib import PurePosixPath

from archmetrics.coupling.computation import ComputationGraph, FlowEdge
from archmetrics.coupling.elements import Element
from archmetrics.coupling.model import EdgeKind, ElementGraph, GraphEdge

SCHEMA = "archmetrics.graph/1"


class GraphFormat(StrEnum):
    DOT = "dot"
    MERMAID = "mermaid"
    JSON = "json"


def node_label(element: Element) -> str:
    """The element's name, with its file names when the name does not say them."""
    if element.files == (element.name,):
        return element.name
    return f"{element.name} ({', '.join(PurePosixPath(f).name for f in element.files)})"


def edge_label(edge: GraphEdge) -> str:
    """The dependency or endpoint, with the number of sites when there are several."""
    return edge.label if edge.weight == 1 else f"{edge.label} x{edge.weight}"


def _dot_text(text: str) -> str:
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"') + '"'


def render_dot(graph: ElementGraph) -> str:
    """Graphviz dot: boxes for elements, solid static and dashed dynamic edges."""
    lines = ["digraph coupling {", "  rankdir=LR;", "  node [shape=box];"]
    for node in graph.nodes:
        lines.append(f"  {_dot_text(node.name)} [label={_dot_text(node_label(node))}];")
    for edge in graph.edges:
        style = "solid" if edge.kind is EdgeKind.STATIC else "dashed"
        lines.append(
            f"  {_dot_text(edge.source)} -> {_dot_text(edge.target)}"
            f" [label={_dot_text(edge_label(edge))}, style={style}];"
        )
    lines.append("}")
    return "\n".join(lines) + "\n"


_MERMAID_CODES = {"#": "#35;", '"': "#quot;", "<": "#60;", ">": "#62;", "&": "#38;", "`": "#96;",
                  "\n": "#92;n", "\r": "#92;r", "\t": "#92;t"}  # fmt: skip


def _mermaid_text(text: str) -> str:
    """A quoted Mermaid label: every character Mermaid or the HTML it renders would read
    (an entity's ``#``, quotes, ``<``, ``>``, ``&``, a markdown string's backtick, line
    breaks) written as Mermaid's entity code, so a name is only ever text."""
    return '"' + "".join(_MERMAID_CODES.get(char, char) for char in text) + '"'


def render_mermaid(graph: ElementGraph) -> str:
    """A Mermaid flowchart: ``-->`` for static edges, ``-.->`` for dynamic ones."""
    ids = {node.name: f"n{index}" for index, node in enumerate(graph.nodes)}
    lines = ["flowchart LR"]
    for node in graph.nodes:
        lines.append(f"  {ids[node.name]}[{_mermaid_text(node_label(node))}]")
    for edge in graph.edges:
        arrow = "-->" if edge.kind is EdgeKind.STATIC else "-.->"
        label = _mermaid_text(edge_label(edge))
        lines.append(f"  {ids[edge.source]} {arrow}|{label}| {ids[edge.target]}")
    return "\n".join(lines) + "\n"


def render_json(graph: ElementGraph) -> str:
    """The graph as versioned JSON (schema ``archmetrics.graph/1``)."""
    document = {
        "schema": SCHEMA,
        "view": "elements",
        "nodes": [
            {
                "name": n.name,
                "files": list(n.files),
                "languages": list(n.languages),
                "kind": "element",
                "label": n.name,
                "ros_nodes": [],
            }
            for n in graph.nodes
        ],
        "edges": [
            {
                "source": e.source,
                "target": e.target,
                "kind": e.kind.value,
                "label": e.label,
                "weight": e.weight,
                "role": None,
            }
            for e in graph.edges
        ],
    }
    return json.dumps(document, indent=2) + "\n"


# how each kind of node of a computation graph is drawn (rqt_graph's: nodes round, topics
# boxed), in dot and in Mermaid (the text goes between the two halves)
_DOT_SHAPES = {"element": "ellipse", "topic": "box", "service": "hexagon",
               "action": "doubleoctagon", "plugin": "component", "launch": "note"}  # fmt: skip
_MERMAID_SHAPES = {"element": ("([", "])"), "topic": ("[", "]"), "service": ("{{", "}}"),
                   "action": ("[/", "/]"), "plugin": ("[[", "]]"),
                   "launch": (">", "]")}  # fmt: skip


def flow_label(edge: FlowEdge) -> str:
    return f"x{edge.weight}" if edge.weight > 1 else ""


def render_computation_dot(graph: ComputationGraph) -> str:
    """Graphviz dot of the computation graph: nodes (elements) round, topics boxed,
    services hexagons, actions double octagons, plugins components, launch files notes."""
    lines = ["digraph computation {", "  rankdir=LR;", '  node [fontname="Helvetica"];']
    for node in graph.nodes:
        tooltip = f", tooltip={_dot_text(node.name)}" if node.kind in ("element", "launch") else ""
        lines.append(
            f"  {_dot_text(node.name)} [label={_dot_text(node.label)},"
            f" shape={_DOT_SHAPES.get(node.kind, 'box')}{tooltip}];"
        )
    for edge in graph.edges:
        label = flow_label(edge)
        shown = f" [label={_dot_text(label)}]" if label else ""
        lines.append(f"  {_dot_text(edge.source)} -> {_dot_text(edge.target)}{shown};")
    lines.append("}")
    return "\n".join(lines) + "\n"


def render_computation_mermaid(graph: ComputationGraph) -> str:
    """A Mermaid flowchart of the computation graph, shaped as the dot one."""
    ids = {node.name: f"n{index}" for index, node in enumerate(graph.nodes)}
    lines = ["flowchart LR"]
    for node in graph.nodes:
        start, end = _MERMAID_SHAPES.get(node.kind, ("[", "]"))
        lines.append(f"  {ids[node.name]}{start}{_mermaid_text(node.label)}{end}")
    for edge in graph.edges:
        label = flow_label(edge)
        arrow = f"-->|{_mermaid_text(label)}|" if label else "-->"
        lines.append(f"  {ids[edge.source]} {arrow} {ids[edge.target]}")
    return "\n".join(lines) + "\n"


def render_computation_json(graph: ComputationGraph) -> str:
    """The computation graph as ``archmetrics.graph/1`` JSON: ``view`` "computation", a
    node's ``kind`` its endpoint type (or "element"), an edge's ``role``."""
    document = {
        "schema": SCHEMA,
        "view": "computation",
        "nodes": [
            {"name": n.name, "files": list(n.files), "languages": list(n.languages),
             "kind": n.kind, "label": n.label, "ros_nodes": list(n.nodes)}
            for n in graph.nodes
        ],
        "edges": [
            {"source": e.source, "target": e.target, "kind": "dynamic",
             "label": e.target if e.role == "initiate" else e.source, "weight": e.weight,
             "role": e.role}
            for e in graph.edges
        ],
    }  # fmt: skip
    return json.dumps(document, indent=2) + "\n"


COMPUTATION_RENDERERS: Mapping[GraphFormat, Callable[[ComputationGraph], str]] = {
    GraphFormat.DOT: render_computation_dot,
    GraphFormat.MERMAID: render_computation_mermaid,
    GraphFormat.JSON: render_computation_json,
}
assert set(COMPUTATION_RENDERERS) == set(GraphFormat), "every format needs a renderer"


RENDERERS: Mapping[GraphFormat, Callable[[ElementGraph], str]] = {
    GraphFormat.DOT: render_dot,
    GraphFormat.MERMAID: render_mermaid,
    GraphFormat.JSON: render_json,
}
assert set(RENDERERS) == set(GraphFormat), "every graph format needs a renderer"


def render(graph: ElementGraph | ComputationGraph, format: GraphFormat | str) -> str:
    """Render ``graph`` in ``format`` (``dot``, ``mermaid`` or ``json``)."""
    if isinstance(graph, ComputationGraph):
        return COMPUTATION_RENDERERS[GraphFormat(format)](graph)
    return RENDERERS[GraphFormat(format)](graph)
