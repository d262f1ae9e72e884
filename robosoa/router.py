"""Content-based router (Hestand 2011, p. 133): declarative rules remap messages by content.

The thesis found the Pragmatics component's hand-written message mapping to be the costly
part of SOA integration, and that an ESB component remapping messages by content would
carry that cost once. This is that component: rules are data (dicts, or a TOML/JSON file),
validated when loaded; the router is itself a service (and/or topic subscriber) on the bus.

Rule keys: ``name``; match keys ``operation`` (or "*"), ``topic`` (match a topic instead of
calls to the router service), ``when`` (an expression, see ``robosoa.expr``); ``stop``
(no later rule is tried); ``to``: a list of outputs with ``kind`` (request, send, publish,
emit), ``service``/``operation`` or ``topic``, and the payload transform: ``copy`` (start
from the incoming fields), ``rename`` {old: new}, ``drop`` [names], ``fields`` {name:
expression string, or any non-string JSON value as a constant}.
"""

from __future__ import annotations

import json
import logging
import tomllib
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from types import TracebackType
from typing import Any

from robosoa.bus import Bus
from robosoa.errors import InvalidMessage, RobosoaError
from robosoa.expr import ExprError, Expression
from robosoa.message import Message
from robosoa.provider import ERROR_EVENT, ProviderHandle
from robosoa.subscription import Subscription

KINDS = ("request", "send", "publish", "emit")
_RULE_KEYS = {"name", "operation", "topic", "when", "stop", "to"}
_OUT_KEYS = {"kind", "service", "operation", "topic", "copy", "rename", "drop", "fields"}


class RuleError(ValueError):
    """A rule file or rule dict is invalid; the message names the source and the key."""


@dataclass(frozen=True, slots=True)
class Output:
    """One outgoing message template."""

    kind: str
    service: str
    operation: str
    topic: str
    copy: bool
    rename: tuple[tuple[str, str], ...]
    drop: tuple[str, ...]
    fields: tuple[tuple[str, Expression | Any], ...]


@dataclass(frozen=True, slots=True)
class Rule:
    """A match condition and the outputs it produces."""

    name: str
    operation: str
    topic: str
    when: Expression | None
    stop: bool
    outputs: tuple[Output, ...]


@dataclass(frozen=True, slots=True)
class Outgoing:
    """A concrete message the router must send."""

    rule: str
    kind: str
    service: str
    operation: str
    topic: str
    payload: dict[str, Any]


def _expect(value: Any, kind: type | tuple[type, ...], where: str) -> Any:
    if not isinstance(value, kind):
        names = kind.__name__ if isinstance(kind, type) else "/".join(k.__name__ for k in kind)
        raise RuleError(f"{where}: expected {names}, got {type(value).__name__}")
    return value


def _output(data: Any, where: str) -> Output:
    _expect(data, dict, where)
    unknown = set(data) - _OUT_KEYS
    if unknown:
        raise RuleError(f"{where}: unknown key {sorted(unknown)[0]!r}")
    kind = data.get("kind", "request")
    if kind not in KINDS:
        raise RuleError(f"{where}.kind: {kind!r} is not one of {', '.join(KINDS)}")
    target = ("topic",) if kind in ("publish", "emit") else ("service", "operation")
    for key in target:
        if not isinstance(data.get(key), str) or not data[key]:
            raise RuleError(f"{where}.{key}: required for kind {kind!r}")
    fields: list[tuple[str, Expression | Any]] = []
    for key, value in _expect(data.get("fields", {}), dict, f"{where}.fields").items():
        try:
            fields.append((key, Expression(value) if isinstance(value, str) else value))
        except ExprError as exc:
            raise RuleError(f"{where}.fields.{key}: {exc}") from None
    rename = _expect(data.get("rename", {}), dict, f"{where}.rename")
    return Output(kind, data.get("service", ""), data.get("operation", ""),
                  data.get("topic", ""), bool(data.get("copy", False)),
                  tuple((str(k), str(v)) for k, v in rename.items()),
                  tuple(str(d) for d in _expect(data.get("drop", []), list, f"{where}.drop")),
                  tuple(fields))


def parse_rule(data: Any, where: str) -> Rule:
    """Validate one rule dict; RuleError names ``where`` and the bad key."""
    _expect(data, dict, where)
    unknown = set(data) - _RULE_KEYS
    if unknown:
        raise RuleError(f"{where}: unknown key {sorted(unknown)[0]!r}")
    outputs = _expect(data.get("to"), list, f"{where}.to")
    when = data.get("when")
    try:
        condition = None if when is None else Expression(_expect(when, str, f"{where}.when"))
    except ExprError as exc:
        raise RuleError(f"{where}.when: {exc}") from None
    return Rule(str(data.get("name", where)), str(data.get("operation", "*")),
                str(data.get("topic", "")), condition, bool(data.get("stop", False)),
                tuple(_output(o, f"{where}.to[{i}]") for i, o in enumerate(outputs)))


def _transform(out: Output, payload: Mapping[str, Any], scope: Mapping[str, Any]) -> dict[str, Any]:
    result = dict(payload) if out.copy else {}
    for old, new in out.rename:
        if old in payload:
            result.pop(old, None)
            result[new] = payload[old]
    for name in out.drop:
        result.pop(name, None)
    for name, value in out.fields:
        result[name] = value.evaluate(scope) if isinstance(value, Expression) else value
    return result


