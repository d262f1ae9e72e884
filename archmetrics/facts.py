"""Facts: the frozen, language-neutral record of one source file.

Parsers turn bytes into a :class:`FileFacts`; everything downstream (complexity, coupling,
change sets, reports) reads only these values. Every fact carries the line span it came
from, so any number in a report can be traced back to the source lines behind it.

The records a file has many of (statements, calls and their arguments, functions, decisions,
spans) are named tuples: immutable like frozen dataclasses, but built by the tuple's C
constructor (a frozen dataclass sets each field through ``object.__setattr__``, four times
slower), and, holding only strings, numbers and other such tuples, dropped from the cyclic
collector's lists after its first look at them. A release of numpy has two million of them;
docs/performance.md has the figures. Compare them only with records of their own type.
"""

from __future__ import annotations

import hashlib
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass
from enum import StrEnum
from typing import Any, Generic, NamedTuple, TypeVar, overload

T = TypeVar("T")


class Language(StrEnum):
    """Languages with a built-in parser. Third-party parsers may add others by name."""

    PYTHON = "python"
    C = "c"
    CPP = "cpp"


class _Lines(NamedTuple):
    start: int
    end: int


class Span(_Lines):
    """An inclusive range of 1-based physical lines (ordered by start, then end)."""

    __slots__ = ()

    def __new__(cls, start: int, end: int) -> Span:
        if start < 1 or end < start:
            raise ValueError(f"bad span {start}-{end}")
        return tuple.__new__(cls, (start, end))

    def contains(self, line: int) -> bool:
        return self.start <= line <= self.end


class Statement(NamedTuple):
    """One logical line of code (λ counts these), as defined on thesis page 103.

    ``kind`` is the syntax node that made it a statement (the rule-table row in
    docs/metrics.md); ``text`` is the statement's own text with whitespace collapsed and
    comments removed -- for a compound statement only its header (``if (x > 0)``), for a
    function only its signature -- so the change-set engine can pair statements across
    revisions without being fooled by reformatting.
    """

    kind: str
    span: Span
    text: str
    function: str | None = None  # qualified name of the enclosing function, if any


class Decision(NamedTuple):
    """One McCabe decision point (+1 to v_g): ``kind`` names the construct, e.g. ``if``, ``&&``."""

    kind: str
    line: int


class Function(NamedTuple):
    """A function or method. ``complexity`` is McCabe's v_g = 1 + decision points.

    ``parameters``: the names of its parameters in the order written (Python's ``*args``
    and ``**kw`` as ``args`` and ``kw``, ``self`` included; C's ``void`` list is empty),
    so that a value can be traced from a call's argument to the parameter it binds.

    ``estimated``: the parser's syntax tree could not read all of it, and its decisions
    (all of them, when the tree lost the whole function) were counted by a reading of its
    tokens instead; its v_g is then an estimate, and its statements and call sites may be
    incomplete (a warning of the file names the lines; docs/metrics.md, "Warnings")."""

    name: str
    qualified_name: str
    span: Span
    decisions: tuple[Decision, ...]
    statements: int  # logical statements inside it, its signature included
    parameters: tuple[str, ...] = ()
    # the fields a reviewer's `archmetrics: ignore[vg]` comment exempts it from ("*": all);
    # it changes no number, only which thresholds and gates the function can fail
    suppressed: tuple[str, ...] = ()
    estimated: bool = False

    @property
    def complexity(self) -> int:
        return 1 + len(self.decisions)

    def exempt(self, field: str) -> bool:
        """Whether a suppression comment exempts this function from gates on ``field``."""
        return field in self.suppressed or "*" in self.suppressed


class Class(NamedTuple):
    """A class, struct or union definition (C/C++ ``struct`` with a body counts)."""

    name: str
    qualified_name: str
    span: Span
    kind: str = "class"


class DependencyKind(StrEnum):
    INCLUDE = "include"  # #include "file.h"
    INCLUDE_SYSTEM = "include_system"  # #include <file.h>
    IMPORT = "import"  # import a.b / from a.b import c


class Dependency(NamedTuple):
    """A static dependency as written in the source: an include or an import.

    For Python, ``target`` is the module named (``a.b`` for ``from a.b import c``, ``""``
    for ``from . import c``), ``level`` the number of leading dots of a relative import and
    ``names`` the names imported from it; ``bound`` the names the statement binds in the
    file: ``a`` for ``import a.b``, ``c`` for ``import a.b as c``, and for ``from m import x
    as y, z`` one per name (``y``, ``z``). For C/C++, ``target`` is the include path.
    """

    target: str
    kind: DependencyKind
    span: Span
    level: int = 0
    names: tuple[str, ...] = ()
    bound: tuple[str, ...] = ()


