"""Names a descriptor turns into Python identifiers, and the checks that keep them harmless.

Every service, operation, parameter, return, field, struct, class, module, package and
function name must be a valid identifier, not a keyword, not one of :data:`RESERVED` (what
generated modules define, import or use themselves), and must not collide with another
generated name. A name that breaks a rule is rejected, never mangled. Pure: returns problems.
"""

from __future__ import annotations

import keyword
import sys
from collections.abc import Iterator

from .errors import Problem
from .model import (
    PRIMITIVES,
    Actor,
    Language,
    Naming,
    OperatingSystem,
    Packaging,
    Participant,
    Pattern,
    Profile,
)
from .service import ServiceDescriptor

# Module-level names of generated modules (imports and definitions), the names their methods
# rely on, and the builtins generated code calls. tests/robosoa/test_codegen_names.py checks
# that generated code uses no other free name.
RESERVED = frozenset({
    # imports
    "annotations", "argparse", "ctypes", "importlib", "os", "sys", "Mapping", "Callable",
    "Sequence", "dataclass", "Any", "Protocol", "robosoa", "payload_of", "to_wire",
    "client_main", "serve_main", "ExecutableRunner", "check_platform", "ServiceDescriptor",
    "loads",
    # definitions
    "SERVICE", "VERSION", "PATTERN", "OPERATIONS", "IDEMPOTENT", "DESCRIPTOR_XML", "DESCRIPTOR",
    "COMMANDS",
    "LIBRARY", "main", "bind",
    # method parameters and members of the generated dataclasses
    "self", "cls", "from_payload", "to_payload",
    # builtins and descriptor type names
    "tuple", "dict", "str", "int", "float", "bool", "bytes", "list", "object", "classmethod",
    *PRIMITIVES,
})
_TOP_PACKAGES = frozenset({*sys.stdlib_module_names, "robosoa", "archmetrics"})


def camel(name: str) -> str:
    """``world_db`` -> ``WorldDb``: class names from service and operation names."""
    return "".join(part[:1].upper() + part[1:] for part in name.split("_"))


def result_class(operation: str) -> str:
    """Name of the generated dataclass holding the return values of ``operation``."""
    return f"{camel(operation)}Result"


def message_class(operation: str) -> str:
    """Name of the generated dataclass holding the parameters of a topic or event."""
    return f"{camel(operation)}Message"


def identifier_problem(name: str) -> str:
    """Why ``name`` cannot be a generated identifier ("" when it can)."""
    if not name.isidentifier():
        return f"{name!r} is not a Python identifier"
    if keyword.iskeyword(name):
        return f"{name!r} is a reserved word (a Python keyword)"
    if name in RESERVED:
        return f"{name!r} is a reserved word (generated code defines or uses it)"
    return ""


def default_naming(service: str, packaging: Packaging, library: str | None) -> Naming:
    """Package, module and class names used when ``<naming>`` leaves them out."""
    if packaging is Packaging.CONSUMER_SOURCE:
        return Naming(f"{service}_client", "client", f"{camel(service)}Client")
    if packaging is Packaging.CONSUMER_NO_SOURCE:
        package = library.rsplit(".", 1)[-1] if library else f"{service}_api"
        return Naming(package, "api", f"{camel(service)}Api")
    return Naming(f"{service}_provider", "provider", f"{camel(service)}Provider")


def default_consumer(d: ServiceDescriptor) -> Participant:
    """The consumer-source participant generated when the descriptor declares none."""
    return Participant(
        actor=Actor.CONSUMER,
        packaging=Packaging.CONSUMER_SOURCE,
        language=Language.PYTHON,
        os=OperatingSystem.ANY,
        implementation=None,
        profile=Profile.CHECKED,
        naming=default_naming(d.name, Packaging.CONSUMER_SOURCE, None),
        group=None,
        line=d.line,
    )


def type_classes(d: ServiceDescriptor) -> list[tuple[str, str, int]]:
    """(label, class name, line) of every class ``types.py`` defines."""
    classes = [(f"type '{t.name}'", t.name, t.line) for t in d.types]
    classes += [(f"operation '{op.name}' result class", result_class(op.name), op.line)
                for op in d.operations if op.returns]
    if not d.pattern.has_replies:
        classes += [(f"operation '{op.name}' message class", message_class(op.name), op.line)
                    for op in d.operations if op.parameters]
    return classes


