"""A tree's coupling kept as an index, so that a tree whose files differ from it only in
content is coupled by redoing what those files reach, not the whole tree (docs/performance.md,
"Incremental diffs").

The index holds, per measured file, where its dependencies resolve and the endpoint keys of
its link sites, and per element its four values. :func:`build_index` makes it from a tree's
:class:`~archmetrics.coupling.measure.TreeLinks`; :func:`patch_index` gives the index of the
same paths with some files' facts changed. The values equal :func:`measure_coupling`'s on the
patched tree (tests/coupling/test_index.py holds it to that on real trees); the counting
rules are measure.py's, restated per element:

* s_e(E): E's distinct counted dependencies: one per target element other than E, one per
  (resolution, name) outside the tree;
* s_a(T): the other elements with a counted dependency on T;
* d_e(E): E's link sites;
* d_a(T): for each endpoint key T receives, the initiating sites with that key in other
  elements.
"""

from __future__ import annotations

from collections.abc import Callable, Collection, Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from typing import NamedTuple

from archmetrics.coupling.config_links import config_link_sites
from archmetrics.coupling.dynamic import LinkFilter
from archmetrics.coupling.elements import Element
from archmetrics.coupling.measure import Reaching, Sites, TreeLinks
from archmetrics.coupling.model import CouplingOptions, LinkSite
from archmetrics.coupling.rules import Role, RuleSet
from archmetrics.coupling.sitememo import SiteMemo
from archmetrics.coupling.static import Occurrence, StaticResolver
from archmetrics.facts import FileFacts

Site = tuple[str, str | None]  # one link site: its role and its endpoint's key (None: unknown)
Values = tuple[int, int, int, int]  # s_a, s_e, d_a, d_e
ALSO = "also"  # a record of a key a receiving site also receives (no site of its own)

_INITIATE, _RECEIVE = Role.INITIATE.value, Role.RECEIVE.value


class Dep(NamedTuple):
    """One dependency occurrence as coupling counts it: where it resolved (None: outside the
    tree or nowhere), how, and the name as written."""

    target_file: str | None
    resolution: str
    name: str


@dataclass(frozen=True, slots=True)
class CouplingIndex:
    """What one tree's coupling adds up to. ``paths``: the measured files in the order they
    were coupled; ``deps`` and ``sites``: per file that has any; ``values``: per element."""

    paths: tuple[str, ...]
    elements: tuple[Element, ...]
    deps: Mapping[str, tuple[Dep, ...]]
    sites: Mapping[str, tuple[Site, ...]]
    values: Mapping[str, Values]
    receivers: Mapping[str, frozenset[str]] = field(default_factory=dict)  # TreeLinks'
    whole: bool = False  # a patch couples the tree whole (TreeLinks.whole)


def _deps(occurrences: Iterable[Occurrence]) -> tuple[Dep, ...]:
    return tuple(Dep(o.target_file, o.resolution.value, o.name) for o in occurrences)


def _sites(sites: Iterable[LinkSite]) -> tuple[Site, ...]:
    found: list[Site] = []
    for s in sites:
        found.append((s.role.value, s.endpoint.key if s.endpoint else None))
        if s.endpoint is not None and s.role is Role.RECEIVE:
            found += [(ALSO, key) for key in s.endpoint.also]
    return tuple(found)


def build_index(links: TreeLinks, paths: Sequence[str]) -> CouplingIndex:
    """The index of a tree coupled whole (``paths``: its measured files, in order)."""
    deps = {path: _deps(occ) for path, occ in links.occurrences.items() if occ}
    by_file: dict[str, list[LinkSite]] = {}
    for element_sites in links.sites.values():
        for site in element_sites:
            by_file.setdefault(site.path, []).append(site)
    sites = {path: _sites(found) for path, found in by_file.items()}
    counter = _Counter(_Names(links.elements), deps, sites, links.receivers)
    values = {e.name: counter.values(e) for e in links.elements}
    return CouplingIndex(
        tuple(paths), links.elements, deps, sites, values, links.receivers, links.whole
    )


