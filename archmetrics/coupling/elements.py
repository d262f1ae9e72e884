"""Elements: the units coupling and complexity are reported for (thesis page 108).

A Python module is one element. A C/C++ header and the implementation files with the same
stem in the same folder form one element (a component, as the thesis measured classes and
applications); ``per_file`` makes every file its own element. The change-set engine reuses
this grouping, so element names must not depend on which members a revision happens to hold.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import NamedTuple

from archmetrics.facts import Language
from archmetrics.parsers import DEFAULT_EXTENSIONS

HEADER_SUFFIXES = frozenset({".h", ".hh", ".hpp", ".hxx", ".h++", ".ipp", ".inl"})
SOURCE_SUFFIXES = frozenset({".c", ".cc", ".cpp", ".cxx", ".c++"})
C_FAMILY_SUFFIXES = HEADER_SUFFIXES | SOURCE_SUFFIXES


class Element(NamedTuple):
    """A unit of measurement: its stable name, the files it holds and their languages.
    (A named tuple: a tree's state makes one per element, 28,000 in a large tree.)"""

    name: str
    files: tuple[str, ...]
    languages: tuple[str, ...]


def suffix(path: str) -> str:
    """The ending of ``path``'s last part, as ``PurePosixPath(path).suffix`` gives it
    (``.c``; none for ``.bashrc`` or ``a.``), without building a path object: grouping a
    tree's files asks it of every file, twice per diff."""
    name = path[path.rfind("/") + 1 :]
    dot = name.rfind(".")
    return name[dot:] if 0 < dot < len(name) - 1 else ""


def _default_language(path: str) -> str | None:
    return DEFAULT_EXTENSIONS.get(suffix(path).lower())


def _is_c_family(path: str) -> bool:
    return suffix(path).lower() in C_FAMILY_SUFFIXES


def component_name(path: str) -> str:
    """The name of the C/C++ component ``path`` belongs to: its folder and stem (``src/foo``)."""
    ending = suffix(path)
    return path[: len(path) - len(ending)] if ending else path


def _languages(files: Iterable[str], language_of: Callable[[str], str | None]) -> tuple[str, ...]:
    return tuple(sorted({lang for f in files if (lang := language_of(f))}))


COMPONENT, FILE, PACKAGE, NODE = "component", "file", "package", "node"
GROUPINGS = (COMPONENT, FILE, PACKAGE, NODE)
MANIFEST = "package.xml"  # a folder holding one is a ROS package


def group_elements(
    paths: Iterable[str],
    per_file: bool | str = False,
    language_of: Callable[[str], str | None] | None = None,
) -> tuple[Element, ...]:
    """Group tree-relative paths into elements, sorted by name.

    Naming: a Python (or any non-C-family) file is named by its path; a C/C++ component by
    its folder and stem, ``src/foo`` for ``src/foo.c`` + ``src/foo.h`` (also when only one
    of them exists, so adding a header later keeps the name). If a stem name equals the path
    of another file (``a/b.py`` next to ``a/b.py.c``), the component is named by its brace
    list instead (``a/b.py.{c}``). ``per_file`` is the grouping: True or ``"file"``, every
    element is named by its path; ``"package"``, the files of a ROS package (the deepest
    folder above them holding ``package.xml``) are one element named by its folder;
    ``"node"``, in a ROS package the C/C++ files of one stem (``include/pkg/talker.hpp``
    and ``src/talker.cpp``, the class of a node) are one element named ``<package>/<stem>``.
    Files outside any package are grouped as components.
    """
    lang_of = language_of or _default_language
    unique = sorted(set(paths))
    grouping = FILE if per_file is True else (per_file or COMPONENT)
    if grouping == FILE:
        return tuple(Element(p, (p,), _languages((p,), lang_of)) for p in unique)
    packages = _packages(unique) if grouping in (PACKAGE, NODE) else set()
    groups: dict[str, list[str]] = {}
    singles: list[str] = []
    for path in unique:
        package = _package_of(path, packages) if packages else None
        if package is not None and grouping == PACKAGE:
            groups.setdefault(package or ".", []).append(path)
        elif package is not None and _is_c_family(path):
            stem = component_name(path).rpartition("/")[2]
            groups.setdefault(f"{package}/{stem}" if package else stem, []).append(path)
        elif _is_c_family(path):
            groups.setdefault(component_name(path), []).append(path)
        else:
            singles.append(path)
    taken = set(singles)
    elements = [Element(p, (p,), _languages((p,), lang_of)) for p in singles]
    for stem, files in groups.items():
        name = stem if stem not in taken else _brace_name(stem, files)
        elements.append(Element(name, tuple(files), _languages(files, lang_of)))
    return tuple(sorted(elements))


def _packages(paths: list[str]) -> set[str]:
    """The folders holding a ``package.xml`` ("" for the root)."""
    return {p.rpartition("/")[0] for p in paths if p.rpartition("/")[2] == MANIFEST}


def _package_of(path: str, packages: set[str]) -> str | None:
    """The deepest package folder above ``path``, or None."""
    folder = path.rpartition("/")[0]
    while True:
        if folder in packages:
            return folder
        if not folder:
            return None
        folder = folder.rpartition("/")[0]


def _brace_name(stem: str, files: list[str]) -> str:
    suffixes = sorted(suffix(f).lstrip(".") for f in files)
    return f"{stem}.{{{','.join(suffixes)}}}"


def element_of_file(elements: Iterable[Element]) -> dict[str, Element]:
    """Map every file path to the element that holds it."""
    return {path: element for element in elements for path in element.files}


def is_python(path: str) -> bool:
    """Whether ``path`` is a Python module by its ending."""
    return _default_language(path) == Language.PYTHON
