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
     "interface", "type", "property", "name", "ice", "action", "plugin", "parameter", "node"}
)  # fmt: skip
NAMINGS = frozenset({"ros", "ros1"})  # how names resolve (coupling/rosnames.py)
# configuration files read by code that knows their format's meaning (coupling/roslinks.py)
INTERPRETERS = frozenset(
    {"ros-parameters", "ros-launch", "pluginlib", "ros-package", "ros-interface"}
)
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
class Place:
    """Where a value is at a call: a template argument of the callee (C++), a positional
    argument, a keyword argument (tried first), or a fixed ``value``; ``callback`` (C++, a
    data type): else the type of the first parameter of the file's function the positional
    argument at that index names (ROS 1's ``nh.subscribe("scan", 10, onScan)``)."""

    template: int | None = None
    arg: int | None = None
    keyword: str | None = None
    value: str | None = None
    callback: int | None = None


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
    # the name is fixed (a tf broadcaster's ``/tf``); more than one: the site receives all
    value: tuple[str, ...] = ()
    # a call on an object made by a call matching one of these (``pub_->publish(m)`` after
    # ``pub_ = create_publisher<T>("x", 10)``) takes that call's endpoint and data type
    created_by: tuple[str, ...] = ()
    naming: str | None = None  # "ros"/"ros1": a graph name, resolved against its node
    data_type: Place | None = None  # where the message, service or action type is
    # with created_by: a call on an object no call of the file made is no link (``call``)
    created_only: bool = False
    # positions tried after ``arg`` when it gives nothing (an overload with more arguments:
    # rclcpp_action::create_client(base, graph, logging, waitables, name))
    more_args: tuple[int, ...] = ()


@dataclass(frozen=True, slots=True)
class ScopeRule:
    """Calls that say what names resolve against (``kind``): ``node`` -- a node's name and
    namespace (``Node("talker")``, ``rospy.init_node("talker")``), for the calls of its
    class, of the object it makes, or of its file; ``handle`` -- a ROS 1 NodeHandle's
    namespace (``ros::NodeHandle pnh("~")``), for the calls on the object it makes."""

    pack: str
    id: str
    languages: tuple[str, ...]
    match: tuple[str, ...]
    kind: str
    name: Place | None = None
    namespace: Place | None = None
    requires: tuple[str, ...] = ()
    description: str = ""


@dataclass(frozen=True, slots=True)
class ValueRule:
    """Calls whose value is known statically although it is no literal: a parameter read
    with its default (``declare_parameter("topic", "cmd_vel")``: ``value`` is the default,
    ``name`` the parameter's name, so that a later ``get_parameter("topic")`` reads the same
    value), a wrapper (``rclcpp::ParameterValue("x")``), or a call that writes the value
    into one of its arguments (``out``: ``get_parameter("topic", topic_)``)."""

    pack: str
    id: str
    languages: tuple[str, ...]
    match: tuple[str, ...]
    value: Place | None = None
    name: Place | None = None
    out: int | None = None
    requires: tuple[str, ...] = ()
    description: str = ""


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
    # the links are read by code that knows the file's meaning (a launch file, a parameter
    # file, a plugin description; INTERPRETERS) instead of ``table`` and ``endpoint.key``
    interpret: str | None = None
    # the files are configuration only inside a folder holding this file (``package.xml``:
    # a ROS package), so a tree without it reads none of them
    within: str | None = None

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
    scopes: tuple[ScopeRule, ...] = ()
    values: tuple[ValueRule, ...] = ()


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

    @property
    def scopes(self) -> tuple[ScopeRule, ...]:
        """The naming-scope rules of every pack, in load order."""
        return tuple(rule for pack in self.packs for rule in pack.scopes)

    @property
    def values(self) -> tuple[ValueRule, ...]:
        """The value rules of every pack, in load order."""
        return tuple(rule for pack in self.packs for rule in pack.values)
