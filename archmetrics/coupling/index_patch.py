"""A tree's coupling index patched from another tree's: only the files whose reach changed
(a changed file, the files that include or import it, transitively) are coupled again; the
rest is read through from the other index (the next commit of a history, the worktree
after an edit)."""

from __future__ import annotations

from collections.abc import Collection, Iterable, Iterator, Mapping, Sequence

from archmetrics.coupling.config_links import config_link_sites
from archmetrics.coupling.dynamic import LinkFilter
from archmetrics.coupling.elements import Element
from archmetrics.coupling.index import (
    Counter,
    CouplingIndex,
    Dep,
    Names,
    Site,
    Values,
    deps_of,
    sites_of,
)
from archmetrics.coupling.measure import Reaching, Sites
from archmetrics.coupling.model import CouplingOptions
from archmetrics.coupling.rules import RuleSet
from archmetrics.coupling.sitememo import SiteMemo
from archmetrics.coupling.static import Occurrence, StaticResolver
from archmetrics.facts import FileFacts


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
    deps = _Overlay(index.deps, {path: deps_of(found) for path, found in occurrences.items()})
    names = Names(index.elements)

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
    sites.update((p, sites_of(f)) for p, f in redone.items() if f)
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
    names: Names,
) -> dict[str, Values]:
    before = Counter(names, index.deps, index.sites, index.receivers)
    after = Counter(names, deps, sites, index.receivers)
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
