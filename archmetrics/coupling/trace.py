"""Reading an argument's value statically: literal, constant, local variable or caller's argument.

An endpoint is often not written at the call: ``getaddrinfo(host, port, ...)`` inside
``listen_on(const char *port)``, called from ``main`` as ``listen_on(port)`` after
``const char *port = getenv("WDB_PORT") ? getenv("WDB_PORT") : PORT;``. The tracer follows
such a name a few steps within one file: a constant visible to the file; else the values the
variable is given in its function (assignments before the site whose right-hand side is a
literal or mentions exactly one constant -- run-time overrides such as ``optarg`` are
ignored); else, when it is a parameter, the agreeing values of that argument at the file's
calls of the function. Anything else stays unknown.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from archmetrics.coupling.endpoints import Lookup, Value, argument_value, literal, tuple_with_names
from archmetrics.coupling.matching import member
from archmetrics.facts import Argument, CallSite, FileFacts, Language, Span

if TYPE_CHECKING:
    from archmetrics.coupling.rules import ValueRule
    from archmetrics.coupling.values import ValueCalls

ArgumentReader = Callable[[Argument, str | None, int], tuple[Value | None, str]]
"""(argument, enclosing function, line) -> (value or None, how it was read)."""

_NAME = re.compile(r"^[A-Za-z_]\w*$")
_MEMBER = re.compile(r"^(?:self\.|this->|this\.)?[A-Za-z_]\w*$")  # x, self.x, this->x
_IDENTIFIER = re.compile(r"[A-Za-z_]\w*")
_STRING = re.compile(r"\"(?:\\.|[^\"\\])*\"|'(?:\\.|[^'\\])*'")
_SELF = frozenset({"self", "cls"})
_STRINGS = frozenset({"std::string", "string", "std::string_view"})  # a member's declared type
DEPTH = 3


def plain_reader(lookup: Lookup) -> ArgumentReader:
    """A reader that knows literals and constants only."""

    def read(argument: Argument, function: str | None, line: int) -> tuple[Value | None, str]:
        return argument_value(argument, lookup)

    return read


class _Ambiguous(Exception):
    """A name given several different values: the site has no single endpoint."""

    def __init__(self, values: set[Value]) -> None:
        super().__init__("several values: " + ", ".join(sorted(map(repr, values))))


AMBIGUOUS = "ambiguous"


@dataclass(frozen=True, slots=True)
class _Signature:
    name: str
    parameters: tuple[str, ...]


class Tracer:
    """Follows names through one file's statements and calls (see the module docstring)."""

    def __init__(
        self,
        facts: FileFacts,
        lookup: Lookup,
        modules: frozenset[str] = frozenset(),
        values: ValueCalls | None = None,
    ) -> None:
        self.facts = facts
        self.lookup = lookup
        self.modules = modules  # names bound to modules: ``su.SERVICE`` reads SERVICE
        self.values = values  # calls a pack's [[values]] know (values.py)
        self._signatures: dict[str, _Signature] | None = None
        self.parameter = ""  # the parameter whose default the last read value came from

    @property
    def signatures(self) -> dict[str, _Signature]:
        """Parameter names of the file's functions (a Python method's ``self`` or ``cls``
        left out: a call passes it before the parentheses)."""
        if self._signatures is None:
            python = self.facts.language == Language.PYTHON
            self._signatures = {}
            for f in self.facts.functions:
                names = f.parameters
                if python and names and names[0] in _SELF:
                    names = names[1:]
                called = f.name
                if python and called == "__init__":  # called as its class: Talker("x")
                    called = (_class_of(f.qualified_name) or called).rsplit(".", 1)[-1]
                self._signatures[f.qualified_name] = _Signature(called, names)
        return self._signatures

    def read(self, argument: Argument, function: str | None, line: int) -> tuple[Value | None, str]:
        """The argument's value and how it was read (``argument``, ``constant``, ``traced``).

        A name given several different values reads as ``(None, "ambiguous: several ...")``.
        """
        value, via = argument_value(argument, self.lookup)
        if value is not None:
            return value, via
        module, _, name = argument.text.replace(" ", "").rpartition(".")
        if module in self.modules and (value := self.lookup(name)) is not None:
            return value, "constant"
        text = argument.text.strip()
        self.parameter = ""
        try:
            traced = self._wrapped(text, function, line, DEPTH)
            if traced is None:
                traced = self._name(text, function, line, DEPTH)
            if traced is None and "+" in text:  # "~/" + planner_namespace
                traced = self._sum(text, function, line)
            if traced is None and text.startswith("("):  # ("", port)
                traced = tuple_with_names(text, lambda name: self._value(name, function, line))
        except _Ambiguous as several:
            return None, f"{AMBIGUOUS}: {several}"
        if traced is None:
            return None, via
        return traced, f"parameter:{self.parameter}" if self.parameter else "traced"

    def _sum(self, text: str, function: str | None, line: int) -> Value | None:
        """A concatenation of strings each known: ``"~/" + planner_namespace``. Literals are
        read first, and a part that is neither a literal, a name nor a known wrapper
        (``get_name()``) ends the reading before any name is traced."""
        parts = _plus_parts(text)
        if len(parts) < 2:
            return None
        values: list[Value | None] = [literal(part) for part in parts]
        for part, value in zip(parts, values, strict=True):
            if value is not None and not isinstance(value, str):
                return None
            wraps = self.values is not None and self.values.wrapped(part) is not None
            if value is None and not _MEMBER.match(part) and not wraps:
                return None
        joined: list[str] = []
        for part, value in zip(parts, values, strict=True):
            if value is None:
                value = self._wrapped(part, function, line, DEPTH)
            if value is None:
                value = self._value(part, function, line)
            if not isinstance(value, str):
                return None
            joined.append(value)
        return "".join(joined) or None

    def _value(self, name: str, function: str | None, line: int) -> Value | None:
        found = self.lookup(name)
        return found if found is not None else self._name(name, function, line, DEPTH)

    def _name(self, name: str, function: str | None, line: int, depth: int) -> Value | None:
        name = name.replace(" ", "")
        if depth <= 0 or function is None or not _MEMBER.match(name):
            return None
        values = self._assigned(name, function, line, depth)
        values |= self._given(name, function, line, depth)
        if len(values) > 1:
            raise _Ambiguous(values)
        if values:
            return values.pop()
        signature = self.signatures.get(function)
        if signature is not None and name in signature.parameters:
            return self._from_callers(signature, signature.parameters.index(name), depth - 1)
        return self._member(name, function, depth)

    def _member(self, name: str, function: str, depth: int) -> Value | None:
        """A member given its value in another function of the class (its constructor,
        say): the values every function of the class gives it, when they agree."""
        owner = _class_of(function)
        if owner is None or (not _NAME.match(name) and "." not in name and ">" not in name):
            return None
        values: set[Value] = set()
        for other in {f.qualified_name for f in self.facts.functions}:
            if other != function and _class_of(other) == owner:
                values |= self._assigned(name, other, 1 << 30, depth - 1)
                values |= self._given(name, other, 1 << 30, depth - 1)
                values |= self._initialized(name, other, depth - 1)
        if len(values) > 1:
            raise _Ambiguous(values)
        return values.pop() if values else None

    def _initialized(self, name: str, function: str, depth: int) -> set[Value]:
        """The value a constructor's member initializer gives ``name`` (``topic_("chatter")``
        or ``topic_(topic)``, a call site of the member or of its declared type)."""
        wanted = member(name)
        found: set[Value] = set()
        owner = _class_of(function)
        if owner is None or function.rsplit("::", 1)[-1] != owner.rsplit("::", 1)[-1]:
            return found  # not a C++ constructor
        for call in self.facts.call_sites:
            if call.function != function or len(call.arguments) != 1:
                continue
            if call.callee == wanted or (call.target == wanted and call.callee in _STRINGS):
                argument = call.arguments[0]
                value, _ = argument_value(argument, self.lookup)
                if value is None:
                    value = self._name(argument.text.strip(), function, call.span.start, depth)
                if value is not None:
                    found.add(value)
        return found

    def _given(self, name: str, function: str, line: int, depth: int) -> set[Value]:
        """The values calls a value rule knows give ``name`` in ``function`` up to ``line``
        (``topic_ = declare_parameter("topic", "x")``, ``get_parameter("topic", topic_)``)."""
        found: set[Value] = set()
        if self.values is None:
            return found
        for call, rule in self.values.giving(name):
            if call.function == function and call.span.start <= line:
                value = self._of_call(call, rule, depth - 1)
                if value is not None:
                    found.add(value)
        return found

    def _of_call(self, call: CallSite, rule: ValueRule, depth: int) -> Value | None:
        """The value a value rule's call gives: its ``value`` argument, or the default the
        file declares for the parameter it names."""
        from archmetrics.coupling.values import pick

        if rule.value is not None:
            if rule.value.value is not None:
                return rule.value.value
            argument = pick(call.arguments, rule.value)
            value = None if argument is None else self._argument(argument, call, depth)
            named = pick(call.arguments, rule.name) if rule.name is not None else None
            if value is not None and named is not None and isinstance(named.value, str):
                self.parameter = named.value  # a parameter's default: a file may set it
            return value
        named = pick(call.arguments, rule.name) if rule.name is not None else None
        if named is None or not isinstance(named.value, str) or self.values is None:
            return None
        defaults = {
            value
            for other, declaring in self.values.declared(named.value)
            if (value := self._of_call(other, declaring, depth - 1)) is not None
        }
        if len(defaults) > 1:
            raise _Ambiguous(defaults)
        if defaults:
            self.parameter = named.value
        return defaults.pop() if defaults else None

    def _argument(self, argument: Argument, call: CallSite, depth: int) -> Value | None:
        value, _ = argument_value(argument, self.lookup)
        if value is not None:
            return value
        text = argument.text.strip()
        wrapped = self._wrapped(text, call.function, call.span.start, depth)
        if wrapped is not None:
            return wrapped
        return self._name(text, call.function, call.span.start, depth)

    def _wrapped(self, text: str, function: str | None, line: int, depth: int) -> Value | None:
        """An argument written as a call a value rule knows: ``rclcpp::ParameterValue("x")``."""
        if self.values is None or depth <= 0 or ("(" not in text and "{" not in text):
            return None
        found = self.values.wrapped(text)
        if found is None:
            return None
        rule, arguments = found
        call = CallSite(text, text, None, _span(line), arguments, function)
        return self._of_call(call, rule, depth - 1)

    def _assigned(self, name: str, function: str, line: int, depth: int) -> set[Value]:
        """The values ``name`` is given in ``function`` up to ``line`` (its bindings)."""
        values: set[Value] = set()
        wanted = member(name)
        for binding in self.facts.bindings:
            if binding.function != function or binding.line > line:
                continue
            if binding.name != name and member(binding.name) != wanted:
                continue
            parts = _split_top_level(binding.value)  # Python's port = 6665, 6666
            rhs = parts[0].strip() if parts else ""
            if value := self._expression(rhs, function, line, depth):
                values.add(value)
        return values

    def _expression(self, text: str, function: str, line: int, depth: int) -> Value | None:
        value = literal(text)
        if value is not None:
            return value
        if _NAME.match(text):
            found = self.lookup(text)
            return found if found is not None else self._name(text, function, line, depth - 1)
        names = set(_IDENTIFIER.findall(_STRING.sub(" ", text)))
        constants = {value for n in names if (value := self.lookup(n)) is not None}
        return constants.pop() if len(constants) == 1 else None

    def _from_callers(self, signature: _Signature, index: int, depth: int) -> Value | None:
        values: set[Value] = set()
        for call in self.facts.call_sites:
            if _called(call) != signature.name:
                continue
            positional = [a for a in call.arguments if a.keyword is None]
            if index >= len(positional):
                return None
            argument = positional[index]
            value, _ = argument_value(argument, self.lookup)
            if value is None:
                value = self._name(argument.text.strip(), call.function, call.span.start, depth)
            if value is None:
                return None
            values.add(value)
        if len(values) > 1:
            raise _Ambiguous(values)
        return values.pop() if values else None