class _Names:
    """An element grouping by file and by name."""

    def __init__(self, elements: Sequence[Element]) -> None:
        self.element_of = {path: e.name for e in elements for path in e.files}
        self.by_name = {e.name: e for e in elements}


class _Counter:
    """The four values of elements, counted from an index's per-file records."""

    def __init__(
        self,
        names: _Names,
        deps: Mapping[str, tuple[Dep, ...]],
        sites: Mapping[str, tuple[Site, ...]],
        implicit: Mapping[str, frozenset[str]] | None = None,
    ) -> None:
        self.element_of, self.by_name = names.element_of, names.by_name
        self.deps, self.sites = deps, sites
        self.implicit: dict[str, set[str]] = {}  # element -> keys it receives without a site
        for received, receiving in (implicit or {}).items():
            for element in receiving:
                self.implicit.setdefault(element, set()).add(received)
        # endpoint key -> elements receiving it
        self.receivers: dict[str, set[str]] = {k: set(v) for k, v in (implicit or {}).items()}
        self.initiated: dict[str, int] = {}  # endpoint key -> initiating sites, all elements
        self.initiated_by: dict[tuple[str, str], int] = {}  # (element, key) -> its sites
        for path, found in sites.items():
            name = self.element_of[path]
            for role, key in found:
                if key is None:
                    continue
                if role in (_RECEIVE, ALSO):
                    self.receivers.setdefault(key, set()).add(name)
                elif role == _INITIATE:
                    self.initiated[key] = self.initiated.get(key, 0) + 1
                    self.initiated_by[name, key] = self.initiated_by.get((name, key), 0) + 1
        self.afferent: dict[str, set[str]] | None = None

    def targets(self, element: Element) -> tuple[int, set[str]]:
        """s_e of ``element`` and the other elements it depends on."""
        keys: set[tuple[str, str]] = set()
        others: set[str] = set()
        for path in element.files:
            for target_file, resolution, name in self.deps.get(path, ()):
                if target_file is None:
                    keys.add((resolution, name))
                    continue
                target = self.element_of[target_file]
                if target != element.name:
                    keys.add(("element", target))
                    others.add(target)
        return len(keys), others

    def d_e(self, element: Element) -> int:
        return sum(
            1 for path in element.files for role, _ in self.sites.get(path, ()) if role != ALSO
        )

    def d_a(self, name: str) -> int:
        received = {
            key
            for path in self.by_name[name].files
            for role, key in self.sites.get(path, ())
            if role in (_RECEIVE, ALSO) and key is not None
        } | self.implicit.get(name, set())
        initiated, mine = self.initiated, self.initiated_by
        return sum(initiated.get(key, 0) - mine.get((name, key), 0) for key in received)

    def s_a(self, name: str) -> int:
        if self.afferent is None:
            self.afferent = {}
            for element in self.by_name.values():
                for target in self.targets(element)[1]:
                    self.afferent.setdefault(target, set()).add(element.name)
        return len(self.afferent.get(name, ()))

    def values(self, element: Element) -> Values:
        s_e = self.targets(element)[0]
        return (self.s_a(element.name), s_e, self.d_a(element.name), self.d_e(element))


class LazyFacts(Mapping[str, FileFacts]):
    """The facts of a tree's measured ``paths``, each read by ``read`` when first asked
    for: a patch reads the files it reaches, not the tree."""

    def __init__(self, paths: Collection[str], read: Callable[[str], FileFacts]) -> None:
        self._paths, self._read = paths, read
        self._known: dict[str, FileFacts] = {}

    def __getitem__(self, path: str) -> FileFacts:
        found = self._known.get(path)
        if found is None:
            if path not in self._paths:
                raise KeyError(path)
            found = self._known[path] = self._read(path)
        return found

    def __contains__(self, path: object) -> bool:
        return path in self._paths

    def __iter__(self) -> Iterator[str]:
        return iter(self._paths)

    def __len__(self) -> int:
        return len(self._paths)


