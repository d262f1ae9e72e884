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

from archmetrics.coupling.elements import Element
from archmetrics.coupling.measure import TreeLinks
from archmetrics.coupling.model import LinkSite
from archmetrics.coupling.rules import Role
from archmetrics.coupling.static import Occurrence
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


def deps_of(occurrences: Iterable[Occurrence]) -> tuple[Dep, ...]:
    return tuple(Dep(o.target_file, o.resolution.value, o.name) for o in occurrences)


def sites_of(sites: Iterable[LinkSite]) -> tuple[Site, ...]:
    found: list[Site] = []
    for s in sites:
        found.append((s.role.value, s.endpoint.key if s.endpoint else None))
        if s.endpoint is not None and s.role is Role.RECEIVE:
            found += [(ALSO, key) for key in s.endpoint.also]
    return tuple(found)


def build_index(links: TreeLinks, paths: Sequence[str]) -> CouplingIndex:
    """The index of a tree coupled whole (``paths``: its measured files, in order)."""
    deps = {path: deps_of(occ) for path, occ in links.occurrences.items() if occ}
    by_file: dict[str, list[LinkSite]] = {}
    for element_sites in links.sites.values():
        for site in element_sites:
            by_file.setdefault(site.path, []).append(site)
    sites = {path: sites_of(found) for path, found in by_file.items()}
    counter = Counter(Names(links.elements), deps, sites, links.receivers)
    values = {e.name: counter.values(e) for e in links.elements}
    return CouplingIndex(
        tuple(paths), links.elements, deps, sites, values, links.receivers, links.whole
    )


class Names:
    """An element grouping by file and by name."""

    def __init__(self, elements: Sequence[Element]) -> None:
        self.element_of = {path: e.name for e in elements for path in e.files}
        self.by_name = {e.name: e for e in elements}


class Counter:
    """The four values of elements, counted from an index's per-file records."""

    def __init__(
        self,
        names: Names,
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
