"""The coupling use case: facts of a tree in, per-element s_a, s_e, d_a, d_e and a graph out."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping, Sequence

from archmetrics.coupling.bindings import module_bindings
from archmetrics.coupling.dynamic import file_link_sites, resolve
from archmetrics.coupling.elements import Element, element_of_file, group_elements
from archmetrics.coupling.endpoints import Lookup, Value, constants_of
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
from archmetrics.coupling.rules import Role, RuleSet
from archmetrics.coupling.static import (
    Occurrence,
    StaticResolver,
    dependents,
    element_dependencies,
)
from archmetrics.coupling.trace import Tracer
from archmetrics.facts import FileFacts, Language

_C_FAMILY = frozenset({Language.C.value, Language.CPP.value})


def measure_coupling(
    files: Sequence[FileFacts],
    options: CouplingOptions | None = None,
    rules: RuleSet | None = None,
) -> CouplingReport:
    """Static and dynamic coupling of every element of the tree the ``files`` make up.

    Paths must be relative to the tree root. ``rules`` come from :func:`load_rule_packs`;
    without them only static coupling is measured.
    """
    options = options or CouplingOptions()
    rules = rules or RuleSet()
    by_path = {f.path: f for f in files}
    languages = {f.path: f.language for f in files}
    elements = group_elements(by_path, options.per_file, languages.get)
    element_of = element_of_file(elements)
    resolver = StaticResolver(tuple(by_path), options)
    occurrences = {path: resolver.resolve_file(facts) for path, facts in by_path.items()}
    dependencies = {e.name: element_dependencies(e, occurrences, element_of) for e in elements}
    constants = _Constants(by_path)
    sites = resolve(
        {e.name: _element_sites(e, by_path, occurrences, rules, constants) for e in elements}
    )
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
            self.tables[path] = constants_of(self.by_path[path].statements)
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


def _reachable(path: str, occurrences: Mapping[str, tuple[Occurrence, ...]]) -> list[str]:
    """``path`` and the tree files it includes or imports, transitively, breadth-first."""
    order, seen = [path], {path}
    for current in order:  # grows while iterating: a breadth-first queue
        for occ in occurrences.get(current, ()):
            if occ.target_file and occ.target_file not in seen:
                seen.add(occ.target_file)
                order.append(occ.target_file)
    return order


def _element_sites(
    element: Element,
    by_path: Mapping[str, FileFacts],
    occurrences: Mapping[str, tuple[Occurrence, ...]],
    rules: RuleSet,
    constants: _Constants,
) -> tuple[LinkSite, ...]:
    found: list[LinkSite] = []
    for path in element.files:
        facts = by_path[path]
        reachable = _reachable(path, occurrences)
        lookup = constants.lookup([p for p in reachable if p in by_path])
        seen = reachable if facts.language in _C_FAMILY else [path]
        visible = {d.target for p in (*seen, *element.files) for d in by_path[p].dependencies}
        submodules = [o.name for o in occurrences.get(path, ()) if o.target_file]
        python = facts.language == Language.PYTHON
        modules = module_bindings(facts.dependencies, submodules) if python else frozenset()
        tracer = Tracer(facts, lookup, modules)
        found.extend(file_link_sites(facts, rules, sorted(visible), tracer.read, modules))
    return tuple(found)


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