def dependents_of(deps: Mapping[str, Sequence[Dep]]) -> Mapping[str, Sequence[str]]:
    """For every file depended on, the files that include or import it (a table read from
    the cache answers from its columns, sources/deptable.py)."""
    sources = getattr(deps, "sources", None)
    if callable(sources):
        found: Mapping[str, Sequence[str]] = sources()
        return found
    made: dict[str, list[str]] = {}
    for path, records in deps.items():
        for dep in records:
            if dep.target_file is not None:
                made.setdefault(dep.target_file, []).append(path)
    return made


def _reaching(deps: Mapping[str, Sequence[Dep]], starts: Iterable[str]) -> set[str]:
    """``starts`` and every file that includes or imports one of them, transitively."""
    sources = dependents_of(deps)
    seen = set(starts)
    queue = list(seen)
    while queue:
        for source in sources.get(queue.pop(), ()):
            if source not in seen:
                seen.add(source)
                queue.append(source)
    return seen


def patch_index(
    index: CouplingIndex,
    changed: Mapping[str, FileFacts],
    facts: Mapping[str, FileFacts],
    options: CouplingOptions,
    rules: RuleSet,
    memo: SiteMemo | None = None,
) -> CouplingIndex:
    """The index of ``index``'s tree with the files in ``changed`` holding those facts (the
    same paths and languages: a tree whose path set differs is coupled whole). ``facts``:
    every measured file's facts in the new tree, read when asked for (:class:`LazyFacts`).

    Redone: the changed files' dependencies; the link sites of every file that reaches a
    changed one by includes or imports and of every file of a changed file's element (what a
    file's sites depend on, sitememo.py); the values of the elements whose dependencies or
    sites changed, of the elements they depend on, and of the elements receiving an endpoint
    key that a redone site has or had."""
    if not changed:
        return index
    affected = _reaching(index.deps, changed)  # first: the overlay below keeps its table
    resolver = StaticResolver(index.paths, options)
    occurrences = {path: resolver.resolve_file(f) for path, f in changed.items()}
    deps = _Overlay(index.deps, {path: _deps(found) for path, found in occurrences.items()})
    names = _Names(index.elements)

    def element(path: str) -> Element:
        return names.by_name[names.element_of[path]]

    for path in changed:
        affected.update(element(path).files)
    may_link = LinkFilter(rules)
    plans = [(element(p), p) for p in sorted(affected) if may_link(facts[p])]
    view = _Occurrences(deps, occurrences)
    redone = dict(Sites(facts, view, rules, memo).of(plans))
    if rules.configuration:  # a configuration file's sites are its tables' (config_links.py)
        for path in sorted(affected):
            if facts[path].tables:
                found = config_link_sites(facts[path], rules.configuration)
                redone[path] = (*redone.get(path, ()), *found)
    sites = {p: s for p, s in index.sites.items() if p not in affected}
    sites.update((p, _sites(f)) for p, f in redone.items() if f)
    values = _patched_values(index, deps, sites, changed, affected, names)
    return CouplingIndex(
        index.paths, index.elements, deps, sites, values, index.receivers, index.whole
    )


