"""Semantic checks a schema cannot express; each finding names file, line and field.

Pure: takes a :class:`ServiceDescriptor`, returns problems, never raises or reads files.
"""

from __future__ import annotations

import math
import shlex
from collections.abc import Iterator, Sequence

from .errors import Problem
from .model import (
    Actor,
    ImplementationForm,
    Language,
    Operation,
    Packaging,
    Parameter,
    Participant,
    Pattern,
    StreamQos,
    TypeRef,
)
from .names import name_problems
from .service import ServiceDescriptor

MAX_TIMEOUT = 86_400  # seconds a provider program may be given (one day)
_PUBSUB_FORMS = (Packaging.PROVIDER_LIBRARY, Packaging.CONSUMER_SOURCE)
_FORMS = {
    Packaging.PROVIDER_EXECUTABLE: (ImplementationForm.EXECUTABLE,),
    Packaging.PROVIDER_LIBRARY: (ImplementationForm.LIBRARY,),
    Packaging.CONSUMER_SOURCE: (ImplementationForm.SOURCE,),
    Packaging.CONSUMER_NO_SOURCE: (ImplementationForm.LIBRARY,),
}


def check(d: ServiceDescriptor) -> list[Problem]:
    """All semantic problems of ``d``, in document order."""
    found = [
        *name_problems(d),
        *_duplicates(d),
        *_types(d),
        *_defaults(d),
        *_pattern(d),
        *(p for part in d.participants for p in _participant(d, part)),
    ]
    return sorted(dict.fromkeys(found), key=lambda p: p.line)


def _members(d: ServiceDescriptor) -> Iterator[tuple[str, Parameter]]:
    """Every typed value with the field label of its owner."""
    for t in d.types:
        for f in t.fields:
            yield f"type '{t.name}' field '{f.name}'", f
    for op in d.operations:
        for p in op.parameters:
            yield f"operation '{op.name}' parameter '{p.name}'", p
        for r in op.returns:
            yield f"operation '{op.name}' return '{r.name}'", r


def _dupes(source: str, label: str, items: Sequence[tuple[str, int]]) -> Iterator[Problem]:
    seen: dict[str, int] = {}
    for name, line in items:
        if name in seen:
            yield Problem(
                source, line, f"{label} '{name}'", f"duplicate (first at line {seen[name]})"
            )
        else:
            seen[name] = line


def _duplicates(d: ServiceDescriptor) -> Iterator[Problem]:
    yield from _dupes(d.source, "operation", [(op.name, op.line) for op in d.operations])
    yield from _dupes(d.source, "type", [(t.name, t.line) for t in d.types])
    for t in d.types:
        yield from _dupes(d.source, f"type '{t.name}' field", [(f.name, f.line) for f in t.fields])
    for op in d.operations:
        values = [(p.name, p.line) for p in (*op.parameters, *op.returns)]
        yield from _dupes(d.source, f"operation '{op.name}' parameter or return", values)
    yield from _dupes(
        d.source, "participant", [(p.packaging.value, p.line) for p in d.participants]
    )


def _base(t: TypeRef) -> TypeRef:
    return _base(t.item) if t.item is not None else t


def _types(d: ServiceDescriptor) -> Iterator[Problem]:
    names = {t.name for t in d.types}
    for label, p in _members(d):
        base = _base(p.type)
        if not base.is_primitive and base.name not in names:
            yield Problem(d.source, p.line, label, f"unknown type '{base.name}'")
    for t in d.types:
        if _reaches(d, t.name, t.name, set()):
            yield Problem(d.source, t.line, f"type '{t.name}'", "recursive type")


def _reaches(d: ServiceDescriptor, start: str, target: str, seen: set[str]) -> bool:
    struct = d.type(start)
    if struct is None or start in seen:
        return False
    seen.add(start)
    for f in struct.fields:
        name = _base(f.type).name
        if name == target or _reaches(d, name, target, seen):
            return True
    return False


def default_value(t: TypeRef, text: str) -> int | float | bool | str | None:
    """The Python value of a default literal for primitive ``t``, or None if it does not parse."""
    try:
        if t.name == "int":
            return int(text)
        if t.name == "float":
            value = float(text)
            return value if math.isfinite(value) else None
    except ValueError:
        return None
    if t.name == "bool":
        return {"true": True, "false": False}.get(text)
    return text if t.name == "string" else None


def _defaults(d: ServiceDescriptor) -> Iterator[Problem]:
    for label, p in _members(d):
        if p.default is None:
            continue
        if p.required:
            yield Problem(d.source, p.line, label, "a required value cannot have a default")
        elif not p.type.is_primitive or p.type.name == "bytes":
            yield Problem(d.source, p.line, label, f"type '{p.type}' cannot have a default")
        elif default_value(p.type, p.default) is None:
            yield Problem(d.source, p.line, label, f"default '{p.default}' is not a valid {p.type}")


