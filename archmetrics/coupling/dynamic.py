"""Dynamic coupling: find link sites with the rule packs and resolve their endpoints.

Every call (or, for ``site = "definition"`` rules, function definition) matching a rule is one
link site, +1 to its element's d_e (thesis page 110: "for each occurrence"). A call matches at
most one rule: the matching rule with the highest ``priority``, ties going to load order.
An initiating site with endpoint key k links into every other element holding a receiving
site with key k (or receiving k without a site: a parameter file, rosgraph.py); d_a of an
element counts the other elements' sites linking into it. Which rule a call matches is
matching.py's; graph names and data types are graphnames.py's; a call on an object made by
another call takes that call's endpoint (receivers.py).
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field, replace

from archmetrics.coupling.endpoints import normalize
from archmetrics.coupling.graphnames import (
    TypeAliases,
    completed,
    data_type,
    graph_endpoint,
    imported_names,
    qualified,
    through_alias,
)
from archmetrics.coupling.matching import (
    Requirements,
    RuleIndex,
    choose_rule,
    constructed,
    matches,
    member,
    normalize_callee,
    requirement_forms,
    requirement_met,
    rule_index,
)
from archmetrics.coupling.model import Endpoint, LinkSite, LinkStatus
from archmetrics.coupling.patterns import SlowPattern, search
from archmetrics.coupling.receivers import Found, bound_to_makers, invoked
from archmetrics.coupling.rules import (
    EndpointSource,
    EndpointSpec,
    FunctionHint,
    Role,
    Rule,
    RuleSet,
    SiteKind,
)
from archmetrics.coupling.scopes import FileScopes
from archmetrics.coupling.trace import AMBIGUOUS, ArgumentReader
from archmetrics.facts import Argument, CallSite, FileFacts, Language

__all__ = [
    "AmbiguousEndpoint", "FileContext", "LinkFilter", "RuleIndex", "choose_rule",
    "file_link_sites", "matches", "normalize_callee", "read_endpoint", "requirement_forms",
    "requirement_met", "resolve", "rule_index",
]  # fmt: skip


class AmbiguousEndpoint(Exception):
    """The endpoint's name is given several values (e.g. by different callers)."""


@dataclass(frozen=True, slots=True)
class FileContext:
    """What resolving a file's graph names needs: its naming scopes and, in Python, the names
    its imports bind (a type written ``Twist`` is ``geometry_msgs.msg.Twist``), in C and C++
    its type aliases."""

    scopes: FileScopes
    imports: Mapping[str, str] = field(default_factory=dict)
    aliases: TypeAliases | None = None  # C++: the file's type aliases


def _pick(arguments: Sequence[Argument], index: int | None, keyword: str | None) -> Argument | None:
    if keyword is not None:
        for argument in arguments:
            if argument.keyword == keyword:
                return argument
    positional = [a for a in arguments if a.keyword is None]
    if index is not None and index < len(positional):
        return positional[index]
    return None


def _key_from(
    argument: Argument | None, spec: EndpointSpec, read: ArgumentReader, call: CallSite
) -> Endpoint | None:
    if argument is None:
        return None
    value, via = read(argument, call.function, call.span.start)
    if via.startswith(AMBIGUOUS):
        raise AmbiguousEndpoint(f"{argument.text}: {via}")
    if spec.pattern is not None:
        subject = value if isinstance(value, str) else argument.text
        found = search(spec.pattern, subject)
        value = (found.group(1) if found.groups() else found.group(0)) if found else None
    key = normalize(spec.type, value) if value is not None else None
    return Endpoint(key, argument.text, via) if key else None


def _first_matching(call: CallSite, spec: EndpointSpec, read: ArgumentReader) -> Endpoint | None:
    """With a pattern but no position: the first argument whose text the pattern finds."""
    for argument in call.arguments:
        if found := _key_from(argument, spec, read, call):
            return found
    return None


def _from_callee(callee: str, spec: EndpointSpec) -> Endpoint | None:
    found = search(spec.pattern or "", callee)
    if not found:
        return None
    key = normalize(spec.type, found.group(1) if found.groups() else found.group(0))
    return Endpoint(key, callee, "callee") if key else None


