"""Dynamic-coupling rule packs: the validated, frozen form of the TOML data files.

A rule says which calls (or function definitions) are run-time linkages in the thesis's sense
(page 110): what they match, their kind, their role in the link and where their endpoint is.
Validation (``validate.py``) happens up front, and a bad pack fails with :class:`RulePackError`
naming the file, the rule and the key. Reading files is the loader's job.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

from archmetrics.facts import Language


class LinkKind(StrEnum):
    """What sort of run-time linkage a rule finds (thesis page 110's list)."""

    SOCKET = "socket"
    DYNAMIC_LOAD = "dynamic-load"
    DYNAMIC_INVOKE = "dynamic-invoke"
    RTTI = "rtti"
    MESSAGING = "messaging"
    CONFIG = "config"


class Role(StrEnum):
    """A site's part in a link: it opens one, accepts one, or only uses a run-time linkage."""

    INITIATE = "initiate"
    RECEIVE = "receive"
    USE = "use"


class SiteKind(StrEnum):
    CALL = "call"  # a call site matches
    DEFINITION = "definition"  # a function definition matches (a callback the runtime invokes)


class EndpointSource(StrEnum):
    ARGUMENT = "argument"
    CALLEE = "callee"


ENDPOINT_TYPES = frozenset(
    {"address", "port", "topic", "service", "event", "operation", "library", "module",
     "interface", "type", "property", "name", "ice"}
)  # fmt: skip
KNOWN_LANGUAGES = frozenset(str(lang) for lang in Language)


class RulePackError(ValueError):
    """A rule pack that cannot be used; the message names the file, the rule and the key."""

    def __init__(self, source: str, rule: str | None, key: str | None, problem: str) -> None:
        where = source
        if rule is not None:
            where += f": rule {rule!r}"
        if key is not None:
            where += f": key {key!r}"
        super().__init__(f"{where}: {problem}")
        self.source = source
        self.rule = rule
        self.key = key
        self.problem = problem


@dataclass(frozen=True, slots=True)
class FunctionHint:
    """Where to look for the endpoint in the same function: a call matching ``match``."""

    match: str
    arg: int | None = None
    keyword: str | None = None


@dataclass(frozen=True, slots=True)
class EndpointSpec:
    """Where a site's endpoint literal is and how to normalize it (``type``)."""

    type: str
    arg: int | None = None
    keyword: str | None = None
    source: EndpointSource = EndpointSource.ARGUMENT
    pattern: str | None = None  # regex; group 1 (or the whole match) is the endpoint
    same_function: tuple[FunctionHint, ...] = ()
    same_file: bool = False  # else: the one endpoint the file's other sites of the pack agree on


@dataclass(frozen=True, slots=True)
class Rule:
    """One dynamic-linkage rule of a pack."""

    pack: str
    id: str
    languages: tuple[str, ...]
    match: tuple[str, ...]
    kind: LinkKind
    role: Role
    site: SiteKind = SiteKind.CALL
    requires: tuple[str, ...] = ()
    priority: int = 0
    endpoint: EndpointSpec | None = None
    description: str = ""
    examples: tuple[tuple[str, str], ...] = ()  # (language, snippet) pairs
    example_endpoint: str | None = None
    # the call is no link when its first argument was assigned, in the same function, from a
    # call to one of these (``write(fd, ...)`` after ``fd = open(...)`` writes a file)
    unless_from: tuple[str, ...] = ()

    @property
    def qualified_id(self) -> str:
        return f"{self.pack}/{self.id}"


@dataclass(frozen=True, slots=True)
class ConfigEndpoint:
    """Where a configuration link's endpoint is: the values of ``key`` in its table, each
    normalized as ``type`` (``pattern``, when given, picks the part of the value to keep:
    group 1, or the whole match)."""

    type: str
    key: str
    pattern: str | None = None


@dataclass(frozen=True, slots=True)
class ConfigRule:
    """A configuration-link rule of a pack (thesis p. 110: "linkages that could be modified
    through configuration information changes without requiring recompilation"): the files
    (``files`` globs) read as configuration in ``format``, the tables of them that are links
    (``table``: the keys leading to them; ``when``: values some of their keys must hold,
    ``defaults`` standing in for a key the table leaves out), and where the endpoint is. Each
    value of the endpoint's key in such a table is one link site (+1 d_e)."""

    pack: str
    id: str
    files: tuple[str, ...]
    format: str
    table: tuple[str, ...]
    kind: LinkKind
    role: Role
    endpoint: ConfigEndpoint
    when: tuple[tuple[str, tuple[str, ...]], ...] = ()
    defaults: tuple[tuple[str, str], ...] = ()
    description: str = ""
    example: str = ""  # a configuration file in ``format`` holding one such link
    example_endpoint: str | None = None

    @property
    def qualified_id(self) -> str:
        return f"{self.pack}/{self.id}"


@dataclass(frozen=True, slots=True)
class RulePack:
    name: str
    source: str
    description: str
    rules: tuple[Rule, ...]
    configuration: tuple[ConfigRule, ...] = ()
    digest: str = ""  # SHA-256 of the text it was read from ("": made in memory)


@dataclass(frozen=True, slots=True)
class RuleSet:
    """The packs in force, in load order (built-in first, then configured, then plugins)."""

    packs: tuple[RulePack, ...] = ()

    @property
    def rules(self) -> tuple[Rule, ...]:
        return tuple(rule for pack in self.packs for rule in pack.rules)

    def for_language(self, language: str) -> tuple[Rule, ...]:
        return tuple(r for r in self.rules if language in r.languages)

    @property
    def configuration(self) -> tuple[ConfigRule, ...]:
        """The configuration-link rules of every pack, in load order."""
        return tuple(rule for pack in self.packs for rule in pack.configuration)
