"""Read a descriptor: parse the XML, validate it against the shipped schema, build the facts.

Semantic checks live in :mod:`robosoa.descriptor.checks`; this module only turns text into
:class:`ServiceDescriptor` and reports syntax and schema errors with file, line and field.
"""

from __future__ import annotations

import os
import re
import stat
from collections.abc import Iterable
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

from lxml import etree

from .checks import check
from .errors import DescriptorError, Problem
from .model import (
    Actor,
    Command,
    Encoding,
    Function,
    Implementation,
    ImplementationForm,
    Language,
    Naming,
    OperatingSystem,
    Operation,
    Packaging,
    Parameter,
    Participant,
    Pattern,
    Profile,
    StreamQos,
    TypeDef,
    TypeRef,
)
from .names import default_naming
from .service import ServiceDescriptor

_Element = etree._Element

_LABELS = {
    "operation": "operation",
    "param": "parameter",
    "return": "return",
    "struct": "type",
    "field": "field",
    "command": "command",
    "function": "function",
    "qos": "qos",
}
_DECLARATION = re.compile(r"<!\s*(DOCTYPE|ENTITY)", re.IGNORECASE)
MAX_DESCRIPTOR_BYTES = 1024 * 1024  # a descriptor is a page of XML; 1 MiB is plenty
_SCHEMA_PREFIX = re.compile(r"^Element '[^']+'(?:, attribute '(?P<attr>[^']+)')?: ")


@cache
def schema() -> etree.XMLSchema:
    """The shipped XML Schema (robosoa/data/descriptor.xsd), parsed once."""
    data = resources.files("robosoa").joinpath("data/descriptor.xsd").read_bytes()
    return etree.XMLSchema(etree.fromstring(data))


def load(path: str | Path, max_bytes: int = MAX_DESCRIPTOR_BYTES) -> ServiceDescriptor:
    """Load and validate the descriptor file at ``path``; raise :class:`DescriptorError`.

    Only a regular file of at most ``max_bytes`` bytes of UTF-8 is read.
    """
    try:
        if not stat.S_ISREG(os.stat(path).st_mode):
            raise OSError("not a regular file")
        with open(path, "rb") as stream:
            data = stream.read(max_bytes + 1)
        if len(data) > max_bytes:
            raise OSError(f"larger than {max_bytes} bytes (the descriptor size limit)")
        text = data.decode("utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise DescriptorError([Problem(str(path), 0, "", f"cannot read: {exc}")]) from None
    text = text.replace("\r\n", "\n").replace("\r", "\n")  # as text mode reads it
    return loads(text, source=str(path), max_bytes=max_bytes)


def _refuse(source: str, line: int, message: str) -> DescriptorError:
    return DescriptorError([Problem(source, line, "", message)])


def _parse(text: str, source: str, max_bytes: int) -> _Element:
    """The document's root, parsed without DTDs, entities or network access."""
    try:
        data = text.encode("utf-8")
    except UnicodeEncodeError as exc:
        raise _refuse(source, 0, f"cannot be encoded as UTF-8: {exc.reason}") from None
    if len(data) > max_bytes:
        raise _refuse(source, 0, f"larger than {max_bytes} bytes (the descriptor size limit)")
    found = _DECLARATION.search(text)
    if found:
        line = text.count("\n", 0, found.start()) + 1
        raise _refuse(source, line, "DTDs and entity declarations are not allowed")
    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False,
                             huge_tree=False, dtd_validation=False)
    try:
        root = etree.fromstring(data, parser)
    except etree.XMLSyntaxError as exc:
        raise _refuse(source, exc.lineno or 0, f"not well-formed XML: {exc.msg}") from None
    docinfo = root.getroottree().docinfo
    doctype: object = getattr(docinfo, "doctype", "")  # the lxml stubs leave it out
    entity = next(root.iter(etree.Entity), None)
    if doctype or docinfo.internalDTD is not None or entity is not None:
        line = _line(entity) if entity is not None else 1
        raise _refuse(source, line, "DTDs and entity references are not allowed")
    return root


def loads(text: str, source: str = "<descriptor>",
          max_bytes: int = MAX_DESCRIPTOR_BYTES) -> ServiceDescriptor:
    """Parse and validate descriptor ``text``; ``source`` names it in error messages."""
    root = _parse(text, source, max_bytes)
    validator = schema()
    try:
        valid = validator.validate(root)
    except etree.Error as exc:  # lxml refuses some documents outright
        raise _refuse(source, 0, f"cannot be checked against the schema: {exc}") from None
    if not valid:
        raise DescriptorError(_schema_problems(root, validator, source))
    descriptor = _service(root, source, text)
    problems = check(descriptor)
    if problems:
        raise DescriptorError(problems)
    return descriptor


def describe(element: _Element) -> str:
    """Name an element as a reader would: ``operation 'query' parameter 'x'``."""
    parts: list[str] = []
    node: _Element | None = element
    while node is not None:
        tag = str(node.tag)
        if tag in _LABELS:
            label = _LABELS[tag]
            key = node.get("name") or node.get("operation")
            parts.append(f"{label} '{key}'" if key else label)
        elif tag == "participant":
            parts.append(f"participant '{node.get('packaging')}'")
        elif tag != "service":
            parts.append(tag)
        node = node.getparent()
    return " ".join(reversed(parts)) or "service"


