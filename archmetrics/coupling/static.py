"""Static coupling: resolve each file's includes and imports, then count per element.

s_e of an element is the number of its distinct dependencies: inside the tree one per target
element, outside it one per module or include path. A dependency on the element itself (a
header included by its own implementation file) is recorded but not counted. s_a is the
number of distinct other elements with a counted dependency resolving to the element.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from archmetrics.coupling.elements import Element
from archmetrics.coupling.imports import ModuleIndex
from archmetrics.coupling.includes import IncludeIndex, IncludeResolution, normalize
from archmetrics.coupling.interfaces import InterfaceIndex
from archmetrics.coupling.model import CouplingOptions, Resolution, SourceRef, StaticDependency
from archmetrics.facts import Dependency, DependencyKind, FileFacts

_GENERATED = "generated from an interface file of the tree"


@dataclass(frozen=True, slots=True)
class Occurrence:
    """One resolved dependency as written at one place in one file."""

    name: str
    kind: DependencyKind
    resolution: Resolution
    site: SourceRef
    target_file: str | None = None
    note: str = ""


class StaticResolver:
    """Resolves the dependencies of the files of one tree."""

    def __init__(self, paths: Sequence[str], options: CouplingOptions) -> None:
        self.options, self.paths = options, paths
        self._includes: IncludeIndex | None = None
        self._modules: ModuleIndex | None = None
        self._interfaces: InterfaceIndex | None = None

    @property
    def interfaces(self) -> InterfaceIndex:
        """The tree's ROS interface files (when a dependency first is not in the tree)."""
        if self._interfaces is None:
            self._interfaces = InterfaceIndex(self.paths)
        return self._interfaces

    @property
    def includes(self) -> IncludeIndex:
        """The tree's files indexed for includes (when a file first has one: a patch that
        resolves one C file again need not index the tree's Python modules)."""
        if self._includes is None:
            self._includes = IncludeIndex(self.paths, self.options.include_dirs)
        return self._includes

    @property
    def modules(self) -> ModuleIndex:
        """The tree's Python modules indexed for imports (when a file first has one)."""
        if self._modules is None:
            self._modules = ModuleIndex(self.paths, self.options.python_roots)
        return self._modules

    def _ignored(self, dep: Dependency) -> bool:
        if dep.kind is DependencyKind.IMPORT:
            return dep.level == 0 and any(
                dep.target == name or dep.target.startswith(name + ".")
                for name in self.options.ignore_imports
            )
        return (normalize(dep.target) or dep.target) in self.options.ignore_includes

    def resolve_file(self, facts: FileFacts) -> tuple[Occurrence, ...]:
        """Every dependency occurrence of one file, resolved; ignored ones are left out."""
        found: list[Occurrence] = []
        for dep in facts.dependencies:
            if self._ignored(dep):
                continue
            site = SourceRef(facts.path, dep.span.start)
            if dep.kind is DependencyKind.IMPORT:
                for imp in self.modules.resolve(facts.path, dep):
                    if (
                        imp.resolution is not Resolution.INTERNAL
                        and dep.names
                        and (found_in := self._interface_imports(dep, site))
                    ):
                        found.extend(found_in)  # from geometry_msgs.msg import Twist
                        continue
                    found.append(Occurrence(imp.name, dep.kind, imp.resolution, site,
                                            imp.target_file, imp.note))  # fmt: skip
            else:
                inc = self.includes.resolve(facts.path, dep.target, dep.kind)
                if inc.resolution is not Resolution.INTERNAL and (
                    defined := self.interfaces.include(dep.target)
                ):
                    inc = IncludeResolution(Resolution.INTERNAL, defined, _GENERATED)
                found.append(Occurrence(dep.target, dep.kind, inc.resolution, site,
                                        inc.target_file, inc.note))  # fmt: skip
        return tuple(found)

    def _interface_imports(self, dep: Dependency, site: SourceRef) -> list[Occurrence]:
        """``from pkg.msg import A, B``: a dependency on each interface file the tree holds
        (none unless it holds all of them, so a name is never dropped)."""
        files = [self.interfaces.module(dep.target, name) for name in dep.names]
        if not self.interfaces or not all(files):
            return []
        return [
            Occurrence(f"{dep.target}.{name}", dep.kind, Resolution.INTERNAL, site, file,
                       _GENERATED)
            for name, file in zip(dep.names, files, strict=True)
        ]  # fmt: skip


def element_dependencies(
    element: Element,
    occurrences: Mapping[str, tuple[Occurrence, ...]],
    element_of: Mapping[str, Element],
) -> tuple[StaticDependency, ...]:
    """The distinct static dependencies of ``element``, in order of first appearance."""
    grouped: dict[tuple[str, str], list[Occurrence]] = {}
    targets: dict[tuple[str, str], str | None] = {}
    for path in element.files:
        for occ in occurrences.get(path, ()):
            target = element_of[occ.target_file].name if occ.target_file else None
            key = ("element", target) if target else (occ.resolution.value, occ.name)
            grouped.setdefault(key, []).append(occ)
            targets[key] = target
    result = []
    for key, occs in grouped.items():
        first, target = occs[0], targets[key]
        own = target == element.name
        result.append(StaticDependency(
            name=first.name, kind=first.kind, resolution=first.resolution,
            sites=tuple(sorted(o.site for o in occs)), target_file=first.target_file,
            target_element=target, counted=not own,
            note="own element, not counted" if own else first.note,
        ))  # fmt: skip
    return tuple(result)


def dependents(
    dependencies: Mapping[str, tuple[StaticDependency, ...]],
) -> dict[str, tuple[str, ...]]:
    """For every target element, the other elements with a counted dependency on it (s_a's set)."""
    found: dict[str, set[str]] = {}
    for source, deps in dependencies.items():
        for dep in deps:
            if dep.counted and dep.target_element and dep.target_element != source:
                found.setdefault(dep.target_element, set()).add(source)
    return {target: tuple(sorted(sources)) for target, sources in found.items()}