class Router:
    """A set of rules; ``route`` is pure, ``attach`` puts the router on a bus."""

    def __init__(self, rules: Sequence[Rule]) -> None:
        self.rules = tuple(rules)

    @staticmethod
    def from_data(data: Any, source: str = "rules") -> Router:
        """Rules from ``{"rules": [...]}`` or a plain list; RuleError names the bad key."""
        items = data.get("rules", data.get("rule")) if isinstance(data, dict) else data
        if not isinstance(items, list):
            raise RuleError(f"{source}: expected a list of rules under 'rules'")
        return Router([parse_rule(r, f"{source}: rules[{i}]") for i, r in enumerate(items)])

    @staticmethod
    def from_file(path: str | Path) -> Router:
        """Rules from a ``.toml`` (``[[rules]]`` tables) or ``.json`` file."""
        path = Path(path)
        try:
            text = path.read_text(encoding="utf-8")
            data = tomllib.loads(text) if path.suffix == ".toml" else json.loads(text)
        except (OSError, ValueError) as exc:
            raise RuleError(f"{path}: {exc}") from None
        return Router.from_data(data, str(path))

    @property
    def topics(self) -> tuple[str, ...]:
        """Topics the router listens to."""
        return tuple(sorted({r.topic for r in self.rules if r.topic}))

    def route(self, operation: str, topic: str, payload: Mapping[str, Any],
              service: str = "") -> list[Outgoing]:
        """The outgoing messages for one incoming message (empty when no rule matches)."""
        scope = {**payload, "_service": service, "_operation": operation, "_topic": topic}
        found: list[Outgoing] = []
        for rule in self.rules:
            if rule.topic != topic or (not topic and rule.operation not in ("*", operation)):
                continue
            try:
                if rule.when is not None and not rule.when.evaluate(scope):
                    continue
            except ExprError:
                continue  # a field the condition needs is absent: the rule does not apply
            for out in rule.outputs:
                try:
                    body = _transform(out, payload, scope)
                except ExprError as exc:
                    raise RuleError(f"rule {rule.name!r}: {exc}") from None
                found.append(Outgoing(rule.name, out.kind, out.service, out.operation,
                                      out.topic, body))
            if rule.stop:
                break
        return found

    def attach(self, bus: Bus, service: str = "router", version: str = "1.0.0") -> RouterHandle:
        """Serve this router on ``bus`` under the service name ``service``: a service for
        calls, a subscriber for topics."""
        return RouterHandle(self, bus, service, version)


log = logging.getLogger("robosoa.router")


class RouterHandle:
    """A running router; ``close`` stops its service and subscriptions."""

    def __init__(self, router: Router, bus: Bus, service: str, version: str) -> None:
        self.router = router
        self.bus = bus
        self.service = service
        self.handle: ProviderHandle | None = None
        self.subscriptions: list[Subscription] = []
        operations = {r.operation for r in router.rules if not r.topic}
        if operations:
            ops = () if "*" in operations else tuple(sorted(operations))
            self.handle = bus.provide(service, self._on_call, version=version, operations=ops)
        for topic in router.topics:
            self.subscriptions.append(bus.subscribe(topic, self._on_topic))

    def _deliver(self, out: Outgoing) -> dict[str, Any]:
        done: dict[str, Any] = {"rule": out.rule, "kind": out.kind}
        if out.kind == "request":
            done["to"] = f"{out.service}.{out.operation}"
            done["reply"] = self.bus.request(out.service, out.operation, out.payload)
        elif out.kind == "send":
            done["to"] = f"{out.service}.{out.operation}"
            done["delivered"] = self.bus.send(out.service, out.operation, out.payload)
        elif out.kind == "publish":
            done["to"] = out.topic
            self.bus.publish(out.topic, out.payload)
        else:
            done["to"] = out.topic
            self.bus.emit(out.topic, out.payload)
        return done

    def _on_call(self, msg: Message) -> dict[str, Any]:
        try:
            outs = self.router.route(msg.operation, "", msg.payload, msg.service)
        except RuleError as exc:
            raise InvalidMessage(str(exc)) from None
        if not outs:
            raise InvalidMessage(f"no rule of router {self.service!r} matches "
                                 f"operation {msg.operation!r} with this payload")
        return {"routed": [self._deliver(out) for out in outs]}

    def _on_topic(self, msg: Message) -> None:
        try:
            for out in self.router.route("", msg.topic, msg.payload):
                self._deliver(out)
        except (RobosoaError, RuleError) as exc:
            log.warning("routing failed", extra={"topic": msg.topic, "error": str(exc)})
            self.bus.emit(ERROR_EVENT, {"service": self.service, "operation": "",
                                        "instance": "", "reason": str(exc)})

    def close(self) -> None:
        """Stop serving and listening."""
        if self.handle is not None:
            self.handle.close()
        for sub in self.subscriptions:
            sub.close()

    def __enter__(self) -> RouterHandle:
        return self

    def __exit__(self, exc_type: type[BaseException] | None, exc: BaseException | None,
                 tb: TracebackType | None) -> None:
        self.close()