def _from_function(
    call: CallSite, hints: Sequence[FunctionHint], spec: EndpointSpec, calls: Sequence[CallSite],
    read: ArgumentReader,
) -> Endpoint | None:  # fmt: skip
    scope = sorted((c for c in calls if c.function == call.function), key=lambda c: c.span.start)
    for hint in hints:
        for other in scope:
            if matches(hint.match, other.callee):
                picked = _pick(other.arguments, hint.arg, hint.keyword)
                if found := _key_from(picked, spec, read, other):
                    return replace(found, via="same-function")
    return None


def read_endpoint(
    call: CallSite, spec: EndpointSpec | None, calls: Sequence[CallSite], read: ArgumentReader
) -> tuple[Endpoint | None, str]:
    """The endpoint of a matched call as its rule's spec says (None if unknown), and a note."""
    try:
        return _read_endpoint(call, spec, calls, read), ""
    except (AmbiguousEndpoint, SlowPattern) as unknown:
        return None, str(unknown)


def _read_endpoint(
    call: CallSite, spec: EndpointSpec | None, calls: Sequence[CallSite], read: ArgumentReader
) -> Endpoint | None:
    if spec is None:
        return None
    if spec.source is EndpointSource.CALLEE:
        return _from_callee(call.callee, spec)
    if spec.arg is None and spec.keyword is None and spec.pattern is not None:
        found = _first_matching(call, spec, read)
    else:
        found = _key_from(_pick(call.arguments, spec.arg, spec.keyword), spec, read, call)
        for index in spec.more_args if found is None else ():
            found = _key_from(_pick(call.arguments, index, None), spec, read, call)
            if found is not None:
                break
    if found is None and spec.same_function:
        found = _from_function(call, spec.same_function, spec, calls, read)
    return found


class LinkFilter:
    """Whether a rule names one of a file's callees or functions: a file for which this is
    False has no link site, whatever it includes or imports (``requires`` and ``unless_from``
    only narrow what these names match), so nothing more of it need be read or traced."""

    def __init__(self, rules: RuleSet) -> None:
        self.rules = rules
        self._indexes: dict[str, tuple[RuleIndex, RuleIndex]] = {}

    def __call__(self, facts: FileFacts) -> bool:
        indexes = self._indexes.get(facts.language)
        if indexes is None:
            usable = self.rules.for_language(facts.language)
            indexes = self._indexes[facts.language] = (
                rule_index(tuple(r for r in usable if r.site is SiteKind.CALL)),
                rule_index(tuple(r for r in usable if r.site is SiteKind.DEFINITION)),
            )
        calls, definitions = indexes
        if calls.may_match(facts.callees()):
            return True
        if facts.language == Language.PYTHON and facts.dependencies:  # callees as imported
            imports = imported_names(facts.dependencies)
            if imports and calls.may_match(qualified(c, imports) for c in facts.callees()):
                return True
        return definitions.may_match(f.qualified_name for f in facts.functions)


def file_link_sites(
    facts: FileFacts,
    rules: RuleSet,
    visible: Iterable[str],
    read: ArgumentReader,
    modules: frozenset[str] = frozenset(),
    context: FileContext | None = None,
) -> tuple[LinkSite, ...]:
    """The unresolved-yet link sites of one file (status and targets are set by ``resolve``)."""
    seen = Requirements(visible)
    usable = [r for r in rules.for_language(facts.language) if seen.met(r.requires)]
    calls = rule_index(tuple(r for r in usable if r.site is SiteKind.CALL))
    found: list[Found] = []
    # a file none of whose callees a rule names has no call site to read (nor to decode)
    readable = facts.call_sites if calls.may_match(facts.callees()) else ()
    for call in readable:
        callee, _ = constructed(call)
        receiver = normalize_callee(call.receiver) if call.receiver else None
        rule = calls.choose(callee, receiver in modules)
        if rule is None and context is not None and context.imports:  # as imported: a
            # module's function, which no ``*.name`` pattern (a method on any object) names
            named = qualified(callee, context.imports)
            rule = calls.choose(named, True) if named != callee else None
        elif rule is None and context is not None and context.aliases is not None:
            aliased = through_alias(call, context.aliases)  # made through a type alias
            rule = calls.choose(aliased.callee) if aliased is not None else None
            call = aliased if rule is not None and aliased is not None else call
        if rule and not (rule.unless_from and _assigned_from(facts, call, rule.unless_from)):
            if _bare(call, rule):
                continue
            found.append(Found(rule, _call_site(facts, call, rule, read, context), call))
    made = {member(f.call.target) for f in found if f.call is not None and f.call.target}
    for call in readable if made else ():
        if (called := invoked(call, made)) and (rule := calls.choose(called.callee)):
            found.append(Found(rule, _call_site(facts, called, rule, read, context), called))
    definitions = rule_index(tuple(r for r in usable if r.site is SiteKind.DEFINITION))
    for function in facts.functions:
        if rule := definitions.choose(function.qualified_name):
            spec, name = rule.endpoint, function.qualified_name
            endpoint, note = None, ""
            if spec and spec.pattern:
                try:
                    endpoint = _from_callee(name, spec)
                except SlowPattern as slow:
                    note = str(slow)
            site = _site(facts.path, function.span.start, rule, name, endpoint, name)
            found.append(Found(rule, replace(site, note=note), None))
    pairs = [(f.rule, f.site) for f in found]
    found = [Found(f.rule, _from_file(f.rule, f.site, pairs), f.call) for f in found]
    found = [_fallback(f, context) for f in bound_to_makers(found, facts)]
    return tuple(sorted((f.site for f in found), key=lambda s: (s.line, s.rule)))


