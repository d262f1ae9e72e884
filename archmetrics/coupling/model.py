"""Coupling options and results: frozen values, each traceable to the lines behind it."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from archmetrics.coupling.elements import Element
from archmetrics.coupling.rules import LinkKind, Role
from archmetrics.facts import DependencyKind


@dataclass(frozen=True, slots=True)
class CouplingOptions:
    """How dependencies are resolved and elements formed.

    ``python_roots``: folders (tree-relative, "" = the root) that absolute imports are
    resolved from; None detects them (the root, ``src`` and the parents of top-level
    packages). ``include_dirs``: tree-relative folders searched for ``#include`` after the
    including file's own folder.
    """

    ignore_includes: tuple[str, ...] = ("stdio.h", "stdlib.h")  # thesis page 110
    ignore_imports: tuple[str, ...] = ("__future__",)
    include_dirs: tuple[str, ...] = ()
    per_file: bool = False
    python_roots: tuple[str, ...] | None = None
    group: str = "component"  # component | file | package | node (elements.py)

    @property
    def grouping(self) -> str:
        """How files are grouped into elements: ``per_file`` is ``"file"``."""
        return "file" if self.per_file else self.group


class Resolution(StrEnum):
    """Where a dependency or link points: inside the measured tree, outside, or unknown."""

    INTERNAL = "internal"
    EXTERNAL = "external"
    UNRESOLVED = "unresolved"


@dataclass(frozen=True, slots=True, order=True)
class SourceRef:
    """A place in the source: tree-relative path and 1-based line."""

    path: str
    line: int


@dataclass(frozen=True, slots=True)
class StaticDependency:
    """One distinct static dependency of an element (an include or an imported module).

    ``name`` is the module (``pkg.mod``) or include path as written (``net/util.h``);
    ``target_file`` and ``target_element`` are set when it resolves inside the tree.
    ``counted`` is False for a dependency on the element itself (a header included by its
    own implementation file), which the element's s_e does not count.
    """

    name: str
    kind: DependencyKind
    resolution: Resolution
    sites: tuple[SourceRef, ...]
    target_file: str | None = None
    target_element: str | None = None
    counted: bool = True
    note: str = ""


@dataclass(frozen=True, slots=True, order=True)
class Endpoint:
    """A link endpoint read from the source: ``key`` is its normalized form (``port:5555``)."""

    key: str
    text: str  # as written, e.g. "tcp://*:5555" or PORT
    via: str = "argument"  # argument | constant | same-function | callee
    # more keys the site receives on (a tf listener: topic:/tf and topic:/tf_static)
    also: tuple[str, ...] = ()


class LinkStatus(StrEnum):
    RESOLVED = "resolved"  # the endpoint matches receiving sites in other elements
    EXTERNAL = "external"  # the endpoint was read but nothing in the tree receives it
    UNRESOLVED = "unresolved"  # the endpoint cannot be read statically
    LOCAL = "local"  # a run-time linkage with no endpoint to follow (role "use")


@dataclass(frozen=True, slots=True)
class LinkSite:
    """One dynamic linkage occurrence (+1 to its element's d_e, thesis page 110)."""

    path: str
    line: int
    rule: str  # qualified rule id, pack/rule
    kind: LinkKind
    role: Role
    callee: str
    endpoint: Endpoint | None
    status: LinkStatus
    targets: tuple[str, ...] = ()  # elements this site links into
    function: str | None = None
    note: str = ""  # why the endpoint is unknown, when it is known why (several values ...)
    # a graph name (ROS): the name as read, before it is resolved against its node
    name: str = ""
    # the node the site is made in, as the code names it (/ns/talker); of a launch file's
    # entry: the node it starts
    node: str = ""
    data_type: str = ""  # the message, service or action type (geometry_msgs/msg/Twist)
    parameter: str = ""  # the parameter whose default gave the name ("" if none)


class EdgeKind(StrEnum):
    STATIC = "static"
    DYNAMIC = "dynamic"


@dataclass(frozen=True, slots=True, order=True)
class GraphEdge:
    """A directed link between two elements; ``label`` is the endpoint or the dependency."""

    source: str
    target: str
    kind: EdgeKind
    label: str
    weight: int = 1  # link sites (dynamic) or dependency sites (static) behind the edge


@dataclass(frozen=True, slots=True)
class ElementGraph:
    """The element graph: every element, static edges and resolved dynamic edges."""

    nodes: tuple[Element, ...]
    edges: tuple[GraphEdge, ...]


@dataclass(frozen=True, slots=True)
class ElementCoupling:
    """Static and dynamic, afferent and efferent coupling of one element (thesis 6.1-6.10).

    s_e: distinct counted static dependencies. s_a: distinct other elements depending on it.
    d_e: its link sites. d_a: link sites of other elements that resolve to it.
    """

    element: Element
    s_a: int
    s_e: int
    d_a: int
    d_e: int
    dependencies: tuple[StaticDependency, ...]
    link_sites: tuple[LinkSite, ...]
    dependents: tuple[str, ...] = ()  # the elements behind s_a
    incoming_sites: tuple[LinkSite, ...] = ()  # the sites behind d_a


@dataclass(frozen=True, slots=True)
class CouplingReport:
    """Coupling of every element of a tree, and the element graph."""

    elements: tuple[ElementCoupling, ...]
    graph: ElementGraph

    def element(self, name: str) -> ElementCoupling:
        """The coupling of the element called ``name`` (KeyError when there is none)."""
        for coupling in self.elements:
            if coupling.element.name == name:
                return coupling
        raise KeyError(name)

    def of_file(self, path: str) -> ElementCoupling:
        """The coupling of the element holding ``path``."""
        for coupling in self.elements:
            if path in coupling.element.files:
                return coupling
        raise KeyError(path)

    @property
    def unresolved_dependencies(self) -> tuple[StaticDependency, ...]:
        unresolved = Resolution.UNRESOLVED
        return tuple(d for c in self.elements for d in c.dependencies if d.resolution is unresolved)

    @property
    def unresolved_sites(self) -> tuple[LinkSite, ...]:
        return tuple(
            s for c in self.elements for s in c.link_sites if s.status is LinkStatus.UNRESOLVED
        )
