"""Dynamic coupling: find link sites with the rule packs and resolve their endpoints.

Every call (or, for ``site = "definition"`` rules, function definition) matching a rule is one
link site, +1 to its element's d_e (thesis page 110: "for each occurrence"). A call matches at
most one rule: the matching rule with the highest ``priority``, ties going to load order.
An initiating site with endpoint key k links into every other element holding a receiving
site with key k; d_a of an element counts the other elements' sites linking into it.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import replace
from functools import lru_cache
from typing import TYPE_CHECKING

from archmetrics.coupling.endpoints import normalize
from archmetrics.coupling.model import Endpoint, LinkSite, LinkStatus
from archmetrics.coupling.patterns import SlowPattern, search
from archmetrics.coupling.rules import (
    EndpointSource,
    EndpointSpec,
    FunctionHint,
    Role,
    Rule,
    RuleSet,
    SiteKind,
)
from archmetrics.coupling.trace import AMBIGUOUS, ArgumentReader
from archmetrics.facts import Argument, CallSite, FileFacts
from archmetrics.globs import compile_glob, compile_globs

if TYPE_CHECKING:
    from pathspec import GitIgnoreSpec


class AmbiguousEndpoint(Exception):
    """The endpoint's name is given several values (e.g. by different callers)."""


_SPECIAL = re.compile(r"[\s()<>:]|->")
_TEMPLATE = re.compile(r"<[^<>]*>")
_PARENS = re.compile(r"\([^()]*\)")


def _strip_nested(pattern: re.Pattern[str], text: str, empty: str) -> str:
    previous = None
    while previous != text:
        previous, text = text, pattern.sub(empty, text)
    return text


@lru_cache(maxsize=1 << 16)
def normalize_callee(callee: str) -> str:
    """A callee as rules see it: no spaces, no template arguments, ``->``/``::`` as ``.``."""
    if not _SPECIAL.search(callee):
        return callee.lstrip(".")
    text = re.sub(r"\s+", "", callee)
    text = _strip_nested(_PARENS, _strip_nested(_TEMPLATE, text, ""), "()")
    return text.replace("->", ".").replace("::", ".").lstrip(".")


@lru_cache(maxsize=65536)
def _normalized(callee: str) -> tuple[str, str]:
    """A callee normalized, and the last part of that (callees repeat across files)."""
    name = normalize_callee(callee)
    return name, name.rsplit(".", 1)[-1]


@lru_cache(maxsize=4096)
def _compiled(pattern: str) -> GitIgnoreSpec:
    """A rule's ``match`` glob, in the one glob dialect (archmetrics.globs): a callee name
    has no ``/``, so ``*`` takes any run of it, dots included."""
    return compile_glob(normalize_callee(pattern))


@lru_cache(maxsize=65536)
def matches(pattern: str, callee: str) -> bool:
    """Whether a rule pattern (``zmq_connect``, ``*.connect``, ``socket.socket``) matches:
    a pattern without a wild card is the normalized name itself; the answer is kept (a
    function's calls are tried against each hint of each of its sites)."""
    name, _ = _normalized(callee)
    if not any(c in pattern for c in "*?[\\") and not pattern.startswith(("!", "#")):
        return name == normalize_callee(pattern)
    return _compiled(pattern).match_file(name)


def requirement_forms(dependencies: Iterable[str]) -> frozenset[str]:
    """Every way a ``requires`` entry can name a dependency: the dependency itself, its dotted
    prefixes (``zmq`` for ``zmq.asyncio``) and path suffixes (``playerc.h`` for
    ``libplayerc/playerc.h``)."""
    forms: set[str] = set()
    for dep in dependencies:
        parts = dep.split(".")
        forms.update(".".join(parts[: i + 1]) for i in range(len(parts)))
        pieces = dep.split("/")
        forms.update("/".join(pieces[i:]) for i in range(len(pieces)))
    return frozenset(forms)


def requirement_met(requires: Iterable[str], dependencies: Iterable[str]) -> bool:
    """Whether a file that sees ``dependencies`` satisfies a rule's ``requires`` list."""
    wanted = tuple(requires)
    forms = requirement_forms(dependencies) if wanted else frozenset()
    return not wanted or any(want in forms for want in wanted)


WILD_ANSWERS = 200_000  # names whose wild-card answer a rule index keeps


