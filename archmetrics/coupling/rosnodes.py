"""The node a class's sites run in when the class's own file names none: the node of the
program that makes the class, in the same package (docs/metrics.md, "Names, as ROS resolves
them").

A ROS 1 node is often written as a class in one file (``move_base.cpp``: the publishers,
with private names such as ``~current_goal``) and a ``main`` in another
(``move_base_node.cpp``: ``ros::init(argc, argv, "move_base_node")``, then
``move_base::MoveBase move_base(buffer);``). The class's file names no node, so its private
names cannot be resolved there; the package's file that makes the class and names exactly one
node gives it. Read from the facts already extracted (the call sites of the package's files),
never from a file the scan did not read; a class that is exported as a plugin or component
(its node is its loader's) or made under two different nodes keeps its names unresolved.
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import replace

from archmetrics.coupling.endpoints import constants_of
from archmetrics.coupling.matching import constructed, last_name, matches, normalize_callee
from archmetrics.coupling.model import Endpoint, LinkSite
from archmetrics.coupling.rosnames import NodeName, UnresolvedName, resolve
from archmetrics.coupling.rules import Role, ScopeRule
from archmetrics.coupling.scopes import FileScopes, owner
from archmetrics.coupling.trace import plain_reader
from archmetrics.facts import FileFacts

#: the note of a site whose name waits for its node's name (rosnames.resolve)
UNKNOWN_NODE = "the node's name is not known statically"

# a declaration without arguments (``mover::Mover mover;``), which is no call site
_DECLARED = re.compile(r"\s*(?:const\s+)?([A-Za-z_][\w:]*)\s+[A-Za-z_]\w*\s*;\s*")

_MAKERS = frozenset({"make_shared", "make_unique"})  # std::make_shared<T>(...) makes a T

PackageOf = Callable[[str], str | None]


def with_package_nodes(
    sites: Mapping[str, tuple[LinkSite, ...]],
    by_path: Mapping[str, FileFacts],
    package_of: PackageOf,
    rules: Sequence[ScopeRule],
) -> dict[str, tuple[LinkSite, ...]]:
    """``sites`` (by element), each waiting for its node's name given the node of the
    program its class is made in, when the package says exactly one."""
    waiting = [s for found in sites.values() for s in found if _waits(s)]
    if not waiting or not rules:
        return dict(sites)
    exported = {_last(s.endpoint.key.partition(":")[2]) for found in sites.values()
                for s in found if s.role is Role.RECEIVE and s.endpoint
                and s.endpoint.key.startswith("plugin:")}  # fmt: skip
    wanted: dict[str, set[str]] = {}  # package folder -> classes waiting there
    for site in waiting:
        package, cls = package_of(site.path), _last(owner(site.function))
        if package is not None and cls not in exported:
            wanted.setdefault(package, set()).add(cls)
    if not wanted:
        return dict(sites)
    nodes = _makers(wanted, by_path, package_of, rules)
    return {
        element: tuple(_named(s, nodes, package_of) if _waits(s) else s for s in found)
        for element, found in sites.items()
    }


def _waits(site: LinkSite) -> bool:
    return (
        site.endpoint is None and UNKNOWN_NODE in site.note and not site.node
        and bool(site.name) and bool(owner(site.function))
    )  # fmt: skip


def _last(name: str) -> str:
    """The last part of a (qualified) class name: ``MoveBase`` of ``move_base::MoveBase``."""
    return name.replace(".", "::").rpartition("::")[2]


def _makers(
    wanted: Mapping[str, set[str]],
    by_path: Mapping[str, FileFacts],
    package_of: PackageOf,
    rules: Sequence[ScopeRule],
) -> dict[tuple[str, str], set[tuple[NodeName, str]]]:
    """For each (package, class) wanted, the nodes of the files making the class there,
    each with where (``path:line``); a file naming several nodes gives an unknown one. A
    file is looked into only when its callees (read without decoding its call sites) name
    a node (``ros::init``), or make a class (``std::make_shared``) and name a wanted one;
    its declarations (``mover::Mover mover;``) only in the first case."""
    patterns = [p for r in rules if r.kind == "node" for p in r.match]
    naming = {normalize_callee(p).rsplit(".", 1)[-1] for p in patterns} - _MAKERS
    inside = [(path, package) for path in by_path if (package := package_of(path)) in wanted]
    visible: dict[str, set[str]] = {}  # what a package's files include (a rule's requires)
    for path, package in inside:
        visible.setdefault(str(package), set()).update(d.target for d in by_path[path].dependencies)
    found: dict[tuple[str, str], set[tuple[NodeName, str]]] = {}
    for path, package in inside:
        facts, classes = by_path[path], wanted[str(package)]
        callees = facts.callees()  # read without decoding the call sites
        called = {last_name(callee) for callee in callees}
        naming_here = any(last_name(c) in naming and any(matches(p, c) for p in patterns)
                          for c in callees)  # ros::init, rospy.init_node, ...  # fmt: skip
        if not naming_here and not (called & _MAKERS and called & classes):
            continue
        made = [(cls, call.span.start) for call in facts.call_sites
                if (call.name in classes or call.name in _MAKERS)
                and (cls := _last(constructed(call)[0])) in classes]  # fmt: skip
        made += [(cls, s.span.start) for s in (facts.statements if naming_here else ())
                 if s.kind == "declaration"
                 and (declared := _DECLARED.fullmatch(s.text.replace(" :: ", "::")))
                 and (cls := _last(declared.group(1))) in classes]  # fmt: skip
        nodes = _file_nodes(facts, rules, sorted(visible[str(package)])) if made else set()
        if not nodes:
            continue  # made where no node is named: no word on its node
        node = next(iter(nodes)) if len(nodes) == 1 else NodeName(None)  # several: unknown
        for cls, line in made:
            found.setdefault((str(package), cls), set()).add((node, f"{path}:{line}"))
    return found


def _file_nodes(
    facts: FileFacts, rules: Sequence[ScopeRule], visible: Sequence[str]
) -> set[NodeName]:
    """The nodes a file names (``ros::init(argc, argv, "move_base_node")``)."""
    scopes = FileScopes(facts, rules, visible, plain_reader(constants_of(facts.bindings).get))
    return {s.node for s in scopes.scopes if s.kind == "node" and s.node and s.node.name}


def _named(
    site: LinkSite,
    nodes: Mapping[tuple[str, str], Iterable[tuple[NodeName, str]]],
    package_of: PackageOf,
) -> LinkSite:
    package = package_of(site.path)
    makers = list(nodes.get((str(package), _last(owner(site.function))), ()))
    distinct = {node for node, _ in makers}
    if len(distinct) != 1:
        return site
    node = distinct.pop()
    if node.name is None:
        return site
    kind, _, raw = site.name.partition(":")
    try:
        key = f"{kind}:{resolve(raw, node)}"
    except UnresolvedName:
        return site
    where = ", ".join(sorted(w for _, w in makers))
    note = f"node {node.fully_qualified}: its class is made there ({where})"
    return replace(site, endpoint=Endpoint(key, raw, "node"), note=note,
                   node=node.fully_qualified or "")  # fmt: skip
