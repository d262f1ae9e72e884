"""The computation graph of a tree: its elements and the endpoints they link through (topics,
services, actions, plugins), as ``archmetrics graph`` draws it for a ROS tree
(docs/metrics.md, "The element graph").

Where the element graph links elements to elements, this one puts each endpoint between
them, as rqt_graph draws a ROS graph: an element that publishes, calls or loads points to
the topic, service, action or plugin, which points to the elements that subscribe, serve or
export it; an element is labelled with the ROS nodes its sites belong to. Parameters and
launch files are left out (they would hide the graph under configuration), as are sites
whose endpoint is unknown, and plugins nothing loads.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

from archmetrics.coupling.elements import Element
from archmetrics.coupling.model import CouplingReport, LinkSite
from archmetrics.coupling.rules import LinkKind, Role

SHOWN = ("topic", "service", "action", "plugin")  # endpoint types drawn as graph nodes


@dataclass(frozen=True, slots=True)
class GraphNode:
    """An element (``kind`` "element", or "launch" for a launch file; its ROS nodes in
    ``nodes``) or an endpoint (``kind`` its type, ``name`` its key)."""

    name: str
    kind: str
    label: str
    files: tuple[str, ...] = ()
    languages: tuple[str, ...] = ()
    nodes: tuple[str, ...] = ()


@dataclass(frozen=True, slots=True)
class FlowEdge:
    """An element to an endpoint it initiates (``initiate``), or an endpoint to an element
    receiving it (``receive``); ``weight``: the link sites behind it."""

    source: str
    target: str
    role: str
    weight: int = 1


@dataclass(frozen=True, slots=True)
class ComputationGraph:
    nodes: tuple[GraphNode, ...]
    edges: tuple[FlowEdge, ...]


def _keys(site: LinkSite) -> tuple[str, ...]:
    if site.endpoint is None or site.role is Role.USE:
        return ()
    keys = (site.endpoint.key, *site.endpoint.also)
    return tuple(k for k in keys if k.partition(":")[0] in SHOWN)


def computation_graph(report: CouplingReport) -> ComputationGraph:
    """The elements with a shown link site, the endpoints they link through, the flows."""
    flows: Counter[tuple[str, str, str]] = Counter()
    names: dict[str, set[str]] = {}
    code: set[str] = set()  # elements with a shown site that is no configuration
    for coupling in report.elements:
        element = coupling.element.name
        for site in coupling.link_sites:
            for key in _keys(site):
                if site.kind is not LinkKind.CONFIG:
                    code.add(element)
                if site.role is Role.INITIATE:
                    flows[(element, key, "initiate")] += 1
                else:
                    flows[(key, element, "receive")] += 1
                if site.node and site.kind is not LinkKind.CONFIG:  # a launch entry's
                    names.setdefault(element, set()).add(site.node)  # node: the one it starts
    loaded = {key for _, key, role in flows if role == "initiate"}
    flows = Counter({f: n for f, n in flows.items() if _shown(f, loaded)})
    linked = {element for element, _ in _ends(flows)}
    endpoints = {key for _, key in _ends(flows)}
    nodes = [_element_node(c.element, names, c.element.name in code)
             for c in report.elements if c.element.name in linked]  # fmt: skip
    nodes += [GraphNode(k, k.partition(":")[0], k.partition(":")[2]) for k in sorted(endpoints)]
    edges = tuple(FlowEdge(s, t, r, n) for (s, t, r), n in sorted(flows.items()))
    return ComputationGraph(tuple(nodes), edges)


def _shown(flow: tuple[str, str, str], loaded: set[str]) -> bool:
    """Whether a flow is drawn: a plugin only when something loads it (a component
    registered and never loaded is no part of the running graph)."""
    source, target, role = flow
    key = target if role == "initiate" else source
    return not key.startswith("plugin:") or key in loaded


def _ends(flows: Counter[tuple[str, str, str]]) -> list[tuple[str, str]]:
    """Each flow as (element, endpoint), whichever way it points."""
    return [(s, t) if role == "initiate" else (t, s) for s, t, role in flows]


def _element_node(element: Element, names: dict[str, set[str]], code: bool) -> GraphNode:
    """An element, labelled with its ROS nodes (``/talker``), else its name; a launch file
    (an element whose shown sites are all configuration) is of kind ``launch``."""
    found = tuple(sorted(names.get(element.name, ())))
    kind = "element" if code else "launch"
    label = ", ".join(found) or element.name
    return GraphNode(element.name, kind, label, element.files, element.languages, found)