class RuleIndex:
    """Rules indexed by the last name their patterns match, so a call is tried on a few."""

    def __init__(self, rules: Sequence[Rule]) -> None:
        self.by_name: dict[str, list[tuple[int, Rule, str]]] = {}
        self.wild: list[tuple[int, Rule, str]] = []
        self.chosen: dict[tuple[str, bool], Rule | None] = {}  # callees repeat: ask once
        # the wild-card patterns' answer per name, kept for the process: within one tree
        # names seldom repeat, but a history meets the same files' names at every commit
        self._wild_answers: dict[str, bool] = {}
        for order, rule in enumerate(rules):
            for pattern in rule.match:
                last = normalize_callee(pattern).rsplit(".", 1)[-1]
                entry = (order, rule, pattern)
                if any(c in last for c in "*?["):
                    self.wild.append(entry)
                else:
                    self.by_name.setdefault(last, []).append(entry)
        wild = tuple(normalize_callee(pattern) for _, _, pattern in self.wild)
        self._wild = compile_globs(wild) if wild else None

    def may_match(self, callees: Iterable[str]) -> bool:
        """Whether a rule could match one of ``callees`` (True may be wrong, False never is):
        a name's last part is one a rule's pattern ends in, or a wildcard pattern matches it.
        One set look-up a callee, where ``choose`` tries each candidate rule's pattern."""
        if self._wild is None and not self.by_name:
            return False
        by_name, wild, answers = self.by_name, self._wild, self._wild_answers
        for callee in callees:
            name, last = _normalized(callee)
            if last in by_name:
                return True
            if wild is None:
                continue
            answer = answers.get(name)
            if answer is None:
                if len(answers) >= WILD_ANSWERS:
                    answers.clear()
                answer = answers[name] = wild.match_file(name)
            if answer:
                return True
        return False

    def choose(self, callee: str, module_receiver: bool = False) -> Rule | None:
        """The rule a callee matches: highest priority first, then load order.

        With ``module_receiver`` (the receiver is a module name) ``*``-patterns do not match.
        """
        key = (callee, module_receiver)
        if key in self.chosen:
            return self.chosen[key]
        rule = self.chosen[key] = self._choose(normalize_callee(callee), module_receiver)
        return rule

    def _choose(self, name: str, module_receiver: bool) -> Rule | None:
        best: tuple[int, int, Rule] | None = None
        for order, rule, pattern in (*self.by_name.get(name.rsplit(".", 1)[-1], ()), *self.wild):
            if module_receiver and pattern.startswith("*"):
                continue
            rank = (rule.priority, -order)
            if (best is None or rank > best[:2]) and _compiled(pattern).match_file(name):
                best = (*rank, rule)
        return best[2] if best else None


@lru_cache(maxsize=256)
def rule_index(rules: tuple[Rule, ...]) -> RuleIndex:
    """The index of these rules, shared by every file that can use the same ones (rules are
    frozen values, so equal tuples index alike)."""
    return RuleIndex(rules)


def choose_rule(callee: str, rules: Sequence[Rule], module_receiver: bool = False) -> Rule | None:
    """The rule a callee matches: highest priority first, then load order."""
    return RuleIndex(rules).choose(callee, module_receiver)


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
        return definitions.may_match(f.qualified_name for f in facts.functions)


def file_link_sites(
    facts: FileFacts,
    rules: RuleSet,
    visible: Iterable[str],
    read: ArgumentReader,
    modules: frozenset[str] = frozenset(),
) -> tuple[LinkSite, ...]:
    """The unresolved-yet link sites of one file (status and targets are set by ``resolve``)."""
    forms = requirement_forms(visible)
    usable = [
        r for r in rules.for_language(facts.language)
        if not r.requires or any(want in forms for want in r.requires)
    ]  # fmt: skip
    calls = rule_index(tuple(r for r in usable if r.site is SiteKind.CALL))
    found: list[tuple[Rule, LinkSite]] = []
    # a file none of whose callees a rule names has no call site to read (nor to decode)
    readable = facts.call_sites if any(map(calls.choose, facts.callees())) else ()
    for call in readable:
        receiver = normalize_callee(call.receiver) if call.receiver else None
        rule = calls.choose(call.callee, receiver in modules)
        if rule and not (rule.unless_from and _assigned_from(facts, call, rule.unless_from)):
            endpoint, note = read_endpoint(call, rule.endpoint, facts.call_sites, read)
            site = _site(facts.path, call.span.start, rule, call.callee, endpoint, call.function)
            found.append((rule, replace(site, note=note)))
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
            found.append((rule, replace(site, note=note)))
    sites = [_from_file(rule, site, found) for rule, site in found]
    return tuple(sorted(sites, key=lambda s: (s.line, s.rule)))


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
) -> dict[str, tuple[LinkSite, ...]]:
    """Set status and targets: initiating keys meet receiving keys in other elements."""
    receivers: dict[str, set[str]] = {}
    initiators: dict[str, set[str]] = {}
    for element, sites in sites_by_element.items():
        for site in sites:
            if site.endpoint is not None and site.role is Role.RECEIVE:
                receivers.setdefault(site.endpoint.key, set()).add(element)
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
        linked = initiators.get(key, set()) - {element}
        status = LinkStatus.RESOLVED if linked else LinkStatus.EXTERNAL
        return replace(site, status=status)
    targets = tuple(sorted(receivers.get(key, set()) - {element}))
    status = LinkStatus.RESOLVED if targets else LinkStatus.EXTERNAL
    return replace(site, status=status, targets=targets)
