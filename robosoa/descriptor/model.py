"""Frozen facts of a service descriptor (Hestand 2011, p. 93-94 and Appendix A field list).

Every fact carries the descriptor line it came from, so a later check or a generated file can
point back at the XML that produced it.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Any

from robosoa.qos import QoS


class Pattern(StrEnum):
    """Message exchange patterns of the thesis (p. 62)."""

    REQUEST_RESPONSE = "request-response"
    PUBLISH_SUBSCRIBE = "publish-subscribe"
    ONE_WAY = "one-way"
    EVENT = "event"
    POINT_TO_POINT = "point-to-point"

    @property
    def has_replies(self) -> bool:
        """Whether operations under this pattern may declare return values."""
        return self in (Pattern.REQUEST_RESPONSE, Pattern.POINT_TO_POINT)


class Actor(StrEnum):
    """The side of the service a participant plays."""

    PROVIDER = "provider"
    CONSUMER = "consumer"


class Packaging(StrEnum):
    """Packaging form factors (thesis p. 94)."""

    PROVIDER_EXECUTABLE = "provider-executable"
    PROVIDER_LIBRARY = "provider-library"
    CONSUMER_SOURCE = "consumer-source"
    CONSUMER_NO_SOURCE = "consumer-no-source"

    @property
    def actor(self) -> Actor:
        """The actor this packaging form belongs to."""
        return Actor.PROVIDER if self.value.startswith("provider") else Actor.CONSUMER


class ImplementationForm(StrEnum):
    """How the code behind a participant is delivered: a program, a library or source."""

    EXECUTABLE = "executable"
    LIBRARY = "library"
    SOURCE = "source"


class Language(StrEnum):
    """Language of the code a participant binds to (generated code is always Python)."""

    PYTHON = "python"
    C = "c"
    ANY = "any"


class OperatingSystem(StrEnum):
    """Operating systems a participant may be generated for."""

    ANY = "any"
    POSIX = "posix"
    LINUX = "linux"
    MACOS = "macos"
    WINDOWS = "windows"


class Encoding(StrEnum):
    """How a provider-executable passes requests on stdin and reads results from stdout."""

    JSON = "json"
    XML = "xml"
    TEXT = "text"


class Profile(StrEnum):
    """Code generation profiles: whether generated code checks payloads against the types."""

    CHECKED = "checked"
    UNCHECKED = "unchecked"


PRIMITIVES: tuple[str, ...] = ("int", "float", "bool", "string", "bytes")


@dataclass(frozen=True, slots=True)
class TypeRef:
    """A data type expression: a primitive, a named struct, or ``list[...]`` of a type."""

    name: str
    item: TypeRef | None = None

    @property
    def is_list(self) -> bool:
        """Whether this is ``list[item]``."""
        return self.item is not None

    @property
    def is_primitive(self) -> bool:
        """Whether this is one of :data:`PRIMITIVES`."""
        return self.item is None and self.name in PRIMITIVES

    def __str__(self) -> str:
        return f"list[{self.item}]" if self.item is not None else self.name


@dataclass(frozen=True, slots=True)
class Parameter:
    """A call parameter, a return value or a struct field: name, type and optional default."""

    name: str
    type: TypeRef
    required: bool
    default: str | None
    definition: str
    line: int


@dataclass(frozen=True, slots=True)
class TypeDef:
    """A named struct type defined in the descriptor's ``<types>``."""

    name: str
    fields: tuple[Parameter, ...]
    definition: str
    line: int


@dataclass(frozen=True, slots=True)
class StreamQos:
    """The ``<qos>`` of a topic or event: what was written (None: the default), and where."""

    depth: int | None
    max_bytes: int | None
    lifespan: float | None
    keep_latest: bool
    reliable: bool
    block: float | None
    line: int

    def settings(self) -> QoS:
        """The runtime's QoS (robosoa.qos.QoS) with these settings; raises ValueError for
        a combination the semantic checks refuse."""
        given: dict[str, Any] = {"depth": self.depth, "max_bytes": self.max_bytes,
                                 "lifespan": self.lifespan, "block": self.block}
        return QoS(keep_latest=self.keep_latest, reliable=self.reliable,
                   **{k: v for k, v in given.items() if v is not None})


@dataclass(frozen=True, slots=True)
class Operation:
    """An operation with its call parameters and return values."""

    name: str
    parameters: tuple[Parameter, ...]
    returns: tuple[Parameter, ...]
    definition: str
    line: int
    idempotent: bool = False  # a consumer may retry it on another instance (fail-over)
    qos: StreamQos | None = None  # publish-subscribe and event: the stream's QoS


@dataclass(frozen=True, slots=True)
class Command:
    """A program a provider-executable runs; ``operation`` None means every operation."""

    operation: str | None
    argv: str
    line: int


@dataclass(frozen=True, slots=True)
class Function:
    """Maps an operation to a library symbol (Python function or C function name)."""

    operation: str
    symbol: str
    line: int


@dataclass(frozen=True, slots=True)
class Implementation:
    """Implementation form factor and the details each form needs."""

    form: ImplementationForm
    library: str | None
    encoding: Encoding
    timeout: float
    commands: tuple[Command, ...]
    functions: tuple[Function, ...]
    line: int

    def symbol(self, operation: str) -> str:
        """The library symbol that implements ``operation`` (defaults to its name)."""
        return next((f.symbol for f in self.functions if f.operation == operation), operation)

    def command(self, operation: str) -> Command | None:
        """The command that serves ``operation``: its own, else the catch-all one."""
        own = [c for c in self.commands if c.operation == operation]
        general = [c for c in self.commands if c.operation is None]
        chosen = own or general
        return chosen[0] if chosen else None


@dataclass(frozen=True, slots=True)
class Naming:
    """Names of the generated package, module and class."""

    package: str
    module: str
    class_name: str


@dataclass(frozen=True, slots=True)
class Participant:
    """One consumer or provider of the service, packaged in one form."""

    actor: Actor
    packaging: Packaging
    language: Language
    os: OperatingSystem
    implementation: Implementation | None
    profile: Profile
    naming: Naming
    group: str | None
    line: int
