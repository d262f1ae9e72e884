"""Descriptor data types as Python source: annotations, wire conversions, default literals."""

from __future__ import annotations

from robosoa.descriptor import Operation, Parameter, TypeRef, names
from robosoa.descriptor.checks import default_value

_PRIMITIVE = {"int": "int", "float": "float", "bool": "bool", "string": "str", "bytes": "bytes"}


def q(value: object) -> str:
    """A Python literal of ``value``: always ``repr``, so any string is escaped correctly.

    A string ``repr`` puts in single quotes that holds no quote character at all is given
    double quotes instead (as ruff format writes it); nothing inside changes.
    """
    literal = repr(value)
    if isinstance(value, str) and literal[0] == "'" and '"' not in value:
        return f'"{literal[1:-1]}"'
    return literal


def literal_lines(head: str, value: str, tail: str = "") -> list[str]:
    """``head + q(value) + tail`` on one line, or the string split into implicitly joined pieces.

    Descriptors carry strings of any length (command lines, library paths); the pieces keep every
    generated line within 99 columns however long the string is.
    """
    line = f"{head}{q(value)}{tail}"
    if len(line) <= 99:
        return [line]
    indent = " " * (len(head) - len(head.lstrip()) + 4)
    room = 99 - len(indent)
    pieces: list[str] = []
    piece = ""
    for char in value:
        if piece and len(q(piece + char)) > room:
            pieces.append(piece)
            piece = ""
        piece += char
    pieces.append(piece)
    return [f"{head}(", *(f"{indent}{q(p)}" for p in pieces), f"{indent[:-4]}){tail}"]


def result_class(op: Operation) -> str:
    """Name of the generated dataclass holding the return values of ``op``."""
    return names.result_class(op.name)


def message_class(op: Operation) -> str:
    """Name of the generated dataclass holding the parameters of a topic or event ``op``."""
    return names.message_class(op.name)


def annotation(t: TypeRef) -> str:
    """The Python annotation of ``t``: ``int``, ``Row``, ``tuple[Row, ...]``."""
    if t.item is not None:
        return f"tuple[{annotation(t.item)}, ...]"
    return _PRIMITIVE.get(t.name, t.name)


def value_annotation(p: Parameter) -> str:
    """Annotation of a parameter or field, ``| None`` when optional without default."""
    base = annotation(p.type)
    return f"{base} | None" if not p.required and p.default is None else base


def default_literal(p: Parameter) -> str | None:
    """Python literal of the default (``10``, ``'x'``, ``None``), or None when required."""
    if p.required:
        return None
    if p.default is None:
        return "None"
    return q(default_value(p.type, p.default))


def from_wire(t: TypeRef, expr: str, depth: int = 0) -> str:
    """Expression converting wire value ``expr`` (JSON-like) into the typed value of ``t``."""
    if t.item is not None:
        var = f"v{depth}"
        return f"tuple({from_wire(t.item, var, depth + 1)} for {var} in {expr})"
    if t.name in _PRIMITIVE:
        return f"{_PRIMITIVE[t.name]}({expr})"
    return f"{t.name}.from_payload({expr})"


def field_from(p: Parameter, source: str = "data") -> str:
    """Expression reading field ``p`` out of mapping ``source``, honouring optional/default."""
    key = q(p.name)
    if p.required:
        return from_wire(p.type, f"{source}[{key}]")
    fallback = default_literal(p)
    return f"{fallback} if {source}.get({key}) is None else {from_wire(p.type, f'{source}[{key}]')}"


def signature(params: tuple[Parameter, ...], first: str = "") -> list[str]:
    """Parameter declarations ``name: T`` / ``name: T = default``, required ones first."""
    out = [first] if first else []
    ordered = [p for p in params if p.required] + [p for p in params if not p.required]
    for p in ordered:
        default = default_literal(p)
        suffix = f" = {default}" if default is not None else ""
        out.append(f"{p.name}: {value_annotation(p)}{suffix}")
    return out


def def_line(indent: str, name: str, args: list[str], returns: str) -> list[str]:
    """A ``def`` line, wrapped one argument per line when it would pass 99 columns."""
    line = f"{indent}def {name}({', '.join(args)}) -> {returns}:"
    if len(line) <= 99:
        return [line]
    return [
        f"{indent}def {name}(",
        *(f"{indent}    {a}," for a in args),
        f"{indent}) -> {returns}:",
    ]


def call(indent: str, head: str, args: list[str], tail: str = ")") -> list[str]:
    """``head(arg, ...)`` on one line, or wrapped one argument per line past 99 columns."""
    line = f"{indent}{head}({', '.join(args)}{tail}"
    if len(line) <= 99:
        return [line]
    return [f"{indent}{head}(", *(f"{indent}    {a}," for a in args), f"{indent}{tail}"]


def keyword_lines(indent: str, p: Parameter, source: str) -> list[str]:
    """``name=<conversion>,`` reading ``p`` from ``source``; split over lines past 99 columns."""
    line = f"{indent}{p.name}={field_from(p, source)},"
    if len(line) <= 99 or p.required:
        return [line]
    key = q(p.name)
    return [
        f"{indent}{p.name}=(",
        f"{indent}    {default_literal(p)}",
        f"{indent}    if {source}.get({key}) is None",
        f"{indent}    else {from_wire(p.type, f'{source}[{key}]')}",
        f"{indent}),",
    ]