def _pattern(d: ServiceDescriptor) -> Iterator[Problem]:
    if d.delivery != "one" and d.pattern is not Pattern.ONE_WAY:
        yield Problem(d.source, d.line, "pattern", "delivery applies to one-way only")
    streams = (Pattern.PUBLISH_SUBSCRIBE, Pattern.EVENT)
    for op in d.operations:
        if op.qos is not None:
            yield from _qos(d, op, op.qos, d.pattern in streams)
        if op.idempotent and not d.pattern.has_replies:
            yield Problem(d.source, op.line, f"operation '{op.name}' attribute 'idempotent'",
                          "applies to request-response and point-to-point only (a retry "
                          "after a lost reply)")
        if op.returns and not d.pattern.has_replies:
            yield Problem(
                d.source,
                op.returns[0].line,
                f"operation '{op.name}' return '{op.returns[0].name}'",
                f"pattern '{d.pattern}' has no replies, so no return values",
            )


def _qos(d: ServiceDescriptor, op: Operation, qos: StreamQos, stream: bool) -> Iterator[Problem]:
    label = f"operation '{op.name}' qos"
    if not stream:
        yield Problem(d.source, qos.line, label,
                      "applies to publish-subscribe and event only (a stream's quality)")
        return
    try:
        qos.settings()
    except ValueError as exc:
        why = str(exc).removeprefix("bad QoS: ")
        why = why.replace("keep_latest", "keep-latest").replace("max_bytes", "max-bytes")
        yield Problem(d.source, qos.line, label, why)


def _participant(d: ServiceDescriptor, part: Participant) -> Iterator[Problem]:
    label = f"participant '{part.packaging}'"
    impl = part.implementation
    if part.actor is not part.packaging.actor:
        yield Problem(d.source, part.line, label, f"packaging is for a {part.packaging.actor}")
    if (
        d.pattern in (Pattern.PUBLISH_SUBSCRIBE, Pattern.EVENT)
        and part.packaging not in _PUBSUB_FORMS
    ):
        yield Problem(
            d.source,
            part.line,
            label,
            f"pattern '{d.pattern}' supports provider-library and consumer-source only",
        )
    if impl is None:
        needs = (Packaging.PROVIDER_EXECUTABLE, Packaging.CONSUMER_NO_SOURCE)
        if part.packaging in needs or (
            (part.packaging is Packaging.PROVIDER_LIBRARY and d.pattern.has_replies)
            or (part.packaging is Packaging.PROVIDER_LIBRARY and d.pattern is Pattern.ONE_WAY)
        ):
            yield Problem(d.source, part.line, label, "needs an <implementation>")
        return
    if impl.form not in _FORMS[part.packaging]:
        yield Problem(
            d.source,
            impl.line,
            f"{label} implementation",
            f"form '{impl.form}' does not fit packaging '{part.packaging}'",
        )
    yield from _implementation(d, part, label)


def _implementation(d: ServiceDescriptor, part: Participant, label: str) -> Iterator[Problem]:
    impl = part.implementation
    assert impl is not None
    here = f"{label} implementation"
    refs = [(c.operation, c.line) for c in impl.commands]
    refs += [(f.operation, f.line) for f in impl.functions]
    for name, line in refs:
        if name is not None and d.operation(name) is None:
            yield Problem(d.source, line, here, f"unknown operation '{name}'")
    if impl.form is ImplementationForm.EXECUTABLE:
        yield from _commands(d, part, here)
        for op in d.operations:
            if impl.command(op.name) is None:
                yield Problem(d.source, impl.line, here, f"no command for operation '{op.name}'")
            elif impl.encoding.value == "text":
                yield from _text_encoding(d, op, impl.line, here)
    if impl.form is ImplementationForm.LIBRARY and not impl.library:
        yield Problem(d.source, impl.line, here, "form 'library' needs a library attribute")
    if part.language is Language.C:
        if (
            impl.form is not ImplementationForm.LIBRARY
            or part.packaging.actor is not Actor.PROVIDER
        ):
            yield Problem(d.source, part.line, label, "language 'c' needs provider-library")
        for op in d.operations:
            yield from _c_operation(d, op, here)


def _commands(d: ServiceDescriptor, part: Participant, here: str) -> Iterator[Problem]:
    impl = part.implementation
    assert impl is not None
    if not 0 < impl.timeout <= MAX_TIMEOUT:
        yield Problem(d.source, impl.line, here, f"timeout must be 1 to {MAX_TIMEOUT} seconds")
    for command in impl.commands:
        try:
            words = shlex.split(command.argv)
        except ValueError as exc:
            words, why = [], f": {exc}"
        else:
            why = ""
        if not words:
            yield Problem(d.source, command.line, f"{here} command",
                          f"not a command line{why or ': empty'}")


def _text_encoding(d: ServiceDescriptor, op: Operation, line: int, here: str) -> Iterator[Problem]:
    params_ok = len(op.parameters) == 1 and op.parameters[0].type.name == "string"
    returns_ok = len(op.returns) <= 1 and all(r.type.name == "string" for r in op.returns)
    if not (params_ok and returns_ok):
        yield Problem(
            d.source,
            line,
            here,
            f"encoding 'text' needs operation '{op.name}' to take one string and return "
            "at most one string",
        )


def _c_operation(d: ServiceDescriptor, op: Operation, here: str) -> Iterator[Problem]:
    for value in (*op.parameters, *op.returns):
        if not value.type.is_primitive or value.type.name == "bytes":
            yield Problem(
                d.source,
                value.line,
                f"operation '{op.name}' '{value.name}'",
                f"type '{value.type}' cannot cross a C call (int, float, bool, string only)",
            )
    if len(op.returns) > 1:
        yield Problem(
            d.source, op.line, f"operation '{op.name}'", "a C function returns one value at most"
        )
