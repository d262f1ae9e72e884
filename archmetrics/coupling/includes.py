"""Resolving C/C++ ``#include`` paths to files of the measured tree.

Quoted includes are looked up relative to the including file, then in the configured include
directories, then by a unique path suffix in the tree. Angled includes skip the first step
(the compiler does not search the including file's folder for them) but resolve by the other
two, so a vendored header (``<libplayerc/playerc.h>``) counts as internal. A quoted include
found nowhere is unresolved; an angled one is external (a system or third-party header).
"""

from __future__ import annotations

import posixpath
from collections.abc import Iterable
from dataclasses import dataclass

from archmetrics.coupling.model import Resolution
from archmetrics.facts import DependencyKind


@dataclass(frozen=True, slots=True)
class IncludeResolution:
    """Where an include leads: a tree file, outside the tree, or unknown (with why)."""

    resolution: Resolution
    target_file: str | None = None
    note: str = ""


def normalize(path: str) -> str | None:
    """A tree-relative posix path without ``.``/``..``; None when it leaves the tree."""
    if not path or path.startswith("/"):
        return None
    joined = posixpath.normpath(path)
    return None if joined == ".." or joined.startswith("../") else joined


class IncludeIndex:
    """The tree's files, indexed for include lookups."""

    def __init__(self, files: Iterable[str], include_dirs: Iterable[str] = ()) -> None:
        listed = files if isinstance(files, (tuple, list)) else list(files)
        self.files = frozenset(listed)
        self.include_dirs = tuple(d.strip("/") for d in include_dirs)
        self._by_name: dict[str, list[str]] = {}
        # sorted from the list given (a tree's paths come sorted: a linear pass), not from
        # the set's hash order; a path's name as rpartition finds it (basename's own cost
        # was a third of indexing a tree of 30,000 files)
        ordered = sorted(listed) if len(listed) == len(self.files) else sorted(self.files)
        by_name = self._by_name
        for path in ordered:
            name = path.rpartition("/")[2]
            found = by_name.get(name)
            if found is None:
                by_name[name] = [path]
            else:
                found.append(path)

    def _in_tree(self, folder: str, target: str) -> str | None:
        path = normalize(posixpath.join(folder, target) if folder else target)
        return path if path in self.files else None

    def _by_suffix(self, target: str) -> tuple[str, ...]:
        clean = normalize(target)
        if clean is None:
            return ()
        candidates = self._by_name.get(posixpath.basename(clean), [])
        return tuple(p for p in candidates if p == clean or p.endswith("/" + clean))

    def resolve(self, including: str, target: str, kind: DependencyKind) -> IncludeResolution:
        """Resolve ``target`` as included from the file ``including``."""
        quoted = kind is DependencyKind.INCLUDE
        if quoted and (found := self._in_tree(posixpath.dirname(including), target)):
            return IncludeResolution(Resolution.INTERNAL, found)
        for folder in self.include_dirs:
            if found := self._in_tree(folder, target):
                return IncludeResolution(Resolution.INTERNAL, found, f"include dir {folder}")
        matches = self._by_suffix(target)
        if len(matches) == 1:
            return IncludeResolution(Resolution.INTERNAL, matches[0], "unique path suffix")
        if len(matches) > 1:
            shown = ", ".join(matches[:5])
            return IncludeResolution(Resolution.UNRESOLVED, None, f"ambiguous: {shown}")
        if quoted:
            return IncludeResolution(Resolution.UNRESOLVED, None, "quoted include not in tree")
        return IncludeResolution(Resolution.EXTERNAL)
