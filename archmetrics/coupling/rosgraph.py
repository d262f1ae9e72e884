"""The ROS graph of a tree: launch files, parameter files and plugin descriptions applied to
the link sites the code gives (docs/metrics.md, "ROS computation graphs").

Code names its endpoints as written, resolved against the node's name and namespace as far
as the code says them (graphnames.py). A launch file that starts the node may rename it,
put it in a namespace and remap its names; a parameter file may set the parameter a name was
read from. When every launch configuration of a node agrees, its sites' names are resolved
again under it; when they disagree, the names stay as the code gives them and a note says
so. The launch file's own sites are given the package and executable they start. What has
no link site of its own but is linked to is a *receiver*: the elements an executable is
built from receive its launch sites, a parameter file receives the code reading the
parameters it sets, a plugin description receives the loads of the classes it names. Two
data types on one topic are an integration bug: each site of the topic says so.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import PurePosixPath

from archmetrics.coupling.elements import Element
from archmetrics.coupling.model import Endpoint, LinkSite
from archmetrics.coupling.roslaunch import Launched
from archmetrics.coupling.rosnames import (
    NodeName,
    UnresolvedName,
    clean_namespace,
    qualified_type,
    resolve,
)
from archmetrics.coupling.rosnodes import with_package_nodes
from archmetrics.coupling.rostree import RosTree, read_tree
from archmetrics.coupling.rules import Role, ScopeRule
from archmetrics.facts import FileFacts

Receivers = dict[str, frozenset[str]]


@dataclass(frozen=True, slots=True)
class RosGraph:
    """Sites with the tree's configuration applied, and the receivers it adds."""

    sites: dict[str, tuple[LinkSite, ...]]
    receivers: Receivers
    applied: bool = False  # the tree has launch, parameter or plugin files


def ros_graph(
    sites: Mapping[str, tuple[LinkSite, ...]],
    elements: Sequence[Element],
    by_path: Mapping[str, FileFacts],
    scopes: Sequence[ScopeRule] = (),
) -> RosGraph:
    """``sites`` (by element) with launch files, parameter files and plugin descriptions
    applied, and a class's node named by the program making it (rosnodes.py, ``scopes``);
    the receivers those add. A tree without any of it comes back as it was."""
    named = any(s.name or _type(s) in _CONFIGURED for found in sites.values() for s in found)
    if not named:
        return RosGraph(dict(sites), {})
    tree = read_tree(by_path)
    sites = with_package_nodes(sites, by_path, tree.package_of, scopes)
    element_of = {path: e.name for e in elements for path in e.files}
    receivers: dict[str, set[str]] = {}
    by_launch = {(entry.path, entry.line): entry for entry in tree.launched}
    starts = _starts(tree, sites, elements, element_of)
    done: dict[str, tuple[LinkSite, ...]] = {}
    for element, found in sites.items():
        configuration = _configuration(starts.get(element, []))
        done[element] = tuple(
            _applied(site, tree, configuration, by_launch, receivers, element_of, starts)
            for site in found
        )
    done = _types_checked(done)
    applied = bool(tree.launched or tree.settings or tree.descriptions)
    return RosGraph(done, {key: frozenset(names) for key, names in receivers.items()}, applied)


_CONFIGURED = frozenset({"node", "plugin", "parameter"})


def _type(site: LinkSite) -> str:
    """The type of a site's endpoint (``topic``), or of the name it could not resolve."""
    if site.endpoint is not None:
        return site.endpoint.key.partition(":")[0]
    return site.name.partition(":")[0]


def _starts(
    tree: RosTree,
    sites: Mapping[str, tuple[LinkSite, ...]],
    elements: Sequence[Element],
    element_of: Mapping[str, str],
) -> dict[str, list[Launched]]:
    """For each element, the launch entries that start it."""
    found: dict[str, list[Launched]] = {}
    if not tree.launched:
        return found
    members: dict[str, list[Element]] = {}  # package folder -> its elements
    for element in elements:
        for folder in {tree.package_of(path) for path in element.files} - {None}:
            members.setdefault(str(folder), []).append(element)
    registered: dict[str, set[str]] = {}  # a receiving plugin key -> the elements holding it
    for name, own in sites.items():
        for site in own:
            if site.role is Role.RECEIVE and site.endpoint and _type(site) == "plugin":
                registered.setdefault(site.endpoint.key, set()).add(name)
    for entry in tree.launched:
        chosen = launched_elements(entry, tree, sites, members, registered, element_of)
        for started in chosen:
            found.setdefault(started, []).append(entry)
    return found


