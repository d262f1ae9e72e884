"""Endpoints: reading a link site's literal (topic, service, port, library ...) and normalizing it.

Two sites link when their normalized keys are equal. Addresses reduce to their port when they
have one (``tcp://*:5555``, ``tcp://localhost:5555``, ``("", 5555)`` and ``htons(5555)`` are
all ``port:5555``); other addresses keep scheme and path (``address:ipc:///tmp/feed``).
Library names drop ``lib`` and version/extension suffixes (``libfoo.so.1`` -> ``library:foo``).
Names (topic, service, operation ...) are compared as written, under their type.
A non-literal argument that is a plain name is looked up among the constants visible to the
file (``#define PORT "3490"``, ``const int PORT = 3490;``, module-level ``PORT = 3490``).
"""

from __future__ import annotations

import ast
import re
from collections.abc import Callable, Mapping, Sequence
from functools import lru_cache

from archmetrics.facts import Argument, Binding

Value = str | int | float | bool | bytes | tuple[object, ...]
Lookup = Callable[[str], Value | None]

_NAME = re.compile(r"^[A-Za-z_]\w*$")
_NAMED_LITERALS = frozenset({"True", "False", "None"})
_PORT = re.compile(r":(\d{1,5})(?:/.*)?$")
_ICE_PORT = re.compile(r"-p\s+(\d{1,5})\b")
_LIBRARY_SUFFIX = re.compile(r"(\.so(\.\d+)*|\.dll|\.dylib|\.\d+)+$", re.IGNORECASE)


def literal(text: str) -> Value | None:
    """The value of a literal written ``text`` (Python or C spelling), or None. A plain name
    (most arguments) is no literal; a short text's answer is kept (texts repeat, and a
    history reads the same files' arguments at every commit that reaches them)."""
    if len(text) > _KEPT_LITERAL:
        return _literal(text)
    return _kept_literal(text)


_KEPT_LITERAL = 200  # characters of a literal whose value is kept
_CONSTANT_NAMES = frozenset({"True", "False", "None"})


@lru_cache(maxsize=65536)
def _kept_literal(text: str) -> Value | None:
    if _NAME.match(text) and text not in _CONSTANT_NAMES:
        return None
    return _literal(text)


def _literal(text: str) -> Value | None:
    text = text.strip()
    first = text[:1]
    if (
        (first.isalpha() or first == "_")
        and text not in _NAMED_LITERALS
        and not (
            "'" in text or '"' in text  # b'x', r"x": a prefixed string literal
        )
    ):
        return None  # a name, a call, a member: no literal (and no parse to learn it)
    if text.startswith("(") and text.endswith(")") and text.count(",") == 0:
        text = text[1:-1].strip()  # C's (3490) and Python's ("x")
    try:
        value = ast.literal_eval(text)
    except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
        return None
    return value if isinstance(value, str | int | float | bool | bytes | tuple) else None


def constants_of(bindings: Sequence[Binding]) -> dict[str, Value]:
    """File-level constants with literal values: the file's bindings outside functions
    (``#define PORT "3490"``, ``const int PORT = 3490;``, Python's ``PORT = 3490``) whose value
    is a literal, or names another such constant (one level: ``#define PORT DEFAULT_PORT``).
    The first binding of a name wins."""
    table: dict[str, Value] = {}
    aliases: dict[str, str] = {}
    for binding in bindings:
        if binding.function is not None or binding.name in table:
            continue
        value = literal(binding.value)
        if value is not None:
            table[binding.name] = value
        elif _NAME.match(binding.value):
            aliases[binding.name] = binding.value
    for name, other in aliases.items():  # one level of #define PORT DEFAULT_PORT
        if name not in table and other in table:
            table[name] = table[other]
    return table


def chain_lookup(tables: Sequence[Mapping[str, Value]]) -> Lookup:
    """A lookup through ``tables`` in order: the first definition wins."""

    def lookup(name: str) -> Value | None:
        for table in tables:
            if name in table:
                return table[name]
        return None

    return lookup


def argument_value(argument: Argument, lookup: Lookup) -> tuple[Value | None, str]:
    """An argument's value and how it was read (``argument`` or ``constant``)."""
    if argument.is_literal and argument.value is not None:
        return argument.value, "argument"
    value = literal(argument.text)
    if value is not None:
        return value, "argument"
    name = argument.text.strip()
    if _NAME.match(name) and (found := lookup(name)) is not None:
        return found, "constant"
    if (pair := tuple_with_names(name, lookup)) is not None:
        return pair, "constant"
    return None, "argument"


def tuple_with_names(text: str, lookup: Lookup) -> tuple[object, ...] | None:
    """A Python tuple of literals and constant names, ``("", PORT)``, with the names looked up."""
    if not text.startswith("("):
        return None
    try:
        tree = ast.parse(text, mode="eval").body
    except (SyntaxError, ValueError, MemoryError, RecursionError):
        return None
    if not isinstance(tree, ast.Tuple):
        return None
    items: list[object] = []
    for node in tree.elts:
        if isinstance(node, ast.Constant):
            items.append(node.value)
        elif isinstance(node, ast.Name) and (value := lookup(node.id)) is not None:
            items.append(value)
        else:
            return None
    return tuple(items)


def _port(value: Value) -> int | None:
    if isinstance(value, bool):
        return None
    if isinstance(value, int):
        return value if 0 <= value < 65536 else None
    if isinstance(value, str) and value.strip().isascii() and value.strip().isdigit():
        return _port(int(value.strip()))
    if isinstance(value, tuple) and len(value) >= 2 and isinstance(value[1], int | str):
        return _port(value[1])
    return None


def _address(value: Value) -> str | None:
    if (port := _port(value)) is not None:
        return f"port:{port}"
    if not isinstance(value, str) or not value.strip():
        return None
    text = value.strip()
    match = _PORT.search(text)
    if match and (port := _port(match.group(1))) is not None:
        return f"port:{port}"
    scheme, sep, rest = text.partition("://")
    return f"address:{scheme.lower()}{sep}{rest}" if sep else f"address:{text}"


def _library(value: Value) -> str | None:
    if not isinstance(value, str) or not value.strip():
        return None
    name = value.strip().replace("\\", "/").rsplit("/", 1)[-1]
    name = _LIBRARY_SUFFIX.sub("", name)
    name = name[3:] if name.startswith("lib") and len(name) > 3 else name
    return f"library:{name}" if name else None


def _ice(value: Value) -> str | None:
    if not isinstance(value, str) or not value.strip():
        return None
    if match := _ICE_PORT.search(value):
        return f"port:{int(match.group(1))}"
    identity = re.split(r"[:@]", value.strip(), maxsplit=1)[0].strip()
    return f"ice:{identity}" if identity else None


def normalize(kind: str, value: Value) -> str | None:
    """The key two matching endpoints share; None when ``value`` is not usable as ``kind``."""
    if kind == "address":
        return _address(value)
    if kind == "port":
        port = _port(value)
        return f"port:{port}" if port is not None else _address(value)
    if kind == "library":
        return _library(value)
    if kind == "ice":
        return _ice(value)
    if isinstance(value, bytes):
        value = value.decode("utf-8", "replace")
    if not isinstance(value, str | int) or isinstance(value, bool) or not str(value).strip():
        return None
    text = str(value).strip()
    return f"{kind}:{text.lower() if kind == 'interface' else text}"
