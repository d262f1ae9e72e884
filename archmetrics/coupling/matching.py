"""Which rule a call matches: callees normalized, ``match`` globs, ``requires`` lists, and
rules indexed by the last name their patterns match (dynamic.py finds the sites with it).

A constructor called through ``std::make_shared<T>(...)`` or ``std::make_unique<T>(...)``
is matched as a call of ``T`` (:func:`constructed`): ``make_shared<tf2_ros::TransformListener>
(buffer)``, ``new tf2_ros::TransformListener(buffer)`` and ``tf2_ros::TransformListener
listener(buffer);`` are one construct, written three ways.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Sequence
from functools import lru_cache
from typing import TYPE_CHECKING

from archmetrics.coupling.rules import Rule
from archmetrics.facts import CallSite
from archmetrics.globs import compile_glob, compile_globs
from archmetrics.parsers.c_family_calls import template_arguments, without_template_arguments

if TYPE_CHECKING:
    from pathspec import GitIgnoreSpec


_SPECIAL = re.compile(r"[\s()<>:]|->")
_TEMPLATE = re.compile(r"<[^<>]*>")
_PARENS = re.compile(r"\([^()]*\)")
_TEMPLATE_KEYWORD = re.compile(r"(?<=[.>:])\s*template\s+")
MAKERS = frozenset(
    {"std.make_shared", "std.make_unique", "make_shared", "make_unique", "boost.make_shared"}
)


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
    text = _TEMPLATE_KEYWORD.sub("", callee)  # node->template create_client<T>
    text = re.sub(r"\s+", "", text)
    text = _strip_nested(_PARENS, _strip_nested(_TEMPLATE, text, ""), "()")
    return text.replace("->", ".").replace("::", ".").lstrip(".")


@lru_cache(maxsize=65536)
def _normalized(callee: str) -> tuple[str, str]:
    """A callee normalized, and the last part of that (callees repeat across files)."""
    name = normalize_callee(callee)
    return name, name.rsplit(".", 1)[-1]


def last_name(callee: str) -> str:
    """The last part of a callee as rules see it (``init`` of ``ros::init``), kept."""
    return _normalized(callee)[1]


def member(text: str) -> str:
    """A name as a variable or member is compared: blanks dropped, ``this->`` left out
    (``this->pub_`` and ``pub_`` are one C++ member; ``self.pub`` stays as it is)."""
    name = text.replace(" ", "")
    for prefix in ("this->", "this.", "(*this)."):
        if name.startswith(prefix):
            return name[len(prefix) :]
    return name


def constructed(call: CallSite) -> tuple[str, tuple[str, ...]]:
    """The callee a rule matches and its template arguments: for ``std::make_shared<T>(...)``
    and ``std::make_unique<T>(...)`` the class ``T`` (with ``T``'s own template arguments),
    else the call's own."""
    if call.templates and _normalized(call.callee)[0] in MAKERS:
        made = call.templates[0]
        if "<" in made:
            return without_template_arguments(made), template_arguments(made)
        return made, ()
    return call.callee, call.templates


@lru_cache(maxsize=4096)
def _compiled(pattern: str) -> GitIgnoreSpec:
    """A rule's ``match`` glob, in the one glob dialect (archmetrics.globs): a callee name
    has no ``/``, so ``*`` takes any run of it, dots included."""
    return compile_glob(normalize_callee(pattern))


@lru_cache(maxsize=1 << 16)
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
    prefixes (``zmq`` for ``zmq.asyncio``), its path suffixes (``playerc.h`` for
    ``libplayerc/playerc.h``) and each of its folders with a slash (``rclcpp/`` for
    ``rclcpp/rclcpp.hpp``: any header of that library; ``msg/`` for
    ``geometry_msgs/msg/twist.hpp``: any generated message header)."""
    forms: set[str] = set()
    for dep in dependencies:
        forms.update(_forms_of(dep))
    return frozenset(forms)


@lru_cache(maxsize=1 << 15)
def _forms_of(dep: str) -> tuple[str, ...]:
    """The forms of one dependency (the same headers reach most files of a tree)."""
    parts = dep.split(".")
    pieces = dep.split("/")
    return (
        *(".".join(parts[: i + 1]) for i in range(len(parts))),
        *("/".join(pieces[i:]) for i in range(len(pieces))),
        *(piece + "/" for piece in pieces[:-1]),
    )


def requirement_met(requires: Iterable[str], dependencies: Iterable[str]) -> bool:
    """Whether a file that sees ``dependencies`` satisfies a rule's ``requires`` list."""
    wanted = tuple(requires)
    return not wanted or Requirements(dependencies).met(wanted)


class Requirements:
    """Which ``requires`` lists a file that sees ``dependencies`` meets, each list asked
    once, the dependencies' forms made when first needed."""

    def __init__(self, dependencies: Iterable[str]) -> None:
        self.dependencies = dependencies
        self.answers: dict[tuple[str, ...], bool] = {}
        self._forms: frozenset[str] | None = None

    def met(self, requires: tuple[str, ...]) -> bool:
        if not requires:
            return True
        answer = self.answers.get(requires)
        if answer is None:
            if self._forms is None:
                self._forms = requirement_forms(self.dependencies)
            forms = self._forms
            answer = self.answers[requires] = any(want in forms for want in requires)
        return answer


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
        a name's last part is one a rule's pattern ends in, or a wildcard pattern matches it,
        or it makes an object (``make_shared``, which :func:`constructed` reads as its
        class). One set look-up a callee, where ``choose`` tries each candidate's pattern."""
        if self._wild is None and not self.by_name:
            return False
        by_name, wild, answers = self.by_name, self._wild, self._wild_answers
        for callee in callees:
            name, last = _normalized(callee)
            if last in by_name or name in MAKERS:
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