class Binding(NamedTuple):
    """A name given a value as written: ``PORT = 5555``, ``#define PORT "3490"``,
    ``const char *port = getenv("P")``, ``fd = socket(...)`` (a plain name on the left of
    ``=``, an initialized declarator, an object-like macro with a body).

    ``value`` is the bound expression's normalized text (as statements' texts are
    normalized); ``function`` the qualified name of the enclosing function, None at file,
    namespace or class level. Coupling reads constants and traces endpoint values from these
    (coupling/endpoints.py, coupling/trace.py), never from statement texts."""

    name: str
    value: str
    line: int
    function: str | None = None


Literal = str | int | float | bool | None


class Argument(NamedTuple):
    """One argument at a call site: its literal value when it is a literal, else None.

    ``text`` is the argument's normalized source text, so a reader can see what it was.
    """

    text: str
    value: Literal = None
    is_literal: bool = False
    keyword: str | None = None


class CallSite(NamedTuple):
    """A call as written: the raw material for dynamic coupling.

    ``callee`` is the called expression's text (``bus.request``, ``zmq_connect``,
    ``dynamic_cast``); ``name`` its last component (``request``); ``receiver`` the text
    before the last ``.``/``->``/``::`` when there is one. In C++ a constructor called
    without a call expression is a call site too, its callee the class (template arguments
    in ``templates``): ``new T(a)``, a declaration ``T x(a);`` or ``T x{a};`` (``target``
    ``x``), an initializer ``Base(a)`` or ``member_(a)`` of a constructor (a member's callee
    is its declared type when the file declares it, else its name); and so is a macro
    called alone on its line between declarations (``PLUGINLIB_EXPORT_CLASS(A, B)``).
    ``target`` is the name the call's value is assigned to (``x = f()``, ``T x = f();``, a
    member initializer ``x_(f())``; also when only accessors follow the call, as in
    ``x = f().value`` or ``x = f().as_string()``).
    """

    callee: str
    name: str
    receiver: str | None
    span: Span
    arguments: tuple[Argument, ...] = ()
    function: str | None = None  # qualified name of the enclosing function, if any
    # C++: the template arguments of the callee's last part as written, normalized
    # (``create_publisher<geometry_msgs::msg::Twist>`` -> ``("geometry_msgs::msg::Twist",)``)
    templates: tuple[str, ...] = ()
    # what the call's value is assigned to or initializes, as written (``pub_``,
    # ``this->pub_``, ``self.pub``, a declared variable); None when it is not
    target: str | None = None


class ConfigFormat(StrEnum):
    """Formats of configuration files a reader turns into :class:`ConfigTable` facts; which
    files are read as configuration is the rule packs' word (docs/metrics.md)."""

    TOML = "toml"
    XML = "xml"
    YAML = "yaml"
    ROSIDL = "rosidl"  # a ROS interface definition (.msg, .srv, .action): listed, λ = 0


class ConfigTable(NamedTuple):
    """One table of a configuration file: the raw material for configuration links (thesis
    p. 110: "linkages that could be modified through configuration information changes
    without requiring recompilation"), as a call site is for the links code makes.

    ``keys``: the keys leading to it from the document's root, array positions left out, so
    every ``[[rules.to]]`` table is ``("rules", "to")`` (the root table is ``()``); ``line``:
    where it is written (its header; for a table written inline, the line of the key holding
    it); ``values``: its keys that hold text, numbers, booleans or arrays of them, each with
    its values as text, in the order written. Tables inside it are tables of their own."""

    keys: tuple[str, ...]
    line: int
    values: tuple[tuple[str, tuple[str, ...]], ...] = ()
    # the index, among the file's tables, of the table holding this one (-1: none read); an
    # XML element's or a YAML mapping's parent, so a launch file's <remap> finds its <node>
    parent: int = -1

    def get(self, key: str) -> tuple[str, ...] | None:
        """The values of ``key``, None when the table does not hold it."""
        for name, values in self.values:
            if name == key:
                return values
        return None


class Severity(StrEnum):
    WARNING = "warning"
    ERROR = "error"