def _call_site(
    facts: FileFacts, call: CallSite, rule: Rule, read: ArgumentReader, context: FileContext | None
) -> LinkSite:
    """The link site ``call`` is under ``rule``: its endpoint read, its graph name resolved
    and its data type read where the rule says so."""
    spec = rule.endpoint
    endpoint, note = read_endpoint(call, spec, facts.call_sites, read)
    if (
        endpoint is None
        and not note
        and spec is not None
        and not spec.created_by
        and (spec.naming or spec.type in _SAID)
    ):
        note = _unknown(call, spec)  # graph names, plugins, launched nodes: always said why
    site = replace(_site(facts.path, call.span.start, rule, call.callee, endpoint, call.function),
                   note=note)  # fmt: skip
    if spec is None or context is None or not (spec.naming or spec.value or spec.data_type):
        return site
    kind = data_type(call, spec.data_type, context.imports, spec.naming == "ros1", context.aliases)
    if spec.naming == "ros1" and spec.type == "action":  # actionlib's MoveBaseAction
        kind = kind.removesuffix("Action")  # is the action move_base_msgs/MoveBase
    if spec.created_by and endpoint is None:
        return replace(site, data_type=kind)  # its maker gives it (receivers.py)
    parameter = endpoint.via.partition(":")[2] if endpoint and endpoint.via.startswith(
        "parameter:") else ""  # fmt: skip
    named = graph_endpoint(spec, call, endpoint, note, context.scopes)
    return completed(site, named, kind, parameter)


_SAID = frozenset({"plugin", "node"})


def _bare(call: CallSite, rule: Rule) -> bool:
    """A call without arguments where a graph-name rule reads its name from one
    (``filter->subscribe()`` re-subscribing a subscriber made elsewhere): no new link."""
    spec = rule.endpoint
    return (
        spec is not None and spec.naming is not None and not call.arguments
        and (spec.arg is not None or spec.keyword is not None)
        and not spec.value and not spec.created_by
    )  # fmt: skip


def _unknown(call: CallSite, spec: EndpointSpec) -> str:
    """Why a call's endpoint could not be read (docs/metrics.md: never dropped, never a
    guess): the argument is missing, or it is computed."""
    if spec.value or spec.source is EndpointSource.CALLEE or (spec.arg is None and spec.keyword
                                                              is None):  # fmt: skip
        return ""
    argument = _pick(call.arguments, spec.arg, spec.keyword)
    if argument is None:
        where = " or ".join(
            p for p in (f"argument {spec.arg}" if spec.arg is not None else "",
                        f"{spec.keyword}=" if spec.keyword else "") if p
        )  # fmt: skip
        return f"no {where}: the name is not given here"
    return (
        f"{argument.text}: computed at run time (no literal, constant or value traced in this file)"
    )