def launched_elements(
    entry: Launched,
    tree: RosTree,
    sites: Mapping[str, tuple[LinkSite, ...]],
    members: Mapping[str, list[Element]],
    registered: Mapping[str, set[str]],
    element_of: Mapping[str, str],
) -> set[str]:
    """The elements a launch entry starts: a component's, the elements holding its
    registration; an executable's, among the elements of its package (``members``, by
    package folder, when the tree holds it), those its ``console_scripts`` entry names, else
    those whose node has its name, else those with a file of its name (``talker`` ->
    ``src/talker.cpp``)."""
    if entry.plugin:
        return set(registered.get(f"plugin:{tree.aliases.get(entry.plugin, entry.plugin)}", ()))
    folders = tree.package_folders(entry.package) if entry.package else []
    inside = [e for folder in folders for e in members.get(folder, ())]
    for folder in folders:
        script = tree.executables.get((folder, entry.executable))
        if script is not None and script in element_of:
            return {element_of[script]}
    by_node = {
        e.name for e in inside
        for s in sites.get(e.name, ()) if s.node and s.node.rsplit("/", 1)[-1] == entry.executable
    }  # fmt: skip
    if by_node:
        return by_node
    wanted = {entry.executable, PurePosixPath(entry.executable).stem}  # ROS 1's talker.py
    return {
        e.name for e in inside
        if any(PurePosixPath(p).stem in wanted for p in e.files)
    }  # fmt: skip


@dataclass(frozen=True, slots=True)
class _Configuration:
    """How an element's node runs, when every launch entry starting it agrees."""

    entry: Launched | None
    note: str = ""


def _configuration(entries: Sequence[Launched]) -> _Configuration:
    if not entries:
        return _Configuration(None)
    shapes = {(e.name, e.namespace, e.remaps, e.parameters, e.known) for e in entries}
    if len(shapes) == 1 and entries[0].known:
        return _Configuration(entries[0])
    where = ", ".join(sorted({f"{e.path}:{e.line}" for e in entries}))
    return _Configuration(
        None, f"started differently by launch files ({where}): names as the code gives them"
    )


def _applied(
    site: LinkSite,
    tree: RosTree,
    configuration: _Configuration,
    by_launch: Mapping[tuple[str, int], Launched],
    receivers: dict[str, set[str]],
    element_of: Mapping[str, str],
    starts: Mapping[str, list[Launched]],
) -> LinkSite:
    entry = by_launch.get((site.path, site.line))
    if entry is not None and (_type(site) in ("node", "plugin") or site.kind == "config"):
        site = _launch_site(site, entry, tree, receivers, starts)
    elif site.name:
        site = _renamed(site, tree, configuration)
    elif site.endpoint is not None and site.role is Role.INITIATE and _type(site) == "plugin":
        lookup = site.endpoint.key.partition(":")[2]  # a lookup name: the class it names
        if lookup in tree.aliases:
            site = replace(  # the lookup name as read is kept as the site's name
                site,
                endpoint=replace(site.endpoint, key=f"plugin:{tree.aliases[lookup]}"),
                name=site.name or f"plugin:{lookup}",
            )
    if site.endpoint is not None and site.role is Role.INITIATE:
        _receivers_of(site, tree, receivers, element_of)
    return site


def _launch_site(
    site: LinkSite, entry: Launched, tree: RosTree, receivers: dict[str, set[str]],
    starts: Mapping[str, list[Launched]],
) -> LinkSite:  # fmt: skip
    key = entry.key
    if entry.plugin:
        key = f"plugin:{tree.aliases.get(entry.plugin, entry.plugin)}"
    point = Endpoint(key, site.endpoint.text if site.endpoint else key, "launch")
    if not entry.plugin:
        started = {element for element, entries in starts.items() if entry in entries}
        if started:
            receivers.setdefault(key, set()).update(started)
    return replace(site, endpoint=point, note="", node=entry.full_name)