def _values(d: ServiceDescriptor) -> Iterator[tuple[str, str, int]]:
    for op in d.operations:
        yield f"operation '{op.name}'", op.name, op.line
        for p in op.parameters:
            yield f"operation '{op.name}' parameter '{p.name}'", p.name, p.line
        for r in op.returns:
            yield f"operation '{op.name}' return '{r.name}'", r.name, r.line
    for t in d.types:
        for f in t.fields:
            yield f"type '{t.name}' field '{f.name}'", f.name, f.line


def participant_classes(d: ServiceDescriptor, part: Participant) -> list[str]:
    """Classes and module-level functions the participant's own module defines."""
    name = part.naming.class_name
    if part.packaging is Packaging.CONSUMER_NO_SOURCE:
        impl = part.implementation
        symbols = [impl.symbol(op.name) if impl else op.name for op in d.operations]
        return [f"{camel(d.name)}Client", *symbols]
    if part.packaging is Packaging.CONSUMER_SOURCE or d.pattern in (
            Pattern.PUBLISH_SUBSCRIBE, Pattern.EVENT):
        return [name]
    form = "Executable" if part.packaging is Packaging.PROVIDER_EXECUTABLE else "Library"
    return [name, f"{name}Implementation", f"{name}{form}"]


def _naming(d: ServiceDescriptor, part: Participant) -> Iterator[str]:
    naming = part.naming
    parts = naming.package.split(".")
    for piece in parts:
        if not piece.isidentifier() or keyword.iskeyword(piece):
            yield f"package {naming.package!r} is not a dotted name of identifiers"
            return
    if parts[0] in _TOP_PACKAGES:
        yield f"package {naming.package!r} would hide the module {parts[0]!r}"
    problem = identifier_problem(naming.module)
    if problem or naming.module == "types":
        yield f"module: {problem or repr('types') + ' is the types module'}"
    problem = identifier_problem(naming.class_name)
    if problem:
        yield f"class: {problem}"


def _participant(d: ServiceDescriptor, part: Participant, taken: set[str]) -> Iterator[Problem]:
    label = f"participant '{part.packaging}' naming"
    for message in _naming(d, part):
        yield Problem(d.source, part.line, label, message)
    impl = part.implementation
    for f in impl.functions if impl else ():
        problem = identifier_problem(f.symbol)
        if problem:
            yield Problem(d.source, f.line, f"function '{f.operation}'", problem)
    seen = set(taken)
    for name in participant_classes(d, part):
        if name in seen:
            yield Problem(d.source, part.line, label, f"generated name {name!r} is taken twice")
        seen.add(name)


def name_problems(d: ServiceDescriptor) -> Iterator[Problem]:
    """Every name of ``d`` that cannot become a harmless Python identifier."""
    if not d.name.isidentifier() or keyword.iskeyword(d.name):
        yield Problem(d.source, d.line, "service", f"{d.name!r} is not a usable Python name")
    classes = type_classes(d)
    taken: dict[str, int] = {}
    for label, name, line in [*classes, *_values(d)]:
        problem = identifier_problem(name)
        if problem:
            yield Problem(d.source, line, label, problem)
    for label, name, line in classes:
        if name in taken:
            yield Problem(d.source, line, label,
                          f"class {name!r} is already generated for line {taken[name]}")
        taken.setdefault(name, line)
    for label, name, line in _values(d):
        if name in taken:
            yield Problem(d.source, line, label, f"{name!r} is also the name of a class")
    packages: dict[str, int] = {}
    declared = d.participant(Packaging.CONSUMER_SOURCE) is not None
    for part in [*d.participants, *([] if declared else [default_consumer(d)])]:
        yield from _participant(d, part, set(taken))
        if part not in d.participants:
            continue  # generated only on request (--form): its package may be declared too
        if part.naming.package in packages:
            yield Problem(d.source, part.line, f"participant '{part.packaging}' naming",
                          f"package {part.naming.package!r} is generated twice")
        packages.setdefault(part.naming.package, part.line)
