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


def group_elements(
    paths: Iterable[str],
    per_file: bool = False,
    language_of: Callable[[str], str | None] | None = None,
) -> tuple[Element, ...]:
    """Group tree-relative paths into elements, sorted by name.

    Naming: a Python (or any non-C-family) file is named by its path; a C/C++ component by
    its folder and stem, ``src/foo`` for ``src/foo.c`` + ``src/foo.h`` (also when only one
    of them exists, so adding a header later keeps the name). If a stem name equals the path
    of another file (``a/b.py`` next to ``a/b.py.c``), the component is named by its brace
    list instead (``a/b.py.{c}``). With ``per_file`` every element is named by its path.
    """
    lang_of = language_of or _default_language
    unique = sorted(set(paths))
    if per_file:
        return tuple(Element(p, (p,), _languages((p,), lang_of)) for p in unique)
    groups: dict[str, list[str]] = {}
    singles: list[str] = []
    for path in unique:
        if _is_c_family(path):
            groups.setdefault(component_name(path), []).append(path)
        else:
            singles.append(path)
    taken = set(singles)
    elements = [Element(p, (p,), _languages((p,), lang_of)) for p in singles]
    for stem, files in groups.items():
        name = stem if stem not in taken else _brace_name(stem, files)
        elements.append(Element(name, tuple(files), _languages(files, lang_of)))
    return tuple(sorted(elements))


def _brace_name(stem: str, files: list[str]) -> str:
    suffixes = sorted(suffix(f).lstrip(".") for f in files)
    return f"{stem}.{{{','.join(suffixes)}}}"


def element_of_file(elements: Iterable[Element]) -> dict[str, Element]:
    """Map every file path to the element that holds it."""
    return {path: element for element in elements for path in element.files}


def is_python(path: str) -> bool:
    """Whether ``path`` is a Python module by its ending."""
    return _default_language(path) == Language.PYTHON