_MAKERS = frozenset({"make_shared", "make_unique"})


def _called(call: CallSite) -> str:
    """The name a call calls: a class's for ``std::make_shared<Producer>(...)`` (its
    constructor's arguments), else the callee's last part."""
    if call.name in _MAKERS and call.templates:
        made = call.templates[0].split("<", 1)[0]
        return made.rsplit("::", 1)[-1].rsplit(".", 1)[-1]
    return call.name


def _class_of(function: str) -> str | None:
    """The class a method belongs to, by its qualified name (``ns::Talker::on_timer``,
    ``Talker.__init__``); None for a free function."""
    for separator in ("::", "."):
        if separator in function:
            return function.rsplit(separator, 1)[0]
    return None


def _span(line: int) -> Span:
    return Span(max(1, line), max(1, line))


def _split_top_level(text: str) -> list[str]:
    parts: list[str] = []
    current: list[str] = []
    depth = 0
    for char in text:
        depth += (char in "([{<") - (char in ")]}>")
        if char == "," and depth == 0:
            parts.append("".join(current))
            current = []
        else:
            current.append(char)
    parts.append("".join(current))
    return [p for p in parts if p.strip()]


def _plus_parts(text: str) -> list[str]:
    """``text`` split at the ``+`` outside brackets and string literals, parts stripped."""
    parts, start, depth, at = [], 0, 0, 0
    while at < len(text):
        char = text[at]
        if char in "\"'":
            string = _STRING.match(text, at)
            at = string.end() if string else len(text)
            continue
        depth += (char in "([{") - (char in ")]}")
        if char == "+" and depth == 0:
            parts.append(text[start:at].strip())
            start = at + 1
        at += 1
    parts.append(text[start:].strip())
    return parts
