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

from archmetrics.coupling.endpoints import Lookup, Value, argument_value, literal, tuple_with_names
from archmetrics.facts import Argument, FileFacts, Language

ArgumentReader = Callable[[Argument, str | None, int], tuple[Value | None, str]]
"""(argument, enclosing function, line) -> (value or None, how it was read)."""

_NAME = re.compile(r"^[A-Za-z_]\w*$")
_IDENTIFIER = re.compile(r"[A-Za-z_]\w*")
_STRING = re.compile(r"\"(?:\\.|[^\"\\])*\"|'(?:\\.|[^'\\])*'")
_SELF = frozenset({"self", "cls"})
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
        self, facts: FileFacts, lookup: Lookup, modules: frozenset[str] = frozenset()
    ) -> None:
        self.facts = facts
        self.lookup = lookup
        self.modules = modules  # names bound to modules: ``su.SERVICE`` reads SERVICE
        self._signatures: dict[str, _Signature] | None = None

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
                self._signatures[f.qualified_name] = _Signature(f.name, names)
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
        try:
            traced = self._name(text, function, line, DEPTH)
            if traced is None and text.startswith("("):  # ("", port)
                traced = tuple_with_names(text, lambda name: self._value(name, function, line))
        except _Ambiguous as several:
            return None, f"{AMBIGUOUS}: {several}"
        return (traced, "traced") if traced is not None else (None, via)

    def _value(self, name: str, function: str | None, line: int) -> Value | None:
        found = self.lookup(name)
        return found if found is not None else self._name(name, function, line, DEPTH)

    def _name(self, name: str, function: str | None, line: int, depth: int) -> Value | None:
        if depth <= 0 or function is None or not _NAME.match(name):
            return None
        values = self._assigned(name, function, line, depth)
        if len(values) > 1:
            raise _Ambiguous(values)
        if values:
            return values.pop()
        signature = self.signatures.get(function)
        if signature is None or name not in signature.parameters:
            return None
        return self._from_callers(signature, signature.parameters.index(name), depth - 1)

    def _assigned(self, name: str, function: str, line: int, depth: int) -> set[Value]:
        """The values ``name`` is given in ``function`` up to ``line`` (its bindings)."""
        values: set[Value] = set()
        for binding in self.facts.bindings:
            if binding.name != name or binding.function != function or binding.line > line:
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
            if call.name != signature.name:
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