def _renamed(site: LinkSite, tree: RosTree, configuration: _Configuration) -> LinkSite:
    """``site`` with its name resolved again under its node's launch configuration and the
    parameter files' values."""
    if site.endpoint is None and _STATIC not in site.note:
        return site  # unknown for another reason than its node (several values ...)
    kind, _, raw = site.name.partition(":")
    namespace, _, own = (site.node or "").rpartition("/")
    entry = configuration.entry
    name = (entry.name if entry and entry.name else own) or None
    where = entry.namespace if entry and entry.namespace else namespace
    node = NodeName(name, clean_namespace(where))
    if site.parameter and node.fully_qualified and not configuration.note:  # agreed, or none
        values = tree.values_for(node.fully_qualified, site.parameter)
        if entry is not None:
            values |= {v for k, v in entry.parameters if k == site.parameter}
        if len(values) == 1:
            raw = values.pop()
    try:
        key = _key(kind, raw, node, entry)
    except UnresolvedName as why:
        return replace(site, endpoint=None, note=str(why))
    also = tuple(_remapped(k, node, entry) for k in site.endpoint.also) if site.endpoint else ()
    text = site.endpoint.text if site.endpoint else raw
    via = site.endpoint.via if site.endpoint else "launch"
    note = "" if _STATIC in site.note else site.note
    note = "; ".join(n for n in (note, configuration.note) if n)
    point = Endpoint(key, text, via, also)
    return replace(site, endpoint=point, note=note, node=node.fully_qualified or "")


_STATIC = "not known statically"


def _key(kind: str, raw: str, node: NodeName, entry: Launched | None) -> str:
    return _remapped(f"{kind}:{resolve(raw, node)}", node, entry)


def _remapped(key: str, node: NodeName, entry: Launched | None) -> str:
    """``key`` with the launch entry's remappings applied (a remapping replaces a whole
    resolved name, both sides resolved in the node)."""
    if entry is None or not entry.remaps:
        return key
    kind, _, name = key.partition(":")
    for source, target in entry.remaps:
        try:
            if resolve(source, node) == name:
                return f"{kind}:{resolve(target, node)}"
        except UnresolvedName:
            continue
    return key


def _receivers_of(
    site: LinkSite, tree: RosTree, receivers: dict[str, set[str]], element_of: Mapping[str, str]
) -> None:
    """Files an initiating site links into without a site of their own."""
    assert site.endpoint is not None
    kind, _, name = site.endpoint.key.partition(":")
    files: set[str] = set()
    if kind == "parameter":
        node, _, parameter = name.rpartition("/")
        files = tree.setters(node, parameter)
    elif kind == "plugin":
        files = tree.descriptions.get(tree.aliases.get(name, name), set())
    targets = {element_of[f] for f in files if f in element_of}
    if targets:
        receivers.setdefault(site.endpoint.key, set()).update(targets)


def _types_checked(sites: dict[str, tuple[LinkSite, ...]]) -> dict[str, tuple[LinkSite, ...]]:
    """Each site of a topic that two sites give different data types notes them."""
    types: dict[str, set[str]] = {}
    for found in sites.values():
        for site in found:
            if site.endpoint and site.data_type and qualified_type(site.data_type):
                for key in (site.endpoint.key, *site.endpoint.also):
                    types.setdefault(key, set()).add(site.data_type)
    clash = {key: kinds for key, kinds in types.items() if len(kinds) > 1}
    if not clash:
        return sites
    return {
        element: tuple(_with_clash(site, clash) for site in found)
        for element, found in sites.items()
    }


def _with_clash(site: LinkSite, clash: Mapping[str, set[str]]) -> LinkSite:
    if site.endpoint is None or site.endpoint.key not in clash:
        return site
    kinds = ", ".join(sorted(clash[site.endpoint.key]))
    warning = f"{site.endpoint.key.partition(':')[2]} carries several types: {kinds}"
    return replace(site, note=f"{site.note}; {warning}" if site.note else warning)