def _schema_problems(root: _Element, validator: etree.XMLSchema, source: str) -> list[Problem]:
    problems = []
    entries: Iterable[Any] = validator.error_log  # type: ignore[assignment]
    for entry in entries:
        found = root.getroottree().xpath(entry.path) if entry.path else []
        element = found[0] if isinstance(found, list) and found else root
        field = describe(element) if isinstance(element, _Element) else "service"
        message = entry.message
        match = _SCHEMA_PREFIX.match(message)
        if match:
            message = message[match.end() :]
            if match.group("attr"):
                field += f" attribute '{match.group('attr')}'"
        problems.append(Problem(source, entry.line, field, message.rstrip(".")))
    return problems


def parse_type(text: str) -> TypeRef:
    """Parse a type expression (``int``, ``Row``, ``list[list[float]]``).

    A malformed expression becomes a TypeRef named by the whole text, which the semantic
    checks then report as an unknown type.
    """
    if text.startswith("list[") and text.endswith("]"):
        return TypeRef("list", parse_type(text[5:-1]))
    return TypeRef(text)


def _line(element: _Element) -> int:
    line: object = element.sourceline  # the lxml stubs leave this untyped
    return line if isinstance(line, int) else 0


def _required(element: _Element, name: str) -> str:
    return element.get(name) or ""


def _text(element: _Element | None) -> str:
    return " ".join((element.text or "").split()) if element is not None else ""


def _typed(element: _Element) -> Parameter:
    default = element.get("default")
    required = element.get("required")
    is_required = required in ("true", "1") if required is not None else default is None
    return Parameter(
        name=element.get("name", ""),
        type=parse_type(element.get("type", "")),
        required=is_required,
        default=default,
        definition=element.get("definition", ""),
        line=_line(element),
    )


def _operation(element: _Element) -> Operation:
    return Operation(
        name=element.get("name", ""),
        parameters=tuple(_typed(e) for e in element.findall("param")),
        returns=tuple(_typed(e) for e in element.findall("return")),
        definition=_text(element.find("definition")),
        line=_line(element),
        idempotent=element.get("idempotent") in ("true", "1"),
        qos=_qos(element.find("qos")),
    )


def _whole(text: str | None) -> int | None:
    """A schema-checked positive integer; one of more than 18 digits as 10**18 (past every
    limit, so the checks report it, and int() never parses thousands of digits)."""
    if text is None:
        return None
    return int(text) if len(text.strip()) <= 18 else 10**18


def _qos(element: _Element | None) -> StreamQos | None:
    if element is None:
        return None
    depth, max_bytes = element.get("depth"), element.get("max-bytes")
    lifespan, block = element.get("lifespan"), element.get("block")
    return StreamQos(
        depth=_whole(depth),
        max_bytes=_whole(max_bytes),
        lifespan=float(lifespan) if lifespan is not None else None,
        keep_latest=element.get("keep-latest") in ("true", "1"),
        reliable=element.get("reliable") in ("true", "1"),
        block=float(block) if block is not None else None,
        line=_line(element),
    )


def _struct(element: _Element) -> TypeDef:
    return TypeDef(
        name=element.get("name", ""),
        fields=tuple(_typed(e) for e in element.findall("field")),
        definition=_text(element.find("definition")),
        line=_line(element),
    )


def _implementation(element: _Element | None) -> Implementation | None:
    if element is None:
        return None
    return Implementation(
        form=ImplementationForm(_required(element, "form")),
        library=element.get("library"),
        encoding=Encoding(element.get("encoding", "json")),
        timeout=float(element.get("timeout", "30")),
        commands=tuple(
            Command(e.get("operation"), (e.text or "").strip(), _line(e))
            for e in element.findall("command")
        ),
        functions=tuple(
            Function(e.get("operation", ""), e.get("symbol", ""), _line(e))
            for e in element.findall("function")
        ),
        line=_line(element),
    )


def _naming(element: _Element | None, defaults: Naming) -> Naming:
    if element is None:
        return defaults
    return Naming(
        package=element.get("package", defaults.package),
        module=element.get("module", defaults.module),
        class_name=element.get("class", defaults.class_name),
    )


def _participant(element: _Element, service: str) -> Participant:
    packaging = Packaging(_required(element, "packaging"))
    target = element.find("target")
    implementation = _implementation(element.find("implementation"))
    naming = element.find("naming")
    defaults = default_naming(
        service, packaging, implementation.library if implementation else None
    )
    codegen = element.find("codegen")
    return Participant(
        actor=Actor(_required(element, "actor")),
        packaging=packaging,
        language=Language(target.get("language", "python") if target is not None else "python"),
        os=OperatingSystem(target.get("os", "any") if target is not None else "any"),
        implementation=implementation,
        profile=Profile(codegen.get("profile", "checked") if codegen is not None else "checked"),
        naming=_naming(naming, defaults),
        group=element.get("group"),
        line=_line(element),
    )


def _service(root: _Element, source: str, text: str) -> ServiceDescriptor:
    name = root.get("name", "")
    pattern = root.find("pattern")
    types = root.find("types")
    return ServiceDescriptor(
        name=name,
        version=root.get("version", ""),
        definition=_text(root.find("definition")),
        pattern=Pattern(_text(pattern)),
        delivery=pattern.get("delivery", "one") if pattern is not None else "one",
        types=tuple(_struct(e) for e in types.findall("struct")) if types is not None else (),
        operations=tuple(_operation(e) for e in root.findall("operation")),
        participants=tuple(_participant(e, name) for e in root.findall("participant")),
        source=source,
        text=text,
        line=_line(root),
    )