class _Overlay(Mapping[str, tuple[Dep, ...]]):
    """``base`` with the records of some files replaced (a file with none has no entry).

    A history patches the index of every commit from its parent's: an overlay of an overlay
    is first made a plain table, so that a look-up never walks a chain as long as the
    history; the reverse table (:meth:`sources`) is patched from the base's, not rebuilt."""

    def __init__(self, base: Mapping[str, tuple[Dep, ...]],
                 changes: Mapping[str, tuple[Dep, ...]]) -> None:  # fmt: skip
        if isinstance(base, _Overlay):
            base = base.flat()
        self.base, self.changes = base, changes
        self._sources: dict[str, list[str]] | None = None

    def __getitem__(self, path: str) -> tuple[Dep, ...]:
        if path in self.changes:
            found = self.changes[path]
            if not found:
                raise KeyError(path)
            return found
        return self.base[path]

    def __iter__(self) -> Iterator[str]:
        yield from (p for p in self.base if p not in self.changes)
        yield from (p for p, found in self.changes.items() if found)

    def __len__(self) -> int:
        return sum(1 for _ in self)

    def flat(self) -> _Table:
        table = _Table((path, self[path]) for path in self)
        table.known_sources = self._sources
        return table

    def sources(self) -> Mapping[str, Sequence[str]]:
        """For every file depended on, the files that include or import it."""
        if self._sources is None:
            made = {target: list(paths) for target, paths in dependents_of(self.base).items()}
            for path, records in self.changes.items():
                for dep in self.base.get(path, ()):
                    if dep.target_file is not None:
                        made[dep.target_file].remove(path)
                for dep in records:
                    if dep.target_file is not None:
                        made.setdefault(dep.target_file, []).append(path)
            self._sources = made
        return self._sources


class _Table(dict[str, tuple[Dep, ...]]):
    """A plain table of dependency records that remembers its reverse table once known."""

    known_sources: dict[str, list[str]] | None = None

    def sources(self) -> Mapping[str, Sequence[str]]:
        if self.known_sources is None:
            self.known_sources = {}
            for path, records in self.items():
                for dep in records:
                    if dep.target_file is not None:
                        self.known_sources.setdefault(dep.target_file, []).append(path)
        return self.known_sources


class _Occurrences(Mapping[str, Sequence[Reaching]]):
    """Every file's occurrences for the link-site finder: the changed files' as resolved
    now, the others' as the index kept them."""

    def __init__(self, deps: Mapping[str, tuple[Dep, ...]],
                 fresh: Mapping[str, tuple[Occurrence, ...]]) -> None:  # fmt: skip
        self.deps, self.fresh = deps, fresh

    def __getitem__(self, path: str) -> Sequence[Reaching]:
        if path in self.fresh:
            return self.fresh[path]
        return self.deps[path]

    def __iter__(self) -> Iterator[str]:
        return iter(self.deps)

    def __len__(self) -> int:
        return len(self.deps)


def _patched_values(
    index: CouplingIndex,
    deps: Mapping[str, tuple[Dep, ...]],
    sites: Mapping[str, tuple[Site, ...]],
    changed: Collection[str],
    affected: Collection[str],
    names: _Names,
) -> dict[str, Values]:
    before = _Counter(names, index.deps, index.sites, index.receivers)
    after = _Counter(names, deps, sites, index.receivers)
    element_of = after.element_of
    redeps = {element_of[p] for p in changed}  # s_e and the targets of s_a
    resites = {element_of[p] for p in affected if p in sites or p in index.sites}
    afferent: dict[str, int] = {}
    for name in redeps:
        old = before.targets(before.by_name[name])[1]
        new = after.targets(after.by_name[name])[1]
        for target in new - old:
            afferent[target] = afferent.get(target, 0) + 1
        for target in old - new:
            afferent[target] = afferent.get(target, 0) - 1
    touched = {
        key
        for path in affected
        for found in (index.sites.get(path, ()), sites.get(path, ()))
        for _, key in found
        if key is not None
    }
    receivers = {
        name
        for key in touched
        for name in (*before.receivers.get(key, ()), *after.receivers.get(key, ()))
    }
    values = dict(index.values)
    for name in redeps | resites | receivers | afferent.keys():
        element = after.by_name[name]
        s_a, s_e, d_a, d_e = values[name]
        values[name] = (
            s_a + afferent.get(name, 0),
            after.targets(element)[0] if name in redeps else s_e,
            after.d_a(name) if name in receivers else d_a,
            after.d_e(element) if name in resites else d_e,
        )
    return values