def _fallback(item: Found, context: FileContext | None) -> Found:
    """A site on an object that no call of the file made takes its rule's fixed ``value``
    (a tf broadcaster's ``sendTransform``: ``/tf``)."""
    spec = item.rule.endpoint
    if (
        spec is None or not spec.value or not spec.created_by or item.site.endpoint is not None
        or item.call is None or context is None or item.site.note.startswith("made by several")
    ):  # fmt: skip
        return item
    named = graph_endpoint(spec, item.call, None, "", context.scopes)
    return Found(item.rule, completed(item.site, named, item.site.data_type, ""), item.call)


def _assigned_from(facts: FileFacts, call: CallSite, producers: Sequence[str]) -> bool:
    """Whether the call's first argument is a name that its function assigns, before the call,
    from a call to one of ``producers`` (``fd = open ( ... )``, ``int fd = mkstemp ( p ) ;``)."""
    first = next((a for a in call.arguments if a.keyword is None), None)
    if first is None or not re.fullmatch(r"[A-Za-z_]\w*", first.text):
        return False
    names = "|".join(re.escape(p) for p in producers)
    produced = re.compile(rf"(?:\( \w+ \) )?(?:{names}) \(")  # (int) open ( ...
    return any(
        b.name == first.text
        and b.function == call.function
        and b.line <= call.span.start
        and produced.match(b.value)
        for b in facts.bindings
    )


def _from_file(rule: Rule, site: LinkSite, found: Sequence[tuple[Rule, LinkSite]]) -> LinkSite:
    """A ``same_file`` site without endpoint takes the one its file's pack-mates agree on.

    Sites of the same role are asked first, then all sites of the pack; two different
    endpoints leave the site unknown.
    """
    if site.endpoint or site.note or rule.endpoint is None or not rule.endpoint.same_file:
        return site
    mates = [s for r, s in found if r.pack == rule.pack and s.endpoint is not None]
    for pool in ([s for s in mates if s.role is site.role], mates):
        keys = {s.endpoint.key for s in pool if s.endpoint is not None}
        if keys:
            if len(keys) > 1:
                return site
            return replace(site, endpoint=Endpoint(keys.pop(), "", "same-file"))
    return site


def _site(path: str, line: int, rule: Rule, callee: str, endpoint: Endpoint | None,
          function: str | None) -> LinkSite:  # fmt: skip
    return LinkSite(path, line, rule.qualified_id, rule.kind, rule.role, callee, endpoint,
                    LinkStatus.UNRESOLVED, (), function)  # fmt: skip


def resolve(
    sites_by_element: Mapping[str, tuple[LinkSite, ...]],
    implicit: Mapping[str, frozenset[str]] | None = None,
) -> dict[str, tuple[LinkSite, ...]]:
    """Set status and targets: initiating keys meet receiving keys in other elements (a
    receiving site's ``also`` keys too), and the ``implicit`` receivers of a key (elements
    receiving it without a site: a parameter file, an executable a launch file starts)."""
    receivers: dict[str, set[str]] = {k: set(v) for k, v in (implicit or {}).items()}
    initiators: dict[str, set[str]] = {}
    for element, sites in sites_by_element.items():
        for site in sites:
            if site.endpoint is not None and site.role is Role.RECEIVE:
                for key in (site.endpoint.key, *site.endpoint.also):
                    receivers.setdefault(key, set()).add(element)
            if site.endpoint is not None and site.role is Role.INITIATE:
                initiators.setdefault(site.endpoint.key, set()).add(element)
    return {
        element: tuple(_resolved(site, element, receivers, initiators) for site in sites)
        for element, sites in sites_by_element.items()
    }


def _resolved(site: LinkSite, element: str, receivers: Mapping[str, set[str]],
              initiators: Mapping[str, set[str]]) -> LinkSite:  # fmt: skip
    if site.role is Role.USE:
        return replace(site, status=LinkStatus.LOCAL)
    if site.endpoint is None:
        return replace(site, status=LinkStatus.UNRESOLVED)
    key = site.endpoint.key
    if site.role is Role.RECEIVE:
        keys = (key, *site.endpoint.also)
        linked = set().union(*(initiators.get(k, set()) for k in keys)) - {element}
        status = LinkStatus.RESOLVED if linked else LinkStatus.EXTERNAL
        return replace(site, status=status)
    targets = tuple(sorted(receivers.get(key, set()) - {element}))
    status = LinkStatus.RESOLVED if targets else LinkStatus.EXTERNAL
    return replace(site, status=status, targets=targets)