@dataclass(frozen=True, slots=True)
class ParseWarning:
    """Something that kept a file from being measured in full; names the file and line."""

    path: str
    line: int
    message: str
    severity: Severity = Severity.WARNING

    def __str__(self) -> str:
        return f"{self.path}:{self.line}: {self.severity}: {self.message}"


class Deferred(Sequence[T], Generic[T]):
    """An immutable sequence whose items are made when first read.

    Decoded facts hold their statements and call sites this way: a diff reads the statements
    of the files that changed, and coupling the call sites of the files where a rule names a
    callee, so the rest stay compact bytes (docs/performance.md). It equals, and hashes as,
    the tuple of its items.
    """

    __slots__ = ("_items", "_length", "_make", "digest", "keys")

    def __init__(
        self,
        length: int,
        make: Callable[[], tuple[T, ...]],
        keys: frozenset[str] | None = None,
        digest: str | None = None,
    ):
        self._length = length
        self._make: Callable[[], tuple[T, ...]] | None = make
        self._items: tuple[T, ...] | None = None
        # what the maker kept readable without making the items: call sites keep their
        # callees (``keys``), statements the digest of their kinds and texts (``digest``)
        self.keys = keys
        self.digest = digest

    def items(self) -> tuple[T, ...]:
        """The items, made on the first call."""
        if self._items is None:
            assert self._make is not None
            items = self._make()
            if len(items) != self._length:
                raise ValueError(f"{len(items)} items made, {self._length} announced")
            self._items, self._make = items, None
        return self._items

    def __len__(self) -> int:
        return self._length

    @overload
    def __getitem__(self, index: int) -> T: ...
    @overload
    def __getitem__(self, index: slice) -> tuple[T, ...]: ...
    def __getitem__(self, index: int | slice) -> T | tuple[T, ...]:
        return self.items()[index]

    def __iter__(self) -> Iterator[T]:
        return iter(self.items())

    def __eq__(self, other: object) -> bool:
        if isinstance(other, Deferred):
            return self is other or self.items() == other.items()
        return isinstance(other, tuple) and self.items() == other

    def __hash__(self) -> int:
        return hash(self.items())

    def __repr__(self) -> str:
        return repr(self.items())

    def __reduce__(self) -> tuple[Any, ...]:
        return (tuple, (self.items(),))


def statements_digest(statements: Iterable[Statement]) -> str:
    """A digest of the kinds and texts of ``statements``, in order: two sequences with the
    same digest have the same statements but for their lines."""
    digest = hashlib.blake2b(digest_size=16)
    for statement in statements:
        kind, text = statement.kind.encode(), statement.text.encode()
        digest.update(b"%d:%s%d:%s" % (len(kind), kind, len(text), text))
    return digest.hexdigest()


def kept_digest(statements: Sequence[Statement]) -> str | None:
    """The digest the cache kept of a statement sequence, without decoding it; None when
    the sequence came from a parser."""
    return statements.digest if isinstance(statements, Deferred) else None


@dataclass(frozen=True, slots=True)
class FileFacts:
    """Everything archmetrics knows about one file version.

    ``statements``, ``call_sites`` and ``bindings`` are tuples from a parser,
    :class:`Deferred` from the cache. A configuration file (``language`` a
    :class:`ConfigFormat`) has ``tables`` and nothing else: it is no executable code, so it
    adds nothing to λ or v_g, only links."""

    path: str
    language: str
    statements: Sequence[Statement] = ()
    functions: tuple[Function, ...] = ()
    classes: tuple[Class, ...] = ()
    dependencies: tuple[Dependency, ...] = ()
    call_sites: Sequence[CallSite] = ()
    bindings: Sequence[Binding] = ()  # in source order
    sloc: int = 0  # physical lines that are neither blank nor only comment
    warnings: tuple[ParseWarning, ...] = ()
    parsed: bool = True  # False: the parser could not read it at all (reported, not guessed)
    generated: bool = False  # the file declares itself generated ("@generated", "DO NOT EDIT")
    tables: tuple[ConfigTable, ...] = ()  # a configuration file's tables (ConfigFormat)

    def callees(self) -> frozenset[str]:
        """The callees of the file's call sites (read without decoding them, if cached)."""
        sites = self.call_sites
        if isinstance(sites, Deferred) and sites.keys is not None:
            return sites.keys
        return frozenset(call.callee for call in sites)

    @property
    def loc(self) -> int:
        """Logical lines of code, λ."""
        return len(self.statements)

    @property
    def vg(self) -> int:
        """McCabe complexity of the file: the sum over its functions."""
        return sum(f.complexity for f in self.functions)
