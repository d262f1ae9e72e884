"""The coupling use case: facts of a tree in, per-element s_a, s_e, d_a, d_e and a graph out."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Protocol

from archmetrics.coupling.bindings import module_bindings
from archmetrics.coupling.config_links import with_config_sites
from archmetrics.coupling.dynamic import FileContext, LinkFilter, file_link_sites, resolve
from archmetrics.coupling.elements import Element, element_of_file, group_elements
from archmetrics.coupling.endpoints import Lookup, Value, constants_of
from archmetrics.coupling.graphnames import TypeAliases, imported_names
from archmetrics.coupling.model import (
    CouplingOptions,
    CouplingReport,
    EdgeKind,
    ElementCoupling,
    ElementGraph,
    GraphEdge,
    LinkSite,
    StaticDependency,
)
from archmetrics.coupling.rosgraph import ros_graph
from archmetrics.coupling.rules import Role, RuleSet
from archmetrics.coupling.scopes import FileScopes
from archmetrics.coupling.sitememo import SiteMemo, decode_sites, encode_sites, site_key
from archmetrics.coupling.static import (
    Occurrence,
    StaticResolver,
    dependents,
    element_dependencies,
)
from archmetrics.coupling.trace import Tracer
from archmetrics.coupling.values import ValueCalls
from archmetrics.facts import FileFacts, Language

_C_FAMILY = frozenset({Language.C.value, Language.CPP.value})


class Reaching(Protocol):
    """What finding link sites reads of a dependency occurrence: the name written and the
    tree file it resolved to (an :class:`Occurrence`, or the coupling index's record)."""

    @property
    def name(self) -> str: ...

    @property
    def target_file(self) -> str | None: ...


@dataclass(frozen=True, slots=True)
class TreeLinks:
    """What coupling one tree finds before it counts: its elements, every file's resolved
    dependencies and each element's link sites (unresolved: ``resolve`` gives them status
    and targets). :func:`measure_coupling` counts these; the coupling index
    (coupling/index.py) keeps them per file."""

    elements: tuple[Element, ...]
    occurrences: Mapping[str, tuple[Occurrence, ...]]
    sites: Mapping[str, tuple[LinkSite, ...]]  # by element name
    # keys elements receive without a site of theirs (a parameter file; rosgraph.py)
    receivers: Mapping[str, frozenset[str]] = field(default_factory=dict)
    whole: bool = False  # the tree's configuration renamed sites: a patch couples it whole


def link_tree(
    files: Sequence[FileFacts],
    options: CouplingOptions | None = None,
    rules: RuleSet | None = None,
    memo: SiteMemo | None = None,
) -> TreeLinks:
    """The elements, resolved dependencies and link sites of the tree ``files`` make up."""
    options = options or CouplingOptions()
    rules = rules or RuleSet()
    by_path = {f.path: f for f in files}
    languages = {f.path: f.language for f in files}
    elements = group_elements(by_path, options.grouping, languages.get)
    resolver = StaticResolver(tuple(by_path), options)
    occurrences = {path: resolver.resolve_file(facts) for path, facts in by_path.items()}
    may_link = LinkFilter(rules)
    plans = [(e, path) for e in elements for path in e.files if may_link(by_path[path])]
    by_file = Sites(by_path, occurrences, rules, memo).of(plans)
    found: dict[str, list[LinkSite]] = {e.name: [] for e in elements}
    for element, path in plans:
        found[element.name].extend(by_file[path])
    code = {name: tuple(s) for name, s in found.items()}
    sites = with_config_sites(code, elements, by_path, rules.configuration)
    graph = ros_graph(sites, elements, by_path, rules.scopes)
    return TreeLinks(elements, occurrences, graph.sites, graph.receivers, graph.applied)


def measure_coupling(
    files: Sequence[FileFacts],
    options: CouplingOptions | None = None,
    rules: RuleSet | None = None,
    memo: SiteMemo | None = None,
) -> CouplingReport:
    """Static and dynamic coupling of every element of the tree the ``files`` make up.

    Paths must be relative to the tree root. ``rules`` come from :func:`load_rule_packs`;
    without them only static coupling is measured. ``memo``: where each file's link sites
    are kept by content (sitememo.py); the report is the same with or without it.
    """
    links = link_tree(files, options, rules, memo)
    elements = links.elements
    element_of = element_of_file(elements)
    dependencies = {
        e.name: element_dependencies(e, links.occurrences, element_of) for e in elements
    }
    sites = resolve({e.name: links.sites[e.name] for e in elements}, links.receivers)
    afferent = dependents(dependencies)
    incoming = _incoming(sites)
    return CouplingReport(
        tuple(_coupling(e, dependencies, sites, afferent, incoming) for e in elements),
        ElementGraph(elements, _edges(dependencies, sites)),
    )


class _Constants:
    """File-level constants of each file, computed once per file."""

    def __init__(self, by_path: Mapping[str, FileFacts]) -> None:
        self.by_path = by_path
        self.tables: dict[str, dict[str, Value]] = {}

    def of(self, path: str) -> dict[str, Value]:
        if path not in self.tables:
            self.tables[path] = constants_of(self.by_path[path].bindings)
        return self.tables[path]

    def lookup(self, paths: Sequence[str]) -> Lookup:
        """A name's value in the first of ``paths`` defining it; tables are read on first use."""

        def find(name: str) -> Value | None:
            for path in paths:
                table = self.of(path)
                if name in table:
                    return table[name]
            return None

        return find


def _reachable(path: str, occurrences: Mapping[str, Sequence[Reaching]]) -> list[str]:
    """``path`` and the tree files it includes or imports, transitively, breadth-first."""
    order, seen = [path], {path}
    for current in order:  # grows while iterating: a breadth-first queue
        for occ in occurrences.get(current, ()):
            if occ.target_file and occ.target_file not in seen:
                seen.add(occ.target_file)
                order.append(occ.target_file)
    return order


class Sites:
    """Files' unresolved link sites: read back from the memo where a file's key is kept,
    else found by the rules (and kept). ``by_path`` may be a mapping that reads facts when
    asked: only the files a plan reaches are asked for."""

    def __init__(
        self,
        by_path: Mapping[str, FileFacts],
        occurrences: Mapping[str, Sequence[Reaching]],
        rules: RuleSet,
        memo: SiteMemo | None,
    ) -> None:
        self.by_path, self.occurrences = by_path, occurrences
        self.rules, self.constants, self.memo = rules, _Constants(by_path), memo

    def of(self, plans: Sequence[tuple[Element, str]]) -> dict[str, tuple[LinkSite, ...]]:
        """The sites of each planned file (a file of an element that a rule may link)."""
        reaches = [(e, path, _reachable(path, self.occurrences)) for e, path in plans]
        known: dict[str, tuple[LinkSite, ...]] = {}
        keys: dict[str, str] = {}
        if self.memo is not None:
            for element, path, reachable in reaches:
                bindings = [(o.name, o.target_file) for o in self.occurrences.get(path, ())]
                key = site_key(self.memo, path, reachable, element.files, bindings)
                if key is not None:
                    keys[path] = key
            stored = self.memo.store.get_many(sorted(set(keys.values())))
            for path, key in keys.items():
                data = stored.get(key)
                read = decode_sites(path, data) if data is not None else None
                if read is not None:
                    known[path] = read
        kept: dict[str, bytes] = {}
        found: dict[str, tuple[LinkSite, ...]] = {}
        for element, path, reachable in reaches:
            sites = known.get(path)
            if sites is None:
                sites = self._file(element, path, reachable)
                record = encode_sites(path, sites) if path in keys else None
                if record is not None:
                    kept[keys[path]] = record
            found[path] = sites
        if kept and self.memo is not None:
            self.memo.store.put_many(kept)
        return found

    def _file(self, element: Element, path: str, reachable: list[str]) -> tuple[LinkSite, ...]:
        by_path, occurrences = self.by_path, self.occurrences
        facts = by_path[path]
        lookup = self.constants.lookup([p for p in reachable if p in by_path])
        seen = reachable if facts.language in _C_FAMILY else [path]
        visible = {d.target for p in (*seen, *element.files) for d in by_path[p].dependencies}
        submodules = [o.name for o in occurrences.get(path, ()) if o.target_file]
        python = facts.language == Language.PYTHON
        modules = module_bindings(facts.dependencies, submodules) if python else frozenset()
        values = ValueCalls(facts, self.rules.values) if self.rules.values else None
        tracer = Tracer(facts, lookup, modules, values)
        seen_ = sorted(visible)
        context = None
        if self.rules.scopes or self.rules.values:
            scopes = FileScopes(facts, self.rules.scopes, seen_, tracer.read)
            imports = imported_names(facts.dependencies) if python else {}
            c_family = facts.language in _C_FAMILY
            aliases = TypeAliases(facts.bindings, facts.statements) if c_family else None
            context = FileContext(scopes, imports, aliases)
        return file_link_sites(facts, self.rules, seen_, tracer.read, modules, context)


def _incoming(sites: Mapping[str, tuple[LinkSite, ...]]) -> dict[str, list[LinkSite]]:
    """For every element, the other elements' sites that link into it (d_a's sites)."""
    found: dict[str, list[LinkSite]] = {}
    for source, source_sites in sites.items():
        for site in source_sites:
            for target in site.targets:
                if target != source:
                    found.setdefault(target, []).append(site)
    return found


def _coupling(
    element: Element,
    dependencies: Mapping[str, tuple[StaticDependency, ...]],
    sites: Mapping[str, tuple[LinkSite, ...]],
    afferent: Mapping[str, tuple[str, ...]],
    incoming: Mapping[str, list[LinkSite]],
) -> ElementCoupling:
    own = dependencies[element.name]
    sources = afferent.get(element.name, ())
    linked = tuple(incoming.get(element.name, ()))
    return ElementCoupling(
        element=element,
        s_a=len(sources),
        s_e=sum(1 for d in own if d.counted),
        d_a=len(linked),
        d_e=len(sites[element.name]),
        dependencies=own,
        link_sites=sites[element.name],
        dependents=sources,
        incoming_sites=linked,
    )


def _edges(
    dependencies: Mapping[str, tuple[StaticDependency, ...]],
    sites: Mapping[str, tuple[LinkSite, ...]],
) -> tuple[GraphEdge, ...]:
    edges = [
        GraphEdge(source, dep.target_element, EdgeKind.STATIC, dep.name, len(dep.sites))
        for source, deps in dependencies.items()
        for dep in deps
        if dep.counted and dep.target_element
    ]
    dynamic: Counter[tuple[str, str, str]] = Counter(
        (source, target, site.endpoint.key)
        for source, source_sites in sites.items()
        for site in source_sites
        if site.role is Role.INITIATE and site.endpoint is not None
        for target in site.targets
    )
    edges.extend(GraphEdge(s, t, EdgeKind.DYNAMIC, k, n) for (s, t, k), n in dynamic.items())
    return tuple(sorted(edges))
