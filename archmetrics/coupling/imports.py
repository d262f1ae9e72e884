"""Resolving Python imports to modules of the measured tree, through the package structure.

Absolute imports are looked up under the Python roots (the tree root, ``src`` and the
parents of top-level regular packages, unless configured), then -- for a file whose folder
is not a regular package, i.e. a script -- in the file's own folder, as ``python script.py``
would. Relative imports are resolved from the importing file's package. Folders without
``__init__.py`` are namespace packages. ``from pkg import mod`` depends on ``pkg.mod`` when
``mod`` is a submodule in the tree, and on ``pkg`` for names that are not submodules.
"""

from __future__ import annotations

import posixpath
from collections.abc import Iterable
from dataclasses import dataclass

from archmetrics.coupling.model import Resolution
from archmetrics.facts import Dependency


@dataclass(frozen=True, slots=True)
class ImportResolution:
    """One module an import statement depends on, and where it resolved."""

    name: str  # dotted module name; relative ones keep their dots (``..util``)
    resolution: Resolution
    target_file: str | None = None
    note: str = ""


_MODULE, _NAMESPACE = "module", "namespace"


def _join(*parts: str) -> str:
    return "/".join(p for p in parts if p)


class ModuleIndex:
    """The tree's Python files, indexed for import lookups."""

    def __init__(self, files: Iterable[str], roots: Iterable[str] | None = None) -> None:
        self.files = frozenset(f for f in files if f.endswith(".py"))
        self.folders = frozenset(folder for f in self.files for folder in _ancestors(f))
        self.roots = tuple(roots) if roots is not None else self._detect_roots()
        # what each folder holds by module name (``x`` for x.py and for the folder x): a
        # root that holds no first part of an import cannot locate it, and most imports
        # (os, sys, numpy ...) are in no root at all
        self._names: dict[str, set[str]] = {}
        for path in (*self.files, *self.folders):
            folder, _, name = path.rpartition("/")
            if name:
                self._names.setdefault(folder, set()).add(name.removesuffix(".py"))
        self._found: dict[tuple[tuple[str, ...], tuple[str, ...]], tuple[str, str | None] | None]
        self._found = {}  # every file imports os, sys, numpy ...: each lookup is made once

    def _is_package(self, folder: str) -> bool:
        return _join(folder, "__init__.py") in self.files

    def _detect_roots(self) -> tuple[str, ...]:
        roots = ["", "src"] if "src" in self.folders else [""]
        for path in sorted(self.files):
            folder = posixpath.dirname(path)
            if not self._is_package(folder):
                continue
            while folder and self._is_package(posixpath.dirname(folder)):
                folder = posixpath.dirname(folder)
            parent = posixpath.dirname(folder)
            if parent not in roots:
                roots.append(parent)
        return tuple(roots)

    def locate(self, folder: str, parts: list[str]) -> tuple[str, str | None] | None:
        """``(kind, file)`` of the module at ``folder`` + ``parts``; None when absent."""
        base = _join(folder, *parts)
        if parts and (module := base + ".py") in self.files:
            return _MODULE, module
        if (package := _join(base, "__init__.py")) in self.files:
            return _MODULE, package
        if base in self.folders:
            return _NAMESPACE, None
        return None

    def _search_roots(self, importer: str) -> tuple[str, ...]:
        folder = posixpath.dirname(importer)
        if self._is_package(folder) or folder in self.roots:
            return self.roots
        return (*self.roots, folder)

    def resolve(self, importer: str, dep: Dependency) -> list[ImportResolution]:
        """The modules ``dep`` (written in the file ``importer``) depends on."""
        parts = [p for p in dep.target.split(".") if p]
        if dep.level == 0:
            roots = self._search_roots(importer)
            return self._resolve(roots, parts, dep.names, dep.target, absolute=True)
        base = posixpath.dirname(importer)
        for _ in range(dep.level - 1):
            if not base:
                return [ImportResolution("." * dep.level + dep.target, Resolution.UNRESOLVED,
                                         note="relative import beyond the tree")]  # fmt: skip
            base = posixpath.dirname(base)
        written = "." * dep.level + dep.target
        return self._resolve((base,), parts, dep.names, written, absolute=False)

    def _find(self, roots: tuple[str, ...], parts: list[str]) -> tuple[str, str | None] | None:
        key = (roots, tuple(parts))
        if key in self._found:
            return self._found[key]
        first = parts[0] if parts else None
        found = next(
            (
                hit
                for root in roots
                if (first is None or first in self._names.get(root, ()))
                and (hit := self.locate(root, parts))
            ),
            None,
        )
        self._found[key] = found
        return found

    def _resolve(self, roots: tuple[str, ...], parts: list[str], names: tuple[str, ...],
                 written: str, absolute: bool) -> list[ImportResolution]:  # fmt: skip
        found = self._find(roots, parts) if parts or not absolute else None
        if found is None:
            internal = not absolute or self._find(roots, parts[:1]) is not None
            if internal:
                return [ImportResolution(written, Resolution.UNRESOLVED, None, "not in tree")]
            return [ImportResolution(written, Resolution.EXTERNAL)]
        results: list[ImportResolution] = []
        rest: list[str] = []
        for name in names:
            sub = self._find(roots, [*parts, name]) if name != "*" else None
            if sub is None:
                rest.append(name)
                continue
            results.append(_resolved(dotted(written, name), sub))
        if not names or rest:
            if found[0] == _NAMESPACE and rest:
                missing = dotted(written, rest[0])
                note = "not a module of the namespace package"
                results.append(ImportResolution(missing, Resolution.UNRESOLVED, None, note))
            else:
                results.append(_resolved(written, found))
        return results


def _ancestors(path: str) -> list[str]:
    """Every folder above ``path``, the tree root ("") included."""
    folders = [""]
    parts = path.split("/")[:-1]
    folders.extend("/".join(parts[: i + 1]) for i in range(len(parts)))
    return folders


def dotted(written: str, name: str) -> str:
    return written + name if written.endswith(".") or not written else f"{written}.{name}"


def _resolved(name: str, found: tuple[str, str | None]) -> ImportResolution:
    kind, target = found
    note = "namespace package" if kind == _NAMESPACE else ""
    return ImportResolution(name, Resolution.INTERNAL, target, note)
